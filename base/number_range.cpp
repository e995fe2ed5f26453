// The one check of every number a user gives (base/number_range.h).
#include "base/number_range.h"

#include <charconv>
#include <cmath>
#include <system_error>

#include <fmt/format.h>

#include "base/field_text.h"

namespace smtcal {
namespace {

// The largest whole number smtcal reads (a 64-bit seed), which a double
// cannot hold exactly: a range reaching 2^64 means "every 64-bit value".
constexpr double kTwoTo64 = 18446744073709551616.0;

std::string WholeText(double value) {
  if (value >= kTwoTo64) return "18446744073709551615";
  return fmt::format("{:.0f}", value);
}

std::string WithUnit(const std::string& number, std::string_view unit) {
  return unit.empty() ? number : fmt::format("{} {}", number, unit);
}

// The text of a refused number, quoted for a message.
std::string Quoted(std::string_view text) { return fmt::format("'{}'", CutForMessage(Printable(text))); }

}  // namespace

bool InRange(double value, const NumberRange& range) {
  if (!std::isfinite(value)) return false;
  if (range.lo_open ? !(value > range.lo) : !(value >= range.lo)) return false;
  if (!(value <= range.hi)) return false;
  return !range.whole || value == std::trunc(value);
}

std::string NumberText(double value) {
  if (value == 0) return "0";
  return fmt::format("{}", value);
}

std::string RangeText(const NumberRange& range) {
  if (range.whole) {
    return WithUnit(fmt::format("a whole number from {} to {}", WholeText(range.lo), WholeText(range.hi)),
                    range.unit);
  }
  if (range.lo_open) {
    return fmt::format("a number greater than {} and at most {}", NumberText(range.lo),
                       WithUnit(NumberText(range.hi), range.unit));
  }
  return fmt::format("a number from {} to {}", NumberText(range.lo), WithUnit(NumberText(range.hi), range.unit));
}

Result<double> ParseNumberIn(std::string_view text, const NumberRange& range) {
  if (text.empty()) return Error{fmt::format("no value; give {}", RangeText(range))};
  std::optional<double> value = ParseNumber(text);
  if (!value) return Error{fmt::format("{} is not a number; give {}", Quoted(text), RangeText(range))};
  if (!std::isfinite(*value)) {
    return Error{fmt::format("{} is not a finite number; give {}", Quoted(text), RangeText(range))};
  }
  if (*value == 0 && std::signbit(*value)) {
    return Error{fmt::format("{} is a negative zero; write 0 ({})", Quoted(text), RangeText(range))};
  }
  if (!InRange(*value, range)) {
    return Error{fmt::format("{} is out of range: it must be {}", Quoted(text), RangeText(range))};
  }
  return *value;
}

Result<WholeNumber> ParseWholeNumberIn(std::string_view text, const NumberRange& range) {
  SMTCAL_CHECK(range.whole, "a whole number needs a whole range");
  if (text.empty()) return Error{fmt::format("no value; give {}", RangeText(range))};
  WholeNumber number;
  std::string_view digits = text;
  if (digits.front() == '-' || digits.front() == '+') {
    number.negative = digits.front() == '-';
    digits.remove_prefix(1);
  }
  auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), number.magnitude);
  const bool all_digits = !digits.empty() && end == digits.data() + digits.size() &&
                          digits.find_first_not_of("0123456789") == std::string_view::npos;
  if (!all_digits || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
    return Error{fmt::format("{} is not a whole number; give {}", Quoted(text), RangeText(range))};
  }
  if (number.negative && number.magnitude == 0 && ec == std::errc()) {
    return Error{fmt::format("{} is a negative zero; write 0 ({})", Quoted(text), RangeText(range))};
  }
  const double value = number.negative ? -static_cast<double>(number.magnitude) : static_cast<double>(number.magnitude);
  const bool beyond = ec == std::errc::result_out_of_range || (number.negative && range.lo >= 0) ||
                      (!number.negative && range.hi < kTwoTo64 && value > range.hi) || value < range.lo;
  if (beyond) return Error{fmt::format("{} is out of range: it must be {}", Quoted(text), RangeText(range))};
  return number;
}

}  // namespace smtcal
