// Numeric command-line options (tools/commands.h): every one goes through the
// one check of base/number_range.h, with its range from calibration/limits.h
// written into its --help.
#include <string>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "base/number_range.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

// Checks the option's text and rewrites it as the plain number it is, which
// CLI11 then converts: CLI11's own conversion accepts nan, inf, hex, and
// wraps -1 into an unsigned seed.
CLI::Validator NumberValidator(const NumberRange& range) {
  return CLI::Validator(
      [range](std::string& text) -> std::string {
        if (range.whole) {
          Result<WholeNumber> number = ParseWholeNumberIn(text, range);
          if (!number) return number.error().message;
          text = fmt::format("{}{}", number.value().negative ? "-" : "", number.value().magnitude);
          return {};
        }
        Result<double> number = ParseNumberIn(text, range);
        if (!number) return number.error().message;
        text = fmt::format("{}", number.value());
        return {};
      },
      "");
}

template <typename T>
CLI::Option* Add(CLI::App& command, const std::string& name, T& value, const std::string& help,
                 const NumberRange& range) {
  return command.add_option(name, value, fmt::format("{} ({})", help, RangeText(range)))
      ->check(NumberValidator(range))
      ->type_name(range.whole ? kWholeOptionType : kNumberOptionType);
}

}  // namespace

CLI::Option* AddNumberOption(CLI::App& command, const std::string& name, double& value, const std::string& help,
                             const NumberRange& range) {
  return Add(command, name, value, help, range);
}

CLI::Option* AddNumberOption(CLI::App& command, const std::string& name, std::optional<double>& value,
                             const std::string& help, const NumberRange& range) {
  return Add(command, name, value, help, range);
}

CLI::Option* AddNumberOption(CLI::App& command, const std::string& name, int& value, const std::string& help,
                             const NumberRange& range) {
  return Add(command, name, value, help, range);
}

CLI::Option* AddNumberOption(CLI::App& command, const std::string& name, std::uint64_t& value,
                             const std::string& help, const NumberRange& range) {
  return Add(command, name, value, help, range);
}

}  // namespace smtcal::tools
