// The text encoding of a placement list (docs/import.md, "What real files
// contain"). Lists arrive as the tools write them: UTF-8 (with or without a
// byte order mark), UTF-16 (EasyEDA writes UTF-16 LE with a byte order mark),
// or a Windows code page (Altium on Windows writes reports in Windows-1252,
// so "µ" is the single byte 0xB5). The readers work on UTF-8, so a list is
// decoded once, before anything reads it:
//   - a UTF-16 byte order mark (FF FE little endian, FE FF big endian), or a
//     first line of ASCII in UTF-16 without one ("D\0e\0" ...): UTF-16;
//   - else valid UTF-8 (and so plain ASCII) is kept as it is;
//   - else the bytes are read as Windows-1252, the code page of Western
//     Windows; the summary says so. A byte that Windows-1252 leaves
//     undefined (0x81, 0x8D, 0x8F, 0x90, 0x9D) means the list is in some
//     other encoding: it is refused, never decoded into wrong letters.
// glibc's iconv does the conversions.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace smtcal::cad {

enum class TextEncoding { kUtf8, kUtf16Le, kUtf16Be, kWindows1252 };
// "UTF-8", "UTF-16 LE", "UTF-16 BE", "Windows-1252"
std::string_view EncodingName(TextEncoding encoding);

struct DecodedText {
  TextEncoding encoding = TextEncoding::kUtf8;
  std::string text;          // UTF-8; empty when the text is UTF-8 already (use the bytes as they are)
  bool ok = true;            // false: the bytes are in none of the encodings above
  std::size_t bad_offset = 0;  // !ok: the first byte that cannot be decoded
  std::string why;           // !ok: what is wrong, for the message
};

DecodedText DecodeListText(std::string_view bytes);

}  // namespace smtcal::cad
