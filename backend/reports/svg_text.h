// Text inside the SVG pictures smtcal writes (table plots, diff arrows): file
// names and point names may hold the characters XML reserves.
#pragma once

#include <string>
#include <string_view>

namespace smtcal {

// `text` with &, <, > and " written as XML entities.
inline std::string SvgEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace smtcal
