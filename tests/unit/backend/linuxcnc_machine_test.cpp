// The LinuxCNC machine's configuration derived from the cell
// (backend/linuxcnc/linuxcnc_machine.h, docs/linuxcnc.md "The machine's
// configuration"), through the real smtcal executable: the example's INI
// and HAL agree with the cell and get the runtime in their SUBROUTINE_PATH
// folder, shared by every program; a disagreement names both values and
// writes nothing; the machine a compile writes passes the check; a program
// run with another cell's runtime aborts before it moves (rs274); the dry
// run's rs274.ini runs the whole program.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "tests/unit/backend/rs274_runner.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = SMTCAL_SOURCE_DIR;
const fs::path kProgram = kSource / "examples" / "paper-cell" / "layers.place";
const fs::path kCell = kSource / "examples" / "paper-cell" / "paper.cell.toml";
const fs::path kMachine = kSource / "examples" / "linuxcnc";

std::string Quote(const fs::path& path) { return "'" + path.string() + "'"; }

// A scratch folder with a copy of the example machine (paper-cell.*).
fs::path MachineCopy(const std::string& name) {
  static int count = 0;
  fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_machine_{}_{}_{}", name, ::getpid(), ++count);
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const fs::directory_entry& entry : fs::directory_iterator(kMachine)) {
    if (entry.path().filename().string().starts_with("paper-cell")) fs::copy_file(entry.path(), dir / entry.path().filename());
  }
  return dir;
}

test::SmtcalRun Compile(const fs::path& cell, const std::string& more, const fs::path& outdir) {
  return test::RunSmtcal(fmt::format("compile {} --cell {} --target linuxcnc {} -o {}", Quote(kProgram), Quote(cell),
                                     more, Quote(outdir)));
}

void Replace(const fs::path& file, const std::string& from, const std::string& to) {
  std::string text = test::ReadFileText(file);
  const std::size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from << " in " << file;
  text.replace(at, from.size(), to);
  std::ofstream(file, std::ios::binary) << text;
}

std::vector<std::string> Names(const fs::path& dir) {
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(LinuxCncMachine, ExampleIniAgreesAndGetsTheRuntime) {
  const fs::path machine = MachineCopy("example");
  test::SmtcalRun run = Compile(kCell, "--ini " + Quote(machine / "paper-cell.ini"), machine / "layers");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find("warning"), std::string::npos) << run.err;
  // The runtime where the INI's SUBROUTINE_PATH says, the program alone in -o.
  EXPECT_EQ(Names(machine / "layers"), std::vector<std::string>{"layers.ngc"});
  EXPECT_TRUE(fs::exists(machine / "runtime" / "smtcal_data.ngc"));
  EXPECT_TRUE(fs::exists(machine / "runtime" / "smtcal_probe_trips.ngc"));
  // A second program (here the same one under another name) shares it.
  fs::copy_file(kProgram, machine / "bottom.place");
  test::SmtcalRun second = test::RunSmtcal(
      fmt::format("compile {} --cell {} --target linuxcnc --ini {} -o {}", Quote(machine / "bottom.place"),
                  Quote(kCell), Quote(machine / "paper-cell.ini"), Quote(machine / "bottom")));
  ASSERT_EQ(second.exit_code, 0) << second.err;
  EXPECT_EQ(Names(machine / "bottom"), std::vector<std::string>{"bottom.ngc"});
  // The headless INI includes it: the same check passes.
  test::SmtcalRun headless = Compile(kCell, "--ini " + Quote(machine / "paper-cell-headless.ini"), machine / "h");
  EXPECT_EQ(headless.exit_code, 0) << headless.err;
  fs::remove_all(machine);
}

TEST(LinuxCncMachine, DisagreementNamesBothValuesAndWritesNothing) {
  const fs::path machine = MachineCopy("disagree");
  // X's speed, and the vacuum switch's input unwired.
  std::string ini = test::ReadFileText(machine / "paper-cell.ini");
  ini = std::regex_replace(ini, std::regex("\\[AXIS_X\\]\nMIN_LIMIT = 0\nMAX_LIMIT = 400\nMAX_VELOCITY = 800"),
                           "[AXIS_X]\nMIN_LIMIT = 0\nMAX_LIMIT = 400\nMAX_VELOCITY = 700");
  std::ofstream(machine / "paper-cell.ini", std::ios::binary) << ini;
  Replace(machine / "paper-cell.hal", "net vacuum-valve => motion.digital-in-11", "");
  test::SmtcalRun run = Compile(kCell, "--ini " + Quote(machine / "paper-cell.ini"), machine / "layers");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("error: [AXIS_X]MAX_VELOCITY = 700 disagrees with the cell: robot.xy_speed_mm_s = 800 needs "
                         "MAX_VELOCITY = 800"),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("motion.digital-in-11 (vacuum_sensor_input 11) is on no net"),
            std::string::npos)
      << run.err;
  EXPECT_FALSE(fs::exists(machine / "layers"));
  EXPECT_FALSE(fs::exists(machine / "runtime"));
  fs::remove_all(machine);
}

TEST(LinuxCncMachine, TheWrittenMachinePassesTheCheck) {
  const fs::path dir = MachineCopy("written");
  test::SmtcalRun run = Compile(kCell, "", dir / "job");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const char* name : {"layers.ngc", "layers.ini", "layers.hal", "layers.tbl", "layers.var", "subroutines"}) {
    EXPECT_TRUE(fs::exists(dir / "job" / name)) << name;
  }
  const std::string ini = test::ReadFileText(dir / "job" / "layers.ini");
  EXPECT_NE(ini.find("SUBROUTINE_PATH = subroutines"), std::string::npos);
  EXPECT_NE(ini.find("OPEN_FILE = layers.ngc"), std::string::npos);
  test::SmtcalRun checked = Compile(kCell, "--ini " + Quote(dir / "job" / "layers.ini"), dir / "again");
  EXPECT_EQ(checked.exit_code, 0) << checked.err;
  EXPECT_EQ(checked.err.find("warning"), std::string::npos) << checked.err;
  // Compiling again replaces the machine's files too.
  test::SmtcalRun again = Compile(kCell, "", dir / "job");
  EXPECT_EQ(again.exit_code, 0) << again.err;
  fs::remove_all(dir);
}

TEST(LinuxCncMachine, AnotherCellsRuntimeIsRefusedBeforeAnyMove) {
  const fs::path dir = MachineCopy("other");
  // The same cell with the feeder table re-measured: other data.
  fs::create_directories(dir / "remeasured");
  for (const fs::directory_entry& entry : fs::directory_iterator(kCell.parent_path())) {
    fs::copy_file(entry.path(), dir / "remeasured" / entry.path().filename());
  }
  std::string table = test::ReadFileText(dir / "remeasured" / "feeders-table.csv");
  table = std::regex_replace(table, std::regex("(\nx,[^,]*,[^,]*,)(-?[0-9.]+)"), "$01" "0.0123");  // $01: group 1 ($10 would be group 10)
  std::ofstream(dir / "remeasured" / "feeders-table.csv", std::ios::binary) << table;
  ASSERT_EQ(Compile(kCell, "", dir / "a").exit_code, 0);
  test::SmtcalRun b = Compile(dir / "remeasured" / "paper.cell.toml", "", dir / "b");
  ASSERT_EQ(b.exit_code, 0) << b.err;
  ASSERT_NE(test::ReadFileText(dir / "a" / "subroutines" / "smtcal_data.ngc"),
            test::ReadFileText(dir / "b" / "subroutines" / "smtcal_data.ngc"));
  const fs::path ini = test::WriteRs274Ini(dir / "ini", {dir / "b" / "subroutines"});
  const test::Rs274Result rs274 = test::RunRs274(ini, dir / "a" / "layers.ngc");
  EXPECT_NE(rs274.exit_code, 0);
  EXPECT_NE(rs274.err.find("smtcal: the runtime on SUBROUTINE_PATH is not the one this program was compiled with"),
            std::string::npos)
      << rs274.err;
  for (const test::CanonMove& move : rs274.moves) ADD_FAILURE() << "moved: " << move.kind;
  fs::remove_all(dir);
}

TEST(LinuxCncMachine, DryRunIniRunsTheWholeProgram) {
  const fs::path machine = MachineCopy("dry");
  test::SmtcalRun run =
      Compile(kCell, "--ini " + Quote(machine / "paper-cell.ini") + " --dry-run-probe", machine / "layers");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string ini = test::ReadFileText(machine / "layers" / "dry-run" / "rs274.ini");
  EXPECT_NE(ini.find(fmt::format("SUBROUTINE_PATH = {}:{}", (machine / "layers" / "dry-run").string(),
                                 (machine / "runtime").string())),
            std::string::npos)
      << ini;
  const test::Rs274Result rs274 = test::RunRs274(machine / "layers" / "dry-run" / "rs274.ini", machine / "layers" / "layers.ngc");
  EXPECT_EQ(rs274.exit_code, 0) << rs274.err.substr(0, 2000);
  EXPECT_NE(std::find(rs274.canon.begin(), rs274.canon.end(), "PROGRAM_END()"), rs274.canon.end());
  fs::remove_all(machine);
}

}  // namespace
}  // namespace smtcal
