// Hostile values on the command line and in the files (issue 31): every
// numeric option of every command refuses NaN, the infinities, overflows, a
// negative zero and an empty value with a usage error naming the option; the
// files of a command never clash; what smtcal writes on stderr is valid UTF-8
// (one JSON document with --diagnostics=json); work is bounded before it
// starts. Each finding of the issue is a case below that failed before.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/unit/test_support.h"
#include "tests/unit/utf8_oracle.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;
using test::SmtcalRun;

const fs::path kSource = SMTCAL_SOURCE_DIR;
const fs::path kExample = kSource / "examples" / "paper-cell";
const fs::path kGolden = kSource / "tests" / "golden";

std::string Quote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}
std::string Q(const fs::path& path) { return Quote(path.string()); }

using test::IsWellFormedUtf8;

// A scratch folder for each test, removed after it.
class Hostile : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           fmt::format("smtcal_hostile_{}_{}", ::getpid(), testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  SmtcalRun Smtcal(const std::string& args, const std::string& stdin_text = "") {
    return test::RunSmtcal(args, dir_, stdin_text);
  }
  fs::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }

  fs::path dir_;
};

// ------------------------------------------------------------------ the sweep

struct OptionHelp {
  std::string name;  // the long name: --threshold
  std::string type;  // NUMBER, INTEGER, X,Y, CxR, TEXT, ... ("" for a flag)
};

// The options of one (sub)command as its --help lists them, and its
// subcommands.
struct CommandHelp {
  std::vector<OptionHelp> options;
  std::vector<std::string> subcommands;
};

CommandHelp ReadHelp(const std::string& command) {
  SmtcalRun help = test::RunSmtcal(command + " --help");
  EXPECT_EQ(help.exit_code, 0) << command;
  CommandHelp result;
  std::string section;
  std::istringstream lines(help.out);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line.back() == ':' && line.front() != ' ') {
      section = line;
      continue;
    }
    static const std::regex kOption(R"(^  (?:-\w,)?(--[\w-]+)(?: (\S+))?)");
    static const std::regex kSubcommand(R"(^  ([a-z]+)\s)");
    std::smatch match;
    if (section == "Options:" && std::regex_search(line, match, kOption)) {
      // The type follows the names after one space; a flag's description
      // after the padding.
      const std::string after = line.substr(match.position(1) + match.length(1));
      const bool typed = after.size() > 1 && after[0] == ' ' && after[1] != ' ';
      std::string type = typed ? std::string(match[2]) : std::string();
      type = type.substr(0, type.find_first_of("=:"));  // NUMBER=10, TEXT:{text,json}=text
      result.options.push_back({match[1], type});
    } else if (section == "Subcommands:" && std::regex_search(line, match, kSubcommand)) {
      result.subcommands.push_back(match[1]);
    }
  }
  return result;
}

// A real command line for every command, without the option under test, so
// a value that slipped through would run the command on real inputs.
std::map<std::string, std::string> BaseCommands(const fs::path& scratch) {
  const std::string program = Q(kExample / "layers.place"), cell = Q(kExample / "paper.cell.toml");
  const std::string table = Q(kExample / "placing-table.csv");
  return {
      {"check", "check " + program},
      {"fmt", "fmt " + program},
      {"table build", fmt::format("table build {} -o {}", Q(kExample / "placing-raw.csv"), Q(scratch / "t.csv"))},
      {"table check", "table check " + table},
      {"table stats", "table stats " + table},
      {"table forward", fmt::format("table forward {} {}", Q(kGolden / "tables-solve/table.csv"),
                                    Q(kGolden / "tables-solve/paper.csv"))},
      {"table inverse", fmt::format("table inverse {} {} --solver paper", Q(kGolden / "tables-solve/table.csv"),
                                    Q(kGolden / "tables-solve/paper.csv"))},
      {"table plot", fmt::format("table plot {} -o {}", table, Q(scratch / "t.svg"))},
      {"table diff", fmt::format("table diff {} {}", table, table)},
      {"compile", fmt::format("compile {} --cell {} -o {}", program, cell, Q(scratch / "c.place"))},
      {"verify", fmt::format("verify {} --cell {}", program, cell)},
      {"fixture", fmt::format("fixture --cell {} --fixture Board --trips {}", Q(kGolden / "fixture/data/board.cell.toml"),
                              Q(kGolden / "fixture/scan.csv"))},
      {"import", fmt::format("import {} --cell {} --feeders {} -o {}", Q(kGolden / "import-data/board.csv"),
                             Q(kGolden / "import-data/cell.toml"), Q(kGolden / "import-data/feeders.toml"),
                             Q(scratch / "i.place"))},
      {"cell check", "cell check " + cell},
      {"diff", fmt::format("diff {} {}", Q(kGolden / "diff/threshold_default.place"),
                           Q(kGolden / "diff/new/threshold_default.place"))},
      {"simulate", fmt::format("simulate {} --cell {} --cycles 2", program, cell)},
      {"measure plan", fmt::format("measure plan --cell {} -o {}", Q(kExample.parent_path() / "calibrating/scratch.cell.toml"),
                                   Q(scratch / "plan.csv"))},
      {"measure program", fmt::format("measure program {} --cell {} -o {}", Q(kGolden / "measure-read/data/plan.csv"),
                                      Q(kGolden / "measure-read/data/cell.toml"), Q(scratch / "measure"))},
      {"monitor", fmt::format("monitor {} --cell {}", Q(kGolden / "monitor/in_control.log"), cell)},
  };
}

// The values no numeric option may take: each must be a usage error naming
// the option, never a run (exit 0 or 1) and never a crash. (More spellings
// are in base's NumberRange tests; these are the issue's.) Each is given as
// --opt=VALUE; the first two also as --opt VALUE, where a value with a
// leading '-' must not be taken for an option.
const std::vector<std::string> kHostile = {"nan", "-inf", "inf", "1e308", "-1e308", "-0", "0x10"};
constexpr std::size_t kBothForms = 2;

TEST_F(Hostile, EveryNumericOptionOfEveryCommandRefusesWhatIsNotANumberInItsRange) {
  const std::map<std::string, std::string> bases = BaseCommands(dir_);
  std::vector<std::string> pending = {""};
  std::set<std::string> commands_seen;
  int swept = 0;
  while (!pending.empty()) {
    const std::string command = pending.back();
    pending.pop_back();
    const CommandHelp help = ReadHelp(command);
    for (const std::string& sub : help.subcommands) pending.push_back(command.empty() ? sub : command + " " + sub);
    if (command.empty() || !help.subcommands.empty()) continue;
    commands_seen.insert(command);
    for (const OptionHelp& option : help.options) {
      // CLI11's own conversions take nan, inf, hex and wrap -1 into an
      // unsigned: a numeric option goes through AddNumberOption.
      for (const char* raw : {"FLOAT", "INT", "UINT", "NONNEGATIVE", "POSITIVE", "DOUBLE"}) {
        EXPECT_NE(option.type, raw)
            << "smtcal " << command << " " << option.name << " " << option.type
            << ": a number read by CLI11 alone; use AddNumberOption (tools/commands.h)";
      }
      // A compound option (X,Y or CxR) gets each value in its first number,
      // and the first value in its second too.
      std::vector<std::string> values;
      if (option.type == "NUMBER" || option.type == "INTEGER") {
        values = kHostile;
      } else if (option.type == "X,Y") {
        for (const std::string& v : kHostile) values.push_back(v + ",0");
        values.push_back("0," + kHostile.front());
      } else if (option.type == "W,H") {
        for (const std::string& v : kHostile) values.push_back(v + ",10");
        values.push_back("10," + kHostile.front());
      } else if (option.type == "CxR") {
        for (const std::string& v : kHostile) values.push_back(v + "x1");
        values.push_back("1x" + kHostile.front());
      } else {
        continue;
      }
      ASSERT_TRUE(bases.contains(command)) << "no base command line for `smtcal " << command
                                           << "`: add one to BaseCommands";
      values.push_back("");  // --opt= : no value
      for (std::size_t v = 0; v < values.size(); ++v) {
        const std::string& value = values[v];
        std::vector<std::string> forms = {fmt::format("{}={}", option.name, Quote(value))};
        if (v < kBothForms) forms.push_back(fmt::format("{} {}", option.name, Quote(value)));
        for (const std::string& form : forms) {
          SmtcalRun run = Smtcal(bases.at(command) + " " + form);
          ++swept;
          EXPECT_EQ(run.exit_code, 2) << "smtcal " << command << " " << form << "\n" << run.err;
          EXPECT_NE(run.err.find(option.name), std::string::npos)
              << "smtcal " << command << " " << form << ": the message does not name the option\n"
              << run.err;
          EXPECT_TRUE(run.out.empty()) << "smtcal " << command << " " << form << " printed a result";
        }
      }
    }
  }
  EXPECT_TRUE(commands_seen.contains("simulate") && commands_seen.contains("table inverse"));
  EXPECT_GE(swept, 12 * 10) << "the sweep found fewer numeric options than smtcal has (12)";
}

// The issue's command lines, exactly.
TEST_F(Hostile, TheIssuesCommandLinesAreUsageErrors) {
  const std::string diff = fmt::format("diff {} {}", Q(kGolden / "diff/threshold_default.place"),
                                       Q(kGolden / "diff/new/threshold_default.place"));
  EXPECT_EQ(Smtcal(diff).exit_code, 1) << "the gate fails without the option";
  for (const char* threshold : {"nan", "1e308"}) {
    SmtcalRun run = Smtcal(diff + " --threshold " + threshold);
    EXPECT_EQ(run.exit_code, 2) << threshold << "\n" << run.out << run.err;
    EXPECT_NE(run.err.find("--threshold"), std::string::npos) << run.err;
    EXPECT_NE(run.err.find("a number from 0 to 1000000 µm"), std::string::npos) << run.err;
  }
  const std::string import =
      fmt::format("import {} --cell {} --feeders {} -o -", Q(kGolden / "import-data/board.csv"),
                  Q(kGolden / "import-data/cell.toml"), Q(kGolden / "import-data/feeders.toml"));
  for (const char* option : {"--rotation nan", "--place-z nan", "--place-z= --vacuum 8", "--place-z=", "--vacuum -0"}) {
    SmtcalRun run = Smtcal(import + " " + option);
    EXPECT_EQ(run.exit_code, 2) << option << "\n" << run.err;
    EXPECT_TRUE(run.out.empty()) << option;
  }
  SmtcalRun paper = Smtcal(fmt::format("table inverse {} {} --solver paper --paper-tolerance nan",
                                       Q(kGolden / "tables-solve/table.csv"), Q(kGolden / "tables-solve/paper.csv")));
  EXPECT_EQ(paper.exit_code, 2) << paper.err;
  const std::string simulate =
      fmt::format("simulate {} --cell {}", Q(kExample / "layers.place"), Q(kExample / "paper.cell.toml"));
  for (const char* option : {"--dirty-marker-mm nan", "--missed-trip-rate nan", "--seed -1", "--seed 18446744073709551616",
                             "--cycles 1e3"}) {
    SmtcalRun run = Smtcal(simulate + " " + option);
    EXPECT_EQ(run.exit_code, 2) << option << "\n" << run.err;
    EXPECT_TRUE(run.out.empty()) << option;
  }
  // The largest seed is a seed.
  EXPECT_EQ(Smtcal(simulate + " --seed 18446744073709551615 --cycles 1").exit_code, 0);
}

// ------------------------------------------------------------------ work bounded

TEST_F(Hostile, SimulateRefusesCellsThatWouldMakeItRunForHours) {
  const std::string cell = test::ReadFileText(kExample / "paper.cell.toml");
  for (const fs::directory_entry& entry : fs::directory_iterator(kExample)) {
    if (entry.path().extension() == ".csv") fs::create_symlink(entry.path(), dir_ / entry.path().filename());
  }
  struct Case {
    std::string from, to;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"x_mm = [0, 400]", "x_mm = [-1e17, 400]", "'x_mm' = -1e+17 is out of range"},
      {"uncalibrated_correlation_mm = 25", "uncalibrated_correlation_mm = 1e-300",
       "'uncalibrated_correlation_mm' = 1e-300 is out of range"},
      {"uncalibrated_correlation_mm = 25", "uncalibrated_correlation_mm = 0.5", "CellTrueFieldTooFine"},
  };
  for (const Case& c : cases) {
    std::string text = cell;
    text.replace(text.find(c.from), c.from.size(), c.to);
    Write("hostile.cell.toml", text);
    SmtcalRun check = Smtcal("cell check hostile.cell.toml");
    EXPECT_EQ(check.exit_code, 1) << c.to << "\n" << check.err;
    SmtcalRun simulate =
        Smtcal(fmt::format("--diagnostics=json simulate {} --cell hostile.cell.toml --cycles 1", Q(kExample / "layers.place")));
    EXPECT_EQ(simulate.exit_code, 1) << c.to;
    EXPECT_NE(simulate.err.find(c.says), std::string::npos) << c.to << "\n" << simulate.err;
  }
  // A truth file's correlation length against the cell's reach.
  Write("fine.truth.toml", "[robot]\nuncalibrated_correlation_mm = 0.1\n");
  SmtcalRun truth = Smtcal(fmt::format("simulate {} --cell {} --truth fine.truth.toml --cycles 1",
                                       Q(kExample / "layers.place"), Q(kExample / "paper.cell.toml")));
  EXPECT_EQ(truth.exit_code, 1) << truth.err;
  EXPECT_NE(truth.err.find("uncalibrated_correlation_mm = 0.1 with the cell's robot reach"), std::string::npos)
      << truth.err;
}

// Cycles x placements: bounded before the run, whatever the machine's memory.
TEST_F(Hostile, SimulateBoundsCyclesTimesPlacements) {
  std::string program = test::ReadFileText(kExample / "layers.place");
  // The example's cycle three times over (40 placements each): 100000
  // cycles of it are 1.2e7 placements, more than the 1e7 a run takes.
  const std::string main = "Function Main\n";
  ASSERT_NE(program.find(main), std::string::npos);
  program.insert(program.find(main) + main.size(), "  Integer k\n");
  const std::string cycle = "Cycle Board";
  const std::size_t at = program.find(cycle);
  ASSERT_NE(at, std::string::npos);
  program.insert(at + cycle.size(), "\n    For k = 1 To 3");
  const std::size_t end = program.find("EndCycle");
  program.insert(end, "Next\n    ");
  Write("many.place", program);
  SmtcalRun run = Smtcal(fmt::format("simulate many.place --cell {} --cycles 100000", Q(kExample / "paper.cell.toml")));
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("give --cycles"), std::string::npos) << run.err;
  EXPECT_TRUE(run.out.empty());
}

// ------------------------------------------------------------------ files that clash

TEST_F(Hostile, TwoOutputsOnOneFileAreAUsageErrorHoweverSpelled) {
  const std::string compile =
      fmt::format("compile {} --cell {}", Q(kExample / "layers.place"), Q(kExample / "paper.cell.toml"));
  fs::create_directories(dir_ / "sub");
  fs::create_symlink(dir_ / "X", dir_ / "link");
  for (const char* outputs : {"-o X --report X", "-o X --report ./X", "-o X --report sub/../X", "-o link --report X",
                              "-o - --report -", "-o out --target linuxcnc --report out/r.json"}) {
    SmtcalRun run = Smtcal(compile + " " + outputs);
    EXPECT_EQ(run.exit_code, 2) << outputs << "\n" << run.err;
    EXPECT_FALSE(fs::exists(dir_ / "X")) << outputs << ": something was written";
    EXPECT_FALSE(fs::exists(dir_ / "out")) << outputs << ": something was written";
    EXPECT_TRUE(run.out.empty()) << outputs;
  }
  EXPECT_EQ(Smtcal(compile + " -o X --report Y").exit_code, 0);
  // An implicit standard output counts too: the diff's report.
  SmtcalRun svg = Smtcal(fmt::format("diff {} {} --svg -", Q(kGolden / "diff/threshold_default.place"),
                                     Q(kGolden / "diff/new/threshold_default.place")));
  EXPECT_EQ(svg.exit_code, 2) << svg.err;
}

TEST_F(Hostile, StandardInputNamedForTwoInputsIsAUsageError) {
  const std::string cell = Q(kExample / "paper.cell.toml");
  const std::string fixture_cell = Q(kGolden / "fixture/data/board.cell.toml");
  const std::vector<std::string> commands = {
      fmt::format("simulate - --cell {} --truth -", cell),
      fmt::format("fixture --cell {} --fixture Board --trips - --previous -", fixture_cell),
      fmt::format("fixture --cell - --fixture Board --trips -"),
      fmt::format("import - --cell {} --feeders - -o out.place", Q(kGolden / "import-data/cell.toml")),
      "table inverse - -",
      "table inverse -",  // POINTS is standard input unless given
      "table forward - -",
      fmt::format("verify - --cell -"),
      fmt::format("compile - --cell - -o out.place"),
      "diff - -",
  };
  for (const std::string& command : commands) {
    SmtcalRun run = Smtcal(command, test::ReadFileText(kExample / "layers.place"));
    EXPECT_EQ(run.exit_code, 2) << command << "\n" << run.err;
    EXPECT_NE(run.err.find("standard input ('-') is named by both"), std::string::npos) << command << "\n" << run.err;
  }
}

// A compile killed while writing its LinuxCNC folder leaves OUT.tmp.PID; the
// next compile removes it (as a file output's stale temporary), and leaves
// a running writer's and anything not its own alone.
TEST_F(Hostile, StaleLinuxCncFoldersOfKilledCompilesAreRemoved) {
  pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) ::_exit(0);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);
  const fs::path stale = dir_ / fmt::format("out.tmp.{}", child);
  const fs::path alive = dir_ / fmt::format("out.tmp.{}", ::getpid());
  const fs::path other = dir_ / "out.tmp.notapid";
  for (const fs::path& folder : {stale, alive, other}) fs::create_directories(folder / "subroutines");
  std::ofstream(stale / "layers.ngc") << "(half";
  SmtcalRun run = Smtcal(fmt::format("compile {} --cell {} --target linuxcnc -o out", Q(kExample / "layers.place"),
                                     Q(kExample / "paper.cell.toml")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "layers.ngc"));
}

// ------------------------------------------------------------------ stderr

// Bytes that are not UTF-8 in every reader's input, in file names and on
// the command line: standard error stays valid UTF-8, in text and JSON.
TEST_F(Hostile, StandardErrorIsAlwaysValidUtf8) {
  const std::vector<std::string> bad = {"\xC0\xAF", "\xED\xA0\x80", "\xF4\x90\x80\x80", "\xE0\x80\xAF", "\xF0\x80\x80\xAF",
                                        "\xFF", "\x1b[31m"};
  std::string bytes;
  for (const std::string& b : bad) bytes += b;
  Write("bad.place", "Program P\nUnits mm\nFunction Main\n  Jump " + bytes + "\nFend\n");
  Write("bad-name.place", "Program P\nUnits mm\nFunction Main\n  Jump X" + bytes + "\nFend\n");
  Write("bad.csv", "axis,x_mm,y_mm,error_mm\nx,0,0," + bytes + "\n");
  Write("bad.cell.toml", "name = \"" + bytes + "\"\n[robot]\n" + bytes + " = 1\n");
  Write("bad-trips.csv", "name,x_mm,y_mm\nT1," + bytes + ",0\n");
  Write("bad.json", bytes + "{");
  Write("bad-list.csv", "Ref,Val,Package,PosX,PosY,Rot,Side\n\"C1" + bytes + "\",\"1\",\"0603\",1,2,0,top\n");
  Write("bad-feeders.toml", "[[feeder]]\nname = \"" + bytes + "\"\n" + bytes + "\n");
  Write("bad.truth.toml", "[field]\n" + bytes + " = 1\n");
  const std::string cell = Q(kExample / "paper.cell.toml"), program = Q(kExample / "layers.place");
  const std::string fixture_cell = Q(kGolden / "fixture/data/board.cell.toml");
  const std::vector<std::string> commands = {
      "check bad.place",
      "check bad-name.place",
      "table check bad.csv",
      "cell check bad.cell.toml",
      fmt::format("fixture --cell {} --fixture Board --trips bad-trips.csv", fixture_cell),
      fmt::format("fixture --cell {} --fixture Board --trips {} --previous bad.json", fixture_cell,
                  Q(kGolden / "fixture/scan.csv")),
      fmt::format("import bad-list.csv --cell {} --feeders {} -o -", Q(kGolden / "import-data/cell.toml"),
                  Q(kGolden / "import-data/feeders.toml")),
      fmt::format("import {} --cell {} --feeders bad-feeders.toml -o -", Q(kGolden / "import-data/board.csv"),
                  Q(kGolden / "import-data/cell.toml")),
      fmt::format("simulate {} --cell {} --truth bad.truth.toml", program, cell),
      Quote("check missing" + bytes + ".place"),
      Quote("--bogus" + bytes),
      "diff " + Quote("a" + bytes) + " " + Quote("b" + bytes),
      fmt::format("fixture --cell {} --fixture {} --trips bad-trips.csv", fixture_cell, Quote("B" + bytes)),
  };
  for (const std::string& command : commands) {
    for (const char* format : {"", "--diagnostics=json "}) {
      SmtcalRun run = Smtcal(format + command);
      EXPECT_NE(run.exit_code, 0) << format << command;
      EXPECT_TRUE(IsWellFormedUtf8(run.err)) << format << command << "\n" << run.err;
      EXPECT_EQ(run.err.find('\x1b'), std::string::npos) << format << command << ": a raw escape reached the terminal";
      if (*format != '\0') {
        EXPECT_TRUE(nlohmann::json::accept(run.err)) << command << "\n" << run.err;
      }
    }
  }
  // The source line under a diagnostic shows '?' for each byte, a message \xNN.
  SmtcalRun check = Smtcal("check bad-name.place");
  EXPECT_NE(check.err.find("Jump X??????????"), std::string::npos) << check.err;
  SmtcalRun previous = Smtcal(commands[5]);
  EXPECT_NE(previous.err.find("last read: '\\xc0'"), std::string::npos) << previous.err;
}

// Notes quote names too: cut after 1000 bytes like messages.
TEST_F(Hostile, NotesAreCutLikeMessages) {
  const std::string name(5000, 'n');
  Write("long.place", "Program P\nUnits mm\nFunction Main\n  For " + name + " = 1 To 2\n  Next other\nFend\n");
  SmtcalRun run = Smtcal("check long.place");
  ASSERT_EQ(run.exit_code, 1) << run.err;
  std::istringstream lines(run.err);
  bool note = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.find(": note: ") == std::string::npos) continue;
    note = true;
    EXPECT_LE(line.size() - line.find(": note: "), 1000u + 20) << line.substr(0, 200);
    EXPECT_TRUE(line.ends_with("...")) << line.substr(line.size() - 50);
  }
  EXPECT_TRUE(note) << run.err.substr(0, 500);
}

// --diagnostics=json: stderr is one JSON document, whatever happened.
TEST_F(Hostile, JsonDiagnosticsAreOneDocumentOnStandardError) {
  const std::string program = Q(kExample / "layers.place"), cell = Q(kExample / "paper.cell.toml");
  struct Case {
    std::string args;
    int exit_code;
  };
  const std::vector<Case> cases = {
      {"check " + program, 0},
      {fmt::format("compile {} --cell {} -o out.place", program, cell), 0},
      {"fmt " + program + " -o f.place", 0},
      {fmt::format("table build {} -o t.csv", Q(kExample / "placing-raw.csv")), 0},
      {fmt::format("import {} --cell {} --feeders {} -o i.place", Q(kGolden / "import-data/board.csv"),
                   Q(kGolden / "import-data/cell.toml"), Q(kGolden / "import-data/feeders.toml")),
       0},
      {"check /nonexistent.place", 3},
      {"check", 2},
      {"diff a.place a.place --threshold nan", 2},
      {fmt::format("compile {} --cell {} -o /nonexistent/dir/x.place", program, cell), 3},
  };
  for (const Case& c : cases) {
    SmtcalRun run = Smtcal("--diagnostics=json " + c.args);
    EXPECT_EQ(run.exit_code, c.exit_code) << c.args << "\n" << run.err;
    nlohmann::json document;
    ASSERT_NO_THROW(document = nlohmann::json::parse(run.err)) << c.args << "\n" << run.err;
    ASSERT_TRUE(document.is_array()) << c.args;
    if (c.exit_code != 0) {
      bool error = false;
      for (const nlohmann::json& entry : document) error = error || entry["severity"] == "error";
      EXPECT_TRUE(error) << c.args << ": the failure is not in the document\n" << run.err;
    }
  }
}

}  // namespace
}  // namespace smtcal
