// The driver's contract: exit codes, --help on every subcommand, --version,
// and atomic outputs. Runs the real smtcal executable.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

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

// An output that names one of the command's own inputs is refused (exit 2)
// before anything is read, and the input is left as it was.
TEST(Cli, OutputThatWouldOverwriteAnInputIsRefused) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_cli_overwrite_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path example = fs::path(SMTCAL_SOURCE_DIR) / "examples" / "paper-cell";
  for (const char* name : {"layers.place", "placing-table.csv"}) fs::copy_file(example / name, dir / name);
  const std::string program = smtcal::test::ReadFileText(dir / "layers.place");
  const std::string table = smtcal::test::ReadFileText(dir / "placing-table.csv");
  const std::string cell = (example / "paper.cell.toml").string();
  struct Case {
    std::string args;
    const char* output;
  };
  const std::vector<Case> cases = {
      {fmt::format("compile layers.place --cell {} -o layers.place", cell), "layers.place"},
      {fmt::format("compile layers.place --cell {} -o out.place --report layers.place", cell), "layers.place"},
      {fmt::format("compile layers.place --cell {} --target linuxcnc -o .", cell), "."},
      {"fmt layers.place -o layers.place", "layers.place"},
      {"table build placing-table.csv -o placing-table.csv", "placing-table.csv"},
      {"table plot placing-table.csv -o placing-table.csv", "placing-table.csv"},
      {fmt::format("simulate layers.place --cell {} --cycles 1 --svg layers.place", cell), "layers.place"},
      {"diff layers.place layers.place --svg layers.place", "layers.place"},
      {fmt::format("import placing-table.csv --cell {} -o placing-table.csv", cell), "placing-table.csv"},
  };
  for (const Case& c : cases) {
    SmtcalRun run = smtcal::test::RunSmtcal(c.args, dir);
    EXPECT_EQ(run.exit_code, 2) << c.args << "\n" << run.err;
    EXPECT_NE(run.err.find("would overwrite the input"), std::string::npos) << c.args << "\n" << run.err;
  }
  EXPECT_EQ(smtcal::test::ReadFileText(dir / "layers.place"), program);
  EXPECT_EQ(smtcal::test::ReadFileText(dir / "placing-table.csv"), table);
  fs::remove_all(dir);
}

}  // namespace

// The README shows docs/images/paper-cell.svg as what `smtcal cell plot`
// draws for the example; it must stay exactly that picture.
// SMTCAL_UPDATE_GOLDEN=1 rewrites it (review it as a PNG before committing).
TEST(Cli, ReadmePictureOfTheExampleCellIsWhatCellPlotDraws) {
  const std::filesystem::path root(SMTCAL_SOURCE_DIR);
  smtcal::test::SmtcalRun run = smtcal::test::RunSmtcal(
      "cell plot examples/paper-cell/paper.cell.toml --program examples/paper-cell/layers.place -o -", root);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::filesystem::path picture = root / "docs" / "images" / "paper-cell.svg";
  const char* update = std::getenv("SMTCAL_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    std::ofstream(picture, std::ios::binary) << run.out;
    return;
  }
  EXPECT_EQ(run.out, smtcal::test::ReadFileText(picture))
      << "docs/images/paper-cell.svg is not what `smtcal cell plot` draws; rewrite it with SMTCAL_UPDATE_GOLDEN=1";
}
