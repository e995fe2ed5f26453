// Decoding placement lists to UTF-8 (see cad_encoding.h).
#include "frontend/cad/cad_encoding.h"

#include <iconv.h>

#include <optional>

#include <fmt/format.h>

#include "base/field_text.h"

namespace smtcal::cad {
namespace {

// Converts all of `bytes` from `from` to UTF-8 with iconv. On failure
// `bad` is the offset of the first byte it could not convert.
bool Convert(const char* from, std::string_view bytes, std::string& out, std::size_t& bad) {
  iconv_t cd = iconv_open("UTF-8", from);
  if (cd == reinterpret_cast<iconv_t>(-1)) {
    bad = 0;
    return false;
  }
  out.resize(bytes.size() * 3 + 16);  // a Windows-1252 byte or a UTF-16 unit is at most 3 UTF-8 bytes
  char* in = const_cast<char*>(bytes.data());
  std::size_t in_left = bytes.size();
  char* to = out.data();
  std::size_t to_left = out.size();
  std::size_t result = iconv(cd, &in, &in_left, &to, &to_left);
  const bool ok = result != static_cast<std::size_t>(-1) && in_left == 0;
  if (ok) {
    // Flush any shift state (none for these encodings, but iconv asks for it).
    iconv(cd, nullptr, nullptr, &to, &to_left);
  }
  iconv_close(cd);
  bad = bytes.size() - in_left;
  out.resize(out.size() - to_left);
  return ok;
}

bool IsValidUtf8(std::string_view bytes) {
  for (std::size_t i = 0; i < bytes.size();) {
    if (static_cast<unsigned char>(bytes[i]) < 0x80) {
      ++i;
      continue;
    }
    std::size_t length = Utf8Length(bytes, i);
    if (length == 0) return false;
    i += length;
  }
  return true;
}

// UTF-16 without a byte order mark: the first characters are ASCII, so
// every other byte is zero.
std::optional<TextEncoding> Utf16WithoutMark(std::string_view bytes) {
  if (bytes.size() < 8) return std::nullopt;
  bool le = true, be = true;
  for (std::size_t i = 0; i < 8; i += 2) {
    le = le && bytes[i] != 0 && bytes[i + 1] == 0;
    be = be && bytes[i] == 0 && bytes[i + 1] != 0;
  }
  if (le) return TextEncoding::kUtf16Le;
  if (be) return TextEncoding::kUtf16Be;
  return std::nullopt;
}

}  // namespace

std::string_view EncodingName(TextEncoding encoding) {
  switch (encoding) {
    case TextEncoding::kUtf8: return "UTF-8";
    case TextEncoding::kUtf16Le: return "UTF-16 LE";
    case TextEncoding::kUtf16Be: return "UTF-16 BE";
    case TextEncoding::kWindows1252: return "Windows-1252";
  }
  return "?";
}

DecodedText DecodeListText(std::string_view bytes) {
  DecodedText decoded;
  std::size_t mark = 0;
  if (bytes.starts_with("\xFF\xFE")) {
    decoded.encoding = TextEncoding::kUtf16Le;
    mark = 2;
  } else if (bytes.starts_with("\xFE\xFF")) {
    decoded.encoding = TextEncoding::kUtf16Be;
    mark = 2;
  } else if (std::optional<TextEncoding> utf16 = Utf16WithoutMark(bytes)) {
    decoded.encoding = *utf16;
  } else if (IsValidUtf8(bytes)) {
    return decoded;
  } else {
    decoded.encoding = TextEncoding::kWindows1252;
  }
  const bool utf16 = decoded.encoding != TextEncoding::kWindows1252;
  const char* from = decoded.encoding == TextEncoding::kUtf16Le   ? "UTF-16LE"
                     : decoded.encoding == TextEncoding::kUtf16Be ? "UTF-16BE"
                                                                  : "WINDOWS-1252";
  std::size_t bad = 0;
  if (Convert(from, bytes.substr(mark), decoded.text, bad)) return decoded;
  decoded.ok = false;
  decoded.bad_offset = mark + bad;
  decoded.text.clear();
  if (utf16) {
    decoded.why = fmt::format("the list starts as {} text, but byte {} ends it halfway through a character",
                              EncodingName(decoded.encoding), decoded.bad_offset + 1);
  } else {
    decoded.why = fmt::format(
        "byte 0x{:02X} is neither UTF-8 nor Windows-1252 (which leaves it undefined), so the list is in "
        "another encoding",
        static_cast<unsigned char>(bytes[decoded.bad_offset]));
  }
  return decoded;
}

}  // namespace smtcal::cad
