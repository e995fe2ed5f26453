// Text inside the SVG pictures smtcal writes (table plots, diff arrows): file
// names and point names may hold the characters XML reserves; the round
// numbers an axis is ticked at; how many glyphs a text is.
#pragma once

#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "base/field_text.h"

namespace smtcal {

// `text` with &, <, > and " written as XML entities, and what XML cannot
// hold at all (bytes that are not UTF-8, as a file name may have; control
// characters) as U+FFFD, so the picture stays a valid SVG file.
inline std::string SvgEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t length = Utf8Length(text, i);
    const char c = text[i];
    if (length == 0 || (length == 1 && static_cast<unsigned char>(c) < 0x20 && c != '\t')) {
      out += "\uFFFD";
      ++i;
      continue;
    }
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += text.substr(i, length);
    }
    i += length;
  }
  return out;
}

// The characters of a UTF-8 text (µ, Ω count once): how wide a label or a
// table cell is in glyphs.
inline std::size_t Utf8Columns(std::string_view text) {
  std::size_t n = 0;
  for (char c : text) n += (static_cast<unsigned char>(c) & 0xc0) != 0x80;
  return n;
}

// A coordinate of the picture: 2 decimals, never "-0.00".
inline std::string SvgNum(double v) {
  std::string text = fmt::format("{:.2f}", v);
  return text == "-0.00" ? "0.00" : text;
}

// The tick step of an axis spanning `span` (> 0) with at most about
// `max_ticks` ticks: the smallest 1, 2, 2.5 or 5 times a power of ten that
// gives no more.
inline double SvgTickStep(double span, int max_ticks) {
  const double rough = span / max_ticks;
  const double power = std::pow(10.0, std::floor(std::log10(rough)));
  for (double m : {1.0, 2.0, 2.5, 5.0}) {
    if (m * power >= rough * (1 - 1e-12)) return m * power;
  }
  return 10 * power;
}

// The multiples of `step` in [lo, hi] (a hair of slack at both ends).
inline std::vector<double> SvgTicks(double lo, double hi, double step) {
  std::vector<double> ticks;
  const double slack = 1e-9 * step;
  for (double k = std::ceil((lo - slack) / step); k * step <= hi + slack; k += 1) ticks.push_back(k * step);
  return ticks;
}

// A tick's label: as many decimals as the step needs (step 2.5 -> 1), no "-0".
inline std::string SvgTickText(double value, double step) {
  int decimals = 0;
  while (decimals < 6 && std::fabs(step * std::pow(10.0, decimals) - std::round(step * std::pow(10.0, decimals))) >
                             1e-9 * std::pow(10.0, decimals)) {
    ++decimals;
  }
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos && text.front() == '-') text.erase(0, 1);
  return text;
}

}  // namespace smtcal
