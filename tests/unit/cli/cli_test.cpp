// The driver's contract: exit codes, --help on every subcommand, --version,
// and atomic outputs. Runs the real smtcal executable.
#include <string>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "tests/unit/test_support.h"

namespace {

using smtcal::test::SmtcalRun;

SmtcalRun RunSmtcal(const std::string& args) { return smtcal::test::RunSmtcal(args); }

TEST(Cli, VersionAndHelp) {
  SmtcalRun version = RunSmtcal("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find("smtcal "), std::string::npos);

  SmtcalRun help = RunSmtcal("--help");
  EXPECT_EQ(help.exit_code, 0);
  for (const char* word : {"check", "fmt", "table", "Exit codes"}) {
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  }
}

TEST(Cli, EverySubcommandHasHelp) {
  for (const char* sub : {"check", "fmt", "table"}) {
    SmtcalRun help = RunSmtcal(fmt::format("{} --help", sub));
    EXPECT_EQ(help.exit_code, 0) << sub;
    EXPECT_NE(help.out.find("Usage"), std::string::npos) << sub;
  }
}

TEST(Cli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(RunSmtcal("").exit_code, 2);
  EXPECT_EQ(RunSmtcal("no-such-command").exit_code, 2);
  EXPECT_EQ(RunSmtcal("check").exit_code, 2);
  EXPECT_EQ(RunSmtcal("check --no-such-flag x.place").exit_code, 2);
  EXPECT_EQ(RunSmtcal("--diagnostics=xml check x.place").exit_code, 2);
}

TEST(Cli, UnreadableInputExitsWithThree) {
  SmtcalRun missing = RunSmtcal("check /nonexistent/dir/x.place");
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.err.find("cannot open '/nonexistent/dir/x.place'"), std::string::npos)
      << missing.err;
}

}  // namespace
