// Golden-file tests: each case is an input beside its expected output.
//
// A suite is a folder tests/golden/<suite>/ with an ARGS file holding the
// smtcal arguments ({input} stands for the case's file name; {scratch} for a
// fresh folder outside the tree, for outputs the case does not compare, so
// that the one it compares can go to standard output). Every other
// file that is not *.out, *.err, *.args or ARGS is a case. The harness runs
// smtcal in the suite folder and compares stdout with <case>.out and stderr
// with <case>.err (both always recorded, an empty output as an empty file; a
// missing one fails the case). A case named
// fail_* must exit 1; every other case must exit 0, unless <case>.exit holds
// the exit code it must give (a gate such as `smtcal diff` exits 1 on clean
// input). <case>.args overrides ARGS for one case.
//
// SMTCAL_UPDATE_GOLDEN=1 rewrites the expectations instead of comparing, so a
// reviewer reads the change as a diff.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <cctype>
#include <tuple>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "tests/unit/test_support.h"

namespace fs = std::filesystem;

namespace {

struct GoldenCase {
  fs::path suite;      // folder
  std::string input;   // file name inside the folder
};

// Failure messages name the case, not its bytes.
void PrintTo(const GoldenCase& c, std::ostream* os) { *os << (c.suite / c.input).string(); }

using smtcal::test::ReadFileText;

// Both expectations are always recorded, an empty output as an empty file:
// a case without them is not a case that expects nothing.
void Write(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string Trim(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) {
    text.pop_back();
  }
  return text;
}

bool IsExpectation(const fs::path& path) {
  std::string ext = path.extension().string();
  return ext == ".out" || ext == ".err" || ext == ".args" || ext == ".exit" || path.filename() == "ARGS" ||
         path.filename().string().rfind('.', 0) == 0;  // hidden files, editor leftovers
}

std::vector<GoldenCase> DiscoverCases() {
  std::vector<GoldenCase> cases;
  fs::path root = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden";
  if (!fs::exists(root)) return cases;
  for (const auto& suite : fs::directory_iterator(root)) {
    if (!suite.is_directory() || !fs::exists(suite.path() / "ARGS")) continue;
    for (const auto& entry : fs::directory_iterator(suite.path())) {
      if (!entry.is_regular_file() || IsExpectation(entry.path())) continue;
      cases.push_back({suite.path(), entry.path().filename().string()});
    }
  }
  std::sort(cases.begin(), cases.end(), [](const GoldenCase& a, const GoldenCase& b) {
    return std::tie(a.suite, a.input) < std::tie(b.suite, b.input);
  });
  return cases;
}

std::string TestName(const testing::TestParamInfo<GoldenCase>& info) {
  std::string name = info.param.suite.filename().string() + "_" + info.param.input;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

std::string ShellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

class GoldenFiles : public testing::TestWithParam<GoldenCase> {};

TEST_P(GoldenFiles, MatchesExpectedOutput) {
  const GoldenCase& c = GetParam();
  fs::path stem = c.suite / fs::path(c.input).stem();
  fs::path args_file = fs::exists(stem.string() + ".args") ? fs::path(stem.string() + ".args")
                                                            : c.suite / "ARGS";
  std::string args = Trim(ReadFileText(args_file));
  for (std::size_t at; (at = args.find("{input}")) != std::string::npos;) {
    args.replace(at, 7, ShellQuote(c.input));
  }
  std::string scratch;
  if (args.find("{scratch}") != std::string::npos) {
    static int scratch_count = 0;
    scratch = (fs::temp_directory_path() / ("smtcal_golden_scratch_" + std::to_string(::getpid()) + "_" +
                                            std::to_string(++scratch_count)))
                  .string();
    fs::remove_all(scratch);
    fs::create_directories(scratch);
    for (std::size_t at; (at = args.find("{scratch}")) != std::string::npos;) {
      args.replace(at, 9, ShellQuote(scratch));
    }
  }
  smtcal::test::SmtcalRun run = smtcal::test::RunSmtcal(args, c.suite);
  ASSERT_NE(run.exit_code, -1) << run.command;
  if (!scratch.empty()) {
    // The folder's name changes from run to run; the expectations say {scratch}.
    for (std::string* text : {&run.out, &run.err}) {
      for (std::size_t at; (at = text->find(scratch)) != std::string::npos;) text->replace(at, scratch.size(), "{scratch}");
    }
    fs::remove_all(scratch);
  }

  bool must_fail = c.input.rfind("fail_", 0) == 0;
  int expected_exit = must_fail ? 1 : 0;
  if (fs::path exit_file = stem.string() + ".exit"; fs::exists(exit_file)) {
    expected_exit = std::stoi(Trim(ReadFileText(exit_file)));
  }
  EXPECT_EQ(run.exit_code, expected_exit) << "command: " << run.command << "\nstderr:\n" << run.err;

  fs::path expected_out = stem.string() + ".out";
  fs::path expected_err = stem.string() + ".err";
  const char* update = std::getenv("SMTCAL_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    Write(expected_out, run.out);
    Write(expected_err, run.err);
    return;
  }
  for (const fs::path& expected : {expected_out, expected_err}) {
    ASSERT_TRUE(fs::exists(expected)) << expected.string() << " is missing: record the case's expectations with "
                                      << "SMTCAL_UPDATE_GOLDEN=1 (an empty output is an empty file)";
  }
  EXPECT_EQ(run.out, ReadFileText(expected_out)) << "stdout of: " << run.command;
  EXPECT_EQ(run.err, ReadFileText(expected_err)) << "stderr of: " << run.command;
  if (must_fail) {
    EXPECT_NE(run.err.find("error"), std::string::npos) << "a fail_ case must report an error";
  }
}

INSTANTIATE_TEST_SUITE_P(Golden, GoldenFiles, testing::ValuesIn(DiscoverCases()), TestName);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(GoldenFiles);

}  // namespace
