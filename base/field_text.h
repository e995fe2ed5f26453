// Reading and showing the text of one field of a user's file, shared by every
// reader of CSV-like and TOML files (error tables and point lists, trip
// files, CAD placement lists, cell, feeders and truth files), so they accept
// the same numbers, compare names the same way and print the same way.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace smtcal {

// The length of the well-formed UTF-8 sequence at text[i] (1 to 4 bytes), or
// 0 if there is none: a stray continuation byte, an overlong form, a
// surrogate, a code point beyond U+10FFFF, or a sequence cut short.
std::size_t Utf8Length(std::string_view text, std::size_t i);

// How Printable shows what a terminal or a JSON reader must not get.
enum class TextQuoting {
  // A name or field quoted in a message: control characters and bytes that
  // are not UTF-8 as \xNN, so a binary file cannot garble the
  // terminal or cut a message short.
  kField,
  // A whole message or note: as kField, but tabs and line breaks are kept.
  kMessage,
  // The source line under a diagnostic: one '?' for each such byte (tabs
  // kept), so the caret line stays aligned, character for character.
  kSourceLine,
};

// The one quoting function for text from the user's files and command line
// that smtcal writes on stderr (docs/files-and-exit-codes.md): the result is
// always valid UTF-8.
std::string Printable(std::string_view text, TextQuoting quoting = TextQuoting::kField);

// The most bytes of a message or note that quotes the input; longer ones are
// cut (at a character boundary) and end in "...".
inline constexpr std::size_t kMaxMessageBytes = 1000;
std::string CutForMessage(std::string text);

// A decimal number written exactly as `text` (optional sign, digits, '.',
// exponent), read locale-independently with fast_float. nullopt when it is
// not exactly one number; an overflow gives HUGE_VAL (so range checks report
// it as not finite), an underflow 0.
std::optional<double> ParseNumber(std::string_view text);

// ASCII letters in lower case, every other byte as it is (names and keywords
// in files are compared case-insensitively, whatever the user's locale).
char AsciiLower(char c);
std::string AsciiLowercase(std::string_view text);

// The double nearest to `value` written with `decimals` decimals, so that a
// JSON writer's shortest form prints exactly those digits (0.285, not
// 0.28500000000000003); -0 becomes 0. Non-finite values pass through.
double RoundedToDecimals(double value, int decimals);

}  // namespace smtcal
