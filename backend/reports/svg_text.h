// Text inside the SVG pictures smtcal writes (table plots, diff arrows): file
// names and point names may hold the characters XML reserves.
#pragma once

#include <string>
#include <string_view>

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

}  // namespace smtcal
