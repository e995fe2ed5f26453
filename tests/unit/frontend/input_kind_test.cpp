// GuessInputKind: the kind of each of smtcal's own files (the shipped
// examples and golden inputs), and never another kind for a program.
#include "frontend/input_kind.h"

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

InputKind KindOfFile(const fs::path& path) {
  return GuessInputKind(path.filename().string(), test::ReadFileText(path));
}

TEST(InputKind, TheExampleFilesAreWhatTheyAre) {
  const fs::path example = fs::path(SMTCAL_SOURCE_DIR) / "examples" / "paper-cell";
  EXPECT_EQ(KindOfFile(example / "layers.place"), InputKind::kProgram);
  EXPECT_EQ(KindOfFile(example / "paper.cell.toml"), InputKind::kCell);
  EXPECT_EQ(KindOfFile(example / "placing-table.csv"), InputKind::kErrorTable);
  EXPECT_EQ(KindOfFile(example / "placing-raw.csv"), InputKind::kRawMeasurements);
  EXPECT_EQ(KindOfFile(example / "placing-table.svg"), InputKind::kSvg);
  const fs::path sim = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "simulate" / "data";
  EXPECT_EQ(KindOfFile(sim / "offset-field.truth.toml"), InputKind::kTruth);
}

TEST(InputKind, EveryGoldenProgramIsAProgramOrUnknown) {
  // A program with mistakes must reach the parser, whose messages say what
  // is wrong: the guess may never call it something else.
  int programs = 0;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden")) {
    if (entry.path().extension() != ".place") continue;
    const std::string name = entry.path().filename().string();
    if (name.starts_with("fail_input_is_")) continue;  // the cases of a wrong kind
    const InputKind kind = KindOfFile(entry.path());
    EXPECT_TRUE(kind == InputKind::kProgram || kind == InputKind::kUnknown)
        << entry.path() << " guessed as " << InputKindName(kind);
    ++programs;
  }
  EXPECT_GT(programs, 100);
}

TEST(InputKind, EveryGoldenCadListIsACadListOrUnknown) {
  // import reads what the guess does not call something else: a real list
  // with its own header words must not be refused.
  int lists = 0;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden")) {
    const std::string suite = entry.path().parent_path().filename().string();
    if (!entry.is_regular_file() || !suite.starts_with("import-")) continue;
    const std::string ext = entry.path().extension().string();
    if (ext != ".csv" && ext != ".pos" && ext != ".txt" && ext != ".tsv") continue;
    const std::string name = entry.path().filename().string();
    if (name.starts_with("fail_input_is_")) continue;
    const InputKind kind = KindOfFile(entry.path());
    EXPECT_TRUE(kind == InputKind::kCadList || kind == InputKind::kUnknown)
        << entry.path() << " guessed as " << InputKindName(kind);
    ++lists;
  }
  EXPECT_GT(lists, 20);
}

TEST(InputKind, CadListsAndTrips) {
  EXPECT_EQ(GuessInputKind("board-top.pos", "### Module positions - created on x ###\n### Printed by Pcbnew\n"),
            InputKind::kCadList);
  EXPECT_EQ(GuessInputKind("cpl.csv", "Designator,Mid X,Mid Y,Layer,Rotation\nR1,1,2,T,0\n"), InputKind::kCadList);
  EXPECT_EQ(GuessInputKind("trips.csv", "name,x_mm,y_mm,z_mm\nT1,1,2,-2\n"), InputKind::kTrips);
  EXPECT_EQ(GuessInputKind("board.log", "smtcal-record 1 cell=c fixtures=B:8 clock=none segment=0\n"),
            InputKind::kRecordLog);
  EXPECT_NE(InputKindAdvice(InputKind::kRecordLog, "board.log").find("smtcal monitor board.log"), std::string::npos);
  EXPECT_EQ(GuessInputKind("feeders.toml", "[[feeder]]\nname = \"A\"\n"), InputKind::kFeeders);
  EXPECT_EQ(GuessInputKind("x.txt", "hello\n"), InputKind::kUnknown);
  EXPECT_EQ(GuessInputKind("x.place", ""), InputKind::kUnknown);
}

}  // namespace
}  // namespace smtcal
