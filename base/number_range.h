// The one check of every number a user gives smtcal: the numeric options of
// every command (tools/number_options.cpp) and the numeric keys of the cell,
// truth and feeders files (frontend/). A number must be finite, inside its
// documented range and, where it counts something, whole. The ranges
// themselves are named constants (calibration/limits.h); RangeText words
// them the same way in --help, in every message and in the docs.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "base/result.h"

namespace smtcal {

struct NumberRange {
  double lo = 0;
  double hi = 0;
  std::string_view unit;  // "mm", "µm", "deg", ...; empty for a plain number
  bool lo_open = false;   // the number must be greater than lo (a length > 0)
  bool whole = false;     // a whole number (a count, an input bit, a seed)
};

// A closed range [lo, hi]; a range (lo, hi] that excludes lo; a whole number.
constexpr NumberRange Closed(double lo, double hi, std::string_view unit) { return {lo, hi, unit, false, false}; }
constexpr NumberRange AboveZero(double hi, std::string_view unit) { return {0, hi, unit, true, false}; }
constexpr NumberRange Whole(double lo, double hi, std::string_view what = "") { return {lo, hi, what, false, true}; }

// False for NaN and the infinities, outside the range, or not whole when it
// must be.
bool InRange(double value, const NumberRange& range);

// What a number in the range is: "a number from 0 to 1000000 µm", "a number
// greater than 0 and at most 10 mm", "a whole number from 1 to 100000".
std::string RangeText(const NumberRange& range);

// A number for messages and the docs: the shortest form that reads back
// (0.1, 100000, 1e-300, 1.8e+308), never "-0".
std::string NumberText(double value);

// The value of a number given as text (a command-line option): exactly one
// decimal number (optional sign, digits, '.', exponent; nan, inf, hex and
// thousands separators are not numbers), inside `range`. A negative zero is
// refused (write 0), an empty text too. The Error's message says what the
// text is and what the range is, without naming the option (the caller
// does).
Result<double> ParseNumberIn(std::string_view text, const NumberRange& range);

// A whole number given as text, inside a whole range: digits with an
// optional sign and nothing else, so that every 64-bit seed reads exactly.
struct WholeNumber {
  bool negative = false;
  std::uint64_t magnitude = 0;
};
Result<WholeNumber> ParseWholeNumberIn(std::string_view text, const NumberRange& range);

}  // namespace smtcal
