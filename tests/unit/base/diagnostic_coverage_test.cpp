// Every diagnostic kind declared in base/diagnostic_kinds.def has a golden
// case that produces it: a file tests/golden/<suite>/fail_<kind>[_more].* (an
// error) or warn_<kind>[_more].* (a warning), <kind> in snake_case.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/diagnostics.h"

namespace fs = std::filesystem;

namespace smtcal {
namespace {

std::string SnakeCase(std::string_view camel) {
  std::string snake;
  for (char c : camel) {
    if (std::isupper(static_cast<unsigned char>(c))) {
      if (!snake.empty()) snake += '_';
      snake += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else {
      snake += c;
    }
  }
  return snake;
}

std::vector<std::string> GoldenStems() {
  std::vector<std::string> stems;
  fs::path root = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden";
  if (!fs::exists(root)) return stems;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.is_regular_file()) stems.push_back(entry.path().stem().string());
  }
  return stems;
}

TEST(DiagnosticCoverage, EveryKindHasAGoldenCase) {
  std::vector<std::string> stems = GoldenStems();
  std::vector<std::string> kinds = {
#define DIAG(name, severity, format) #name,
#include "base/diagnostic_kinds.def"
#undef DIAG
  };
  // SyntaxError is the parser's defensive fallback for an ANTLR error that
  // no specific kind describes; fuzzing has not found an input that reaches
  // it, so it cannot have an honest golden case.
  const std::vector<std::string> exempt = {"SyntaxError"};
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    if (std::find(exempt.begin(), exempt.end(), kinds[i]) != exempt.end()) continue;
    Severity severity = DiagKindSeverity(static_cast<DiagKind>(i));
    std::string prefix = (severity == Severity::Warning ? "warn_" : "fail_") + SnakeCase(kinds[i]);
    bool found = false;
    for (const std::string& stem : stems) {
      if (stem == prefix || stem.rfind(prefix + "_", 0) == 0) found = true;
    }
    EXPECT_TRUE(found) << "no golden case for " << kinds[i] << ": add tests/golden/<suite>/"
                       << prefix << ".<ext>";
  }
}

}  // namespace
}  // namespace smtcal
