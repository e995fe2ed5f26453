// `smtcal diff` on the machine, as a user runs it: the example program
// compiled for the example cell and for a copy whose placing table is
// re-measured (every x error 12 µm larger), once as .place and once for
// LinuxCNC. The .place diff must name every placement of layer 1; the two
// LinuxCNC folders must give the same verdict and the same moved positions
// (a differential test of the LinuxCNC reader against the .place path); and
// a cell whose tables changed since a program was compiled must never stand
// in for the one it was compiled with. (The texts are golden tests in
// tests/golden/diff and tests/golden/diff-linuxcnc.)
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/unit/test_support.h"

namespace fs = std::filesystem;

namespace {

using smtcal::test::ReadFileText;
using smtcal::test::RunSmtcal;
using smtcal::test::SmtcalRun;

const fs::path kExample = fs::path(SMTCAL_SOURCE_DIR) / "examples" / "paper-cell";

// The x errors of a table 12 µm larger, as the awk does.
void Remeasure(const fs::path& from, const fs::path& to) {
  std::istringstream in(ReadFileText(from));
  std::ofstream out(to, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("x,", 0) == 0) {
      // axis,x_mm,y_mm,error_mm[,...]
      std::size_t c1 = line.find(','), c2 = line.find(',', c1 + 1), c3 = line.find(',', c2 + 1);
      std::size_t c4 = line.find(',', c3 + 1);
      double error = std::stod(line.substr(c3 + 1, c4 == std::string::npos ? std::string::npos : c4 - c3 - 1));
      line = line.substr(0, c3 + 1) + fmt::format("{:.6f}", error + 0.012) +
             (c4 == std::string::npos ? "" : line.substr(c4));
    }
    out << line << '\n';
  }
}

class DiffOnTheMachine : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / fmt::format("smtcal_diff_machine_{}", ::getpid());
    fs::create_directories(dir_ / "remeasured");
    for (const fs::directory_entry& entry : fs::directory_iterator(kExample)) {
      if (entry.path().extension() == ".csv" || entry.path().extension() == ".toml") {
        fs::copy_file(entry.path(), dir_ / "remeasured" / entry.path().filename());
      }
    }
    Remeasure(kExample / "placing-table.csv", dir_ / "remeasured" / "placing-table.csv");
    const std::string source = (kExample / "layers.place").string();
    const std::string cell = (kExample / "paper.cell.toml").string();
    for (const auto& [out, cell_path, target] :
         {std::tuple{"old.place", cell, "place"}, std::tuple{"new.place", std::string("remeasured/paper.cell.toml"), "place"},
          std::tuple{"old", cell, "linuxcnc"}, std::tuple{"new", std::string("remeasured/paper.cell.toml"), "linuxcnc"}}) {
      SmtcalRun run = RunSmtcal(fmt::format("compile '{}' --cell '{}' --target {} -o {}", source, cell_path, target, out), dir_);
      ASSERT_EQ(run.exit_code, 0) << run.err;
    }
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // The moved positions of a diff's JSON: (required x, y in 0.1 µm, the worst move in 0.1 µm).
  static std::set<std::tuple<long, long, long>> Moved(const nlohmann::json& diff) {
    std::set<std::tuple<long, long, long>> moved;
    for (const nlohmann::json& change : diff["changes"]) {
      for (const nlohmann::json& position : change["machine"]) {
        if (!position["comparable"].get<bool>()) continue;
        moved.emplace(std::lround(position["required"]["x_mm"].get<double>() * 1e4),
                      std::lround(position["required"]["y_mm"].get<double>() * 1e4),
                      std::lround(position["worst"]["d_um"].get<double>() * 10));
      }
    }
    return moved;
  }

  static fs::path dir_;
};
fs::path DiffOnTheMachine::dir_;

TEST_F(DiffOnTheMachine, ARemeasuredPlacingTableMovesEveryPlacementOfLayer1) {
  SmtcalRun run = RunSmtcal("diff old.place new.place", dir_);
  EXPECT_EQ(run.exit_code, 1) << run.out << run.err;
  // verify's count is 14 placements in layer 1: the 13 parts of the first
  // layer, corrected on the controller through the table, each land 12 µm
  // further in x; U3 is placed at its taught pose, where the robot was shown
  // the part, so a re-measured table does not move it (its Place is named,
  // 0.0 µm, and its point's text moves 12 µm).
  std::size_t named = 0;
  std::istringstream lines(run.out);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("moved Place") != std::string::npos && line.find("in region layer1") != std::string::npos &&
        line.find("[more than 10.0 µm]") != std::string::npos) {
      ++named;
    }
  }
  EXPECT_EQ(named, 13u) << run.out;
  EXPECT_NE(run.out.find("the cells differ in: region layer1"), std::string::npos) << run.out;
  SmtcalRun passes = RunSmtcal("diff old.place new.place --threshold 12.5", dir_);
  EXPECT_EQ(passes.exit_code, 0) << passes.out << passes.err;
}

TEST_F(DiffOnTheMachine, LinuxCncOutputsGiveTheSameVerdictAndMoves) {
  SmtcalRun place = RunSmtcal("diff old.place new.place --json", dir_);
  SmtcalRun linuxcnc = RunSmtcal("diff old new --json", dir_);
  ASSERT_EQ(linuxcnc.exit_code, place.exit_code) << linuxcnc.err;
  EXPECT_EQ(linuxcnc.err, "");
  const nlohmann::json a = nlohmann::json::parse(place.out), b = nlohmann::json::parse(linuxcnc.out);
  EXPECT_EQ(a["summary"]["gate"], b["summary"]["gate"]);
  EXPECT_EQ(a["summary"]["targets_moved"], b["summary"]["targets_moved"]);
  EXPECT_EQ(a["summary"]["beyond_threshold"], b["summary"]["beyond_threshold"]);
  EXPECT_EQ(Moved(a), Moved(b));
  EXPECT_EQ(Moved(a).size(), 14u);
  // The main .ngc files name the same folders.
  SmtcalRun by_file = RunSmtcal("diff old/layers.ngc new/layers.ngc --json", dir_);
  const nlohmann::json c = nlohmann::json::parse(by_file.out);
  EXPECT_EQ(c["changes"], b["changes"]);
  EXPECT_EQ(c["summary"], b["summary"]);
}

TEST_F(DiffOnTheMachine, TheSameProgramAndCellMoveNothing) {
  SmtcalRun place = RunSmtcal("diff old.place old.place", dir_);
  EXPECT_EQ(place.exit_code, 0) << place.out << place.err;
  SmtcalRun linuxcnc = RunSmtcal("diff old old", dir_);
  EXPECT_EQ(linuxcnc.exit_code, 0) << linuxcnc.out << linuxcnc.err;
  EXPECT_NE(linuxcnc.out.find("no changes"), std::string::npos) << linuxcnc.out;
}

TEST_F(DiffOnTheMachine, ACellThatChangedSinceTheCompileIsRefused) {
  // One --cell for both: NEW was compiled with the re-measured table.
  SmtcalRun run = RunSmtcal(fmt::format("diff old.place new.place --cell '{}'", (kExample / "paper.cell.toml").string()),
                            dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("new.place was not compiled with the cell"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("table placing-table.csv"), std::string::npos) << run.err;
  // The given cells: the diff runs.
  SmtcalRun given = RunSmtcal(fmt::format("diff old.place new.place --old-cell '{}' --new-cell remeasured/paper.cell.toml",
                                          (kExample / "paper.cell.toml").string()),
                              dir_);
  EXPECT_EQ(given.exit_code, 1) << given.err;
  EXPECT_EQ(given.err, "");
}

TEST_F(DiffOnTheMachine, ThePictureDrawsThePositionsAtTheirSpacing) {
  SmtcalRun run = RunSmtcal("diff old.place new.place --exit-zero --svg moves.svg", dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string svg = ReadFileText(dir_ / "moves.svg");
  EXPECT_NE(svg.find("55 commanded positions compared on the machine (as in the text report): 55 in the robot base"),
            std::string::npos)
      << svg;
  // The 12 µm moves among parts about 9 mm apart: a few millimetres, not tens.
  const std::size_t at = svg.find("is drawn ");
  ASSERT_NE(at, std::string::npos);
  const double drawn_mm = std::stod(svg.substr(at + 9));
  EXPECT_GT(drawn_mm, 1.0);
  EXPECT_LT(drawn_mm, 6.0);
}

// docs/diff.md shows docs/images/diff-board.svg as what `diff --svg` draws
// for the board re-measured (marker 2 20 µm further out, L1 190.02), run as
// the document runs it: it must stay exactly that picture.
// SMTCAL_UPDATE_GOLDEN=1 rewrites it (review it as a PNG before committing).
TEST_F(DiffOnTheMachine, TheDocsPictureOfAReMeasuredBoardIsWhatDiffDraws) {
  fs::create_directories(dir_ / "doc" / "board");
  for (const fs::directory_entry& entry : fs::directory_iterator(kExample)) {
    if (entry.path().extension() == ".csv" || entry.path().extension() == ".toml" ||
        entry.path().extension() == ".place") {
      fs::copy_file(entry.path(), dir_ / "doc" / entry.path().filename(), fs::copy_options::overwrite_existing);
      if (entry.path().extension() != ".place") {
        fs::copy_file(entry.path(), dir_ / "doc" / "board" / entry.path().filename(),
                      fs::copy_options::overwrite_existing);
      }
    }
  }
  std::string cell = ReadFileText(dir_ / "doc" / "board" / "paper.cell.toml");
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"\nl1_mm = 190\n", "\nl1_mm = 190.02\n"},
                                 {"[190, 82], to_mm = [190, 90]", "[190.02, 82], to_mm = [190.02, 90]"},
                                 {"[182, 90], to_mm = [190, 90]", "[182.02, 90], to_mm = [190.02, 90]"}}) {
    const std::size_t at = cell.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    cell.replace(at, from.size(), to);
  }
  std::ofstream(dir_ / "doc" / "board" / "paper.cell.toml", std::ios::binary) << cell;
  for (const std::string& command : {std::string("compile layers.place --cell paper.cell.toml -o old.place"),
                                     std::string("compile layers.place --cell board/paper.cell.toml -o board.place")}) {
    SmtcalRun run = RunSmtcal(command, dir_ / "doc");
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  SmtcalRun run = RunSmtcal("diff old.place board.place --svg board.svg", dir_ / "doc");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  const fs::path picture = fs::path(SMTCAL_SOURCE_DIR) / "docs" / "images" / "diff-board.svg";
  const std::string svg = ReadFileText(dir_ / "doc" / "board.svg");
  const char* update = std::getenv("SMTCAL_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    std::ofstream(picture, std::ios::binary) << svg;
    return;
  }
  EXPECT_EQ(svg, ReadFileText(picture))
      << "docs/images/diff-board.svg is not what `smtcal diff --svg` draws; rewrite it with SMTCAL_UPDATE_GOLDEN=1";
}

TEST_F(DiffOnTheMachine, LinuxCncOutputsTakeNoCell) {
  SmtcalRun run = RunSmtcal("diff old new --cell remeasured/paper.cell.toml", dir_);
  EXPECT_EQ(run.exit_code, 2);
  SmtcalRun mixed = RunSmtcal("diff old.place new", dir_);
  EXPECT_EQ(mixed.exit_code, 2);
}

}  // namespace
