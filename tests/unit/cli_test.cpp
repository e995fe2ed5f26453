// The driver's contract: exit codes, --help on every subcommand, --version,
// and atomic outputs. Runs the real smtcal executable.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/core.h>
#include <gtest/gtest.h>

namespace fs = std::filesystem;

namespace {

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string Slurp(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

RunResult RunSmtcal(const std::string& args) {
  fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_cli_{}", ::getpid());
  fs::create_directories(dir);
  std::string command = fmt::format("{} {} </dev/null >{} 2>{}", SMTCAL_BINARY, args,
                                    (dir / "out").string(), (dir / "err").string());
  int status = std::system(command.c_str());
  RunResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = Slurp(dir / "out");
  result.err = Slurp(dir / "err");
  fs::remove_all(dir);
  return result;
}

TEST(Cli, VersionAndHelp) {
  RunResult version = RunSmtcal("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find("smtcal "), std::string::npos);

  RunResult help = RunSmtcal("--help");
  EXPECT_EQ(help.exit_code, 0);
  for (const char* word : {"check", "fmt", "table", "Exit codes"}) {
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  }
}

TEST(Cli, EverySubcommandHasHelp) {
  for (const char* sub : {"check", "fmt", "table"}) {
    RunResult help = RunSmtcal(fmt::format("{} --help", sub));
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
  RunResult missing = RunSmtcal("check /nonexistent/dir/x.place");
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.err.find("cannot open '/nonexistent/dir/x.place'"), std::string::npos)
      << missing.err;
}

}  // namespace
