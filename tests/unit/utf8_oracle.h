// Well-formed UTF-8 decoded code point by code point: the tests' own oracle
// for "standard error is always valid UTF-8" (issue 31), written apart from
// base/field_text.h's table so that a mistake there cannot hide in both.
// No overlong form, no surrogate, nothing beyond U+10FFFF.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace smtcal::test {

// True when `text` is well-formed UTF-8; `characters`, when given, gets the
// number of code points.
inline bool IsWellFormedUtf8(std::string_view text, std::size_t* characters = nullptr) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < text.size(); ++count) {
    const auto lead = static_cast<unsigned char>(text[i]);
    if (lead < 0x80) {
      ++i;
      continue;
    }
    const std::size_t n = (lead & 0xE0) == 0xC0 ? 2 : (lead & 0xF0) == 0xE0 ? 3 : (lead & 0xF8) == 0xF0 ? 4 : 0;
    if (n == 0 || i + n > text.size()) return false;
    std::uint32_t code = lead & (0x7Fu >> n);
    for (std::size_t k = 1; k < n; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xC0) != 0x80) return false;
      code = (code << 6) | (next & 0x3Fu);
    }
    const std::uint32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
    if (code < least[n] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return false;
    i += n;
  }
  if (characters != nullptr) *characters = count;
  return true;
}

}  // namespace smtcal::test
