// Every diagnostic kind declared in base/diagnostic_kinds.def has a golden
// case that produces it: a file tests/golden/<suite>/fail_<kind>[_more].* (an
// error) or warn_<kind>[_more].* (a warning), <kind> in snake_case, whose
// expected standard error holds that diagnostic (its message as the kind's
// format makes it, or the kind by name in --diagnostics=json).
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
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

// The golden cases' stems and where their expected standard error is.
std::map<std::string, std::vector<fs::path>> GoldenCases() {
  std::map<std::string, std::vector<fs::path>> cases;
  fs::path root = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden";
  if (!fs::exists(root)) return cases;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    const fs::path err = entry.path().parent_path() / (entry.path().stem().string() + ".err");
    std::vector<fs::path>& errs = cases[entry.path().stem().string()];
    if (std::find(errs.begin(), errs.end(), err) == errs.end()) errs.push_back(err);
  }
  return cases;
}

std::string FileText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A line of the text rendering of a diagnostic of this kind: the severity,
// then the message as the format makes it, any argument standing for
// anything.
std::regex MessagePattern(Severity severity, std::string_view format) {
  std::string pattern = severity == Severity::Warning ? ": warning: " : ": error: ";
  static const std::string kSpecial = "\\^$.|?*+()[]{}";
  for (std::size_t i = 0; i < format.size(); ++i) {
    const char c = format[i];
    if ((c == '{' || c == '}') && i + 1 < format.size() && format[i + 1] == c) {
      pattern += std::string("\\") + c;
      ++i;
    } else if (c == '{') {
      i = format.find('}', i);
      pattern += "[^]*?";
    } else {
      if (kSpecial.find(c) != std::string::npos) pattern += '\\';
      pattern += c;
    }
  }
  return std::regex(pattern, std::regex::ECMAScript | std::regex::multiline);
}

// Whether the expected standard error holds a diagnostic of the kind.
bool HoldsKind(const std::string& err, std::string_view name, const std::regex& message) {
  if (err.find(fmt::format("\"kind\": \"{}\"", name)) != std::string::npos) return true;
  std::istringstream lines(err);
  for (std::string line; std::getline(lines, line);) {
    if (std::regex_search(line, message)) return true;
  }
  return false;
}

TEST(DiagnosticCoverage, EveryKindHasAGoldenCaseThatEmitsIt) {
#if defined(SMTCAL_SANITIZED)
  // A check of the repository's files, run by the ordinary build; under the
  // sanitizers its regular expressions took 95 s and checked nothing more.
  GTEST_SKIP() << "run by the ordinary build";
#endif
  const std::map<std::string, std::vector<fs::path>> cases = GoldenCases();
  std::vector<std::string> kinds = {
#define DIAG(name, severity, format) #name,
#include "base/diagnostic_kinds.def"
#undef DIAG
  };
  // SyntaxError is the parser's defensive fallback for an ANTLR error that
  // no specific kind describes; fuzzing has not found an input that reaches
  // it, so it cannot have an honest golden case.
  const std::vector<std::string> exempt = {"SyntaxError"};
  // A case belongs to the kind with the longest name its stem starts with
  // (fail_cell_edge_... is CellEdge..., not Cell...).
  std::vector<std::string> prefixes;
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    Severity severity = DiagKindSeverity(static_cast<DiagKind>(i));
    prefixes.push_back((severity == Severity::Warning ? "warn_" : "fail_") + SnakeCase(kinds[i]));
  }
  auto owner = [&](const std::string& stem) {
    std::size_t best = kinds.size();
    for (std::size_t i = 0; i < kinds.size(); ++i) {
      if ((stem == prefixes[i] || stem.rfind(prefixes[i] + "_", 0) == 0) &&
          (best == kinds.size() || prefixes[i].size() > prefixes[best].size())) {
        best = i;
      }
    }
    return best;
  };
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    if (std::find(exempt.begin(), exempt.end(), kinds[i]) != exempt.end()) continue;
    const Severity severity = DiagKindSeverity(static_cast<DiagKind>(i));
    const std::regex message = MessagePattern(severity, DiagKindFormat(static_cast<DiagKind>(i)));
    bool found = false;
    for (const auto& [stem, errs] : cases) {
      if (owner(stem) != i) continue;
      found = true;
      bool emitted = false;
      for (const fs::path& err : errs) emitted |= fs::exists(err) && HoldsKind(FileText(err), kinds[i], message);
      EXPECT_TRUE(emitted) << "the golden case " << stem << " is named for " << kinds[i]
                           << ", but its expected standard error (" << errs.front().string()
                           << ") holds no such " << SeverityName(severity);
    }
    EXPECT_TRUE(found) << "no golden case for " << kinds[i] << ": add tests/golden/<suite>/" << prefixes[i]
                       << ".<ext>";
  }
}

}  // namespace
}  // namespace smtcal
