// The measuring programs (`smtcal measure program`, backend/linuxcnc/linuxcnc_measure.h)
// run by LinuxCNC's own interpreter rs274, and the final approach of the
// compiled placing programs:
// - every reading is made at the end of the final approach, and the probe's
//   program aborts at the first visit (rs274's probe never trips) naming the
//   visit to resume at;
// - the external device's program runs to its end (rs274's M66 waits return
//   at once): its LOG lines, written to a file as LinuxCNC's task writes
//   them, read back by `smtcal measure read` with an external system's
//   readings give exactly the errors those readings hold; a resumed program
//   appends (LOGAPPEND) from its visit;
// - with robot.final_approach_mm every Pick, Place and Jump of a compiled
//   program reaches its target by that last move, as the nodes were measured.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "backend/linuxcnc/embedded_files.h"
#include "tests/unit/backend/rs274_runner.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = SMTCAL_SOURCE_DIR;
const fs::path kScratchCell = kSource / "examples" / "calibrating" / "scratch.cell.toml";
const fs::path kPaperCellDir = kSource / "examples" / "paper-cell";
constexpr double kPrintedMm = 0.5e-4 + 1e-7;  // rs274 prints 4 decimals

std::string Quote(const fs::path& path) { return "'" + path.string() + "'"; }

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

fs::path Scratch(const std::string& name) {
  static int count = 0;
  fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_measure_{}_{}_{}", name, ::getpid(), ++count);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The scratch cell with another [measure] table.
fs::path CellWithDevice(const fs::path& dir, const std::string& measure) {
  std::string text = ReadText(kScratchCell);
  text = text.substr(0, text.find("\n[measure]\n") + 1) + measure;
  std::ofstream(dir / "scratch.cell.toml", std::ios::binary) << text;
  return dir / "scratch.cell.toml";
}

test::SmtcalRun Smtcal(const std::string& args) { return test::RunSmtcal(args); }

test::Rs274Result RunProgram(const fs::path& outdir, const std::string& name) {
  fs::path ini = test::WriteRs274Ini(outdir.parent_path() / ("ini-" + outdir.filename().string()),
                                     {outdir / "subroutines"});
  return test::RunRs274(ini, outdir / name);
}

// The canonical LOG("...") texts, as LinuxCNC's task writes them into the log.
std::vector<std::string> LogLines(const test::Rs274Result& run) {
  std::vector<std::string> lines;
  for (const std::string& canon : run.canon) {
    if (canon.rfind("LOG(\"", 0) == 0) lines.push_back(canon.substr(5, canon.size() - 7));
  }
  return lines;
}

TEST(LinuxCncMeasure, ProbeProgramApproachesEveryNodeAndAbortsWithoutContact) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  fs::path dir = Scratch("probe");
  test::SmtcalRun plan = Smtcal(fmt::format("measure plan --cell {} --region layer1 --pitch 25 --sets 1 "
                                            "--repetitions 1 --no-check-points -o {}",
                                            Quote(kScratchCell), Quote(dir / "plan.csv")));
  ASSERT_EQ(plan.exit_code, 0) << plan.err;
  test::SmtcalRun made = Smtcal(fmt::format("measure program {} --cell {} -o {}", Quote(dir / "plan.csv"),
                                            Quote(kScratchCell), Quote(dir / "out")));
  ASSERT_EQ(made.exit_code, 0) << made.err;
  ASSERT_TRUE(fs::exists(dir / "out" / "measure_s1.ngc"));
  test::Rs274Result run = RunProgram(dir / "out", "measure_s1.ngc");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("smtcal: measuring stopped at visit 1 - node 1 set 1 repetition 1: the probe did not "
                         "touch the wall along x"),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("smtcal measure program --start 1"), std::string::npos) << run.err;
  // The grid's first node is (150, 60) (bounds 150.5..199.5, 25 mm). The
  // head starts at z 0, the safe height: it is never lowered where it
  // stands; u (the C axis) is turned to the device's angle; across to the
  // approach point at that height, down to the clear z, onto the node, down,
  // towards the wall at rapid to the overtravel short of it (0.8 mm: more
  // than the robot's error, the plate's placement and turn), the probe move.
  ASSERT_GE(run.moves.size(), 7u);
  const auto& m = run.moves;
  EXPECT_NEAR(m[0].xyzabc[2], 0, kPrintedMm);
  EXPECT_NEAR(m[0].xyzabc[5], 0, kPrintedMm);
  EXPECT_NEAR(m[1].xyzabc[0], 149.5, kPrintedMm);
  EXPECT_NEAR(m[1].xyzabc[1], 59.5, kPrintedMm);
  EXPECT_NEAR(m[1].xyzabc[2], 0, kPrintedMm);
  EXPECT_NEAR(m[2].xyzabc[2], -5, kPrintedMm);
  EXPECT_NEAR(m[3].xyzabc[0], 150, kPrintedMm);
  EXPECT_NEAR(m[3].xyzabc[1], 60, kPrintedMm);
  EXPECT_NEAR(m[4].xyzabc[2], -8, kPrintedMm);
  EXPECT_NEAR(m[5].xyzabc[0], 150 + 1.5 - 0.8, kPrintedMm);  // the contact radius less the overtravel
  EXPECT_EQ(m[6].kind, "STRAIGHT_PROBE");
  EXPECT_NEAR(m[6].xyzabc[0], 150 + 1.5 + 0.8, kPrintedMm);
  std::vector<std::string> log = LogLines(run);
  ASSERT_GE(log.size(), 3u);
  EXPECT_EQ(log[0].rfind("# smtcal measuring log: plan plan.csv digest ", 0), 0u) << log[0];
  EXPECT_EQ(log.back(), "# aborted at visit 1 repetition 1: no contact along x");
  fs::remove_all(dir);
}

TEST(LinuxCncMeasure, ExternalProgramLogsEveryReadingAndReadsBackToTheErrors) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  fs::path dir = Scratch("external");
  fs::path cell = CellWithDevice(dir,
                                 "[measure]\ndevice = \"external\"\nz_mm = -8\nclear_z_mm = -5\nnoise_mm = 0.002\n"
                                 "[measure.external]\ntrigger_output = 9\ndone_input = 15\nnode_output = 0\n");
  test::SmtcalRun plan = Smtcal(fmt::format("measure plan --cell {} --region layer1 --pitch 25 --sets 2 "
                                            "--repetitions 2 -o {}",
                                            Quote(cell), Quote(dir / "plan.csv")));
  ASSERT_EQ(plan.exit_code, 0) << plan.err;
  test::SmtcalRun made = Smtcal(fmt::format("measure program {} --cell {} -o {}", Quote(dir / "plan.csv"),
                                            Quote(cell), Quote(dir / "out")));
  ASSERT_EQ(made.exit_code, 0) << made.err;
  test::Rs274Result run = RunProgram(dir / "out", "measure_s1.ngc");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::vector<std::string> log = LogLines(run);
  // 3 x 3 nodes and the one check point, 2 sets, 2 repetitions; the header,
  // the column line and "# end".
  ASSERT_EQ(log.size(), 10u * 2 * 2 + 3);
  EXPECT_EQ(log.back(), "# end");
  std::ofstream(dir / "measure_s1.log") << [&] {
    std::string text;
    for (const std::string& line : log) text += line + "\n";
    return text;
  }();
  // The external system's readings: every node off by a known error.
  std::string readings = "node,set,repetition,x_mm,y_mm\n";
  std::map<int, std::pair<double, double>> truth;
  for (std::size_t k = 2; k + 1 < log.size(); ++k) {
    int visit, node, set, rep;
    double x, y;
    ASSERT_EQ(std::sscanf(log[k].c_str(), "%d,%d,%d,%d,%lf,%lf", &visit, &node, &set, &rep, &x, &y), 6) << log[k];
    const double ex = 1e-3 * (node % 7) - 0.004 + 1e-4 * rep, ey = -1e-3 * (node % 5) + 1e-4 * set;
    readings += fmt::format("{},{},{},{:.6f},{:.6f}\n", node, set, rep, x + ex, y + ey);
  }
  std::ofstream(dir / "readings.csv") << readings;
  test::SmtcalRun read = Smtcal(fmt::format("measure read {} {} --cell {} --external {} -o {}",
                                            Quote(dir / "plan.csv"), Quote(dir / "measure_s1.log"), Quote(cell),
                                            Quote(dir / "readings.csv"), Quote(dir / "raw.csv")));
  ASSERT_EQ(read.exit_code, 0) << read.err;
  const std::string raw = ReadText(dir / "raw.csv");
  EXPECT_NE(raw.find("# plan plan.csv (digest "), std::string::npos) << raw;
  EXPECT_NE(raw.find("axis,x_mm,y_mm,set,repetition,error_mm,u_mm,kind\n"), std::string::npos) << raw;
  // node 1: 0.001 - 0.004 + 0.0001; an external system has no artefact to register
  EXPECT_NE(raw.find("x,150,60,1,1,-0.002900,0.000000,node\n"), std::string::npos) << raw;
  EXPECT_NE(raw.find(",check\n"), std::string::npos) << raw;

  // A reading the system lacks is named; so is a resumed run's start.
  std::string short_readings = readings.substr(0, readings.rfind('\n', readings.size() - 2) + 1);
  std::ofstream(dir / "short.csv") << short_readings;
  test::SmtcalRun missing = Smtcal(fmt::format("measure read {} {} --cell {} --external {} -o {}",
                                               Quote(dir / "plan.csv"), Quote(dir / "measure_s1.log"),
                                               Quote(cell), Quote(dir / "short.csv"), Quote(dir / "raw2.csv")));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("the external readings have none for node"), std::string::npos) << missing.err;
  test::SmtcalRun resumed = Smtcal(fmt::format("measure program {} --cell {} -o {} --start 7",
                                               Quote(dir / "plan.csv"), Quote(cell), Quote(dir / "resumed")));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  const std::string text = ReadText(dir / "resumed" / "measure_s1.ngc");
  EXPECT_NE(text.find("(LOGAPPEND,measure_s1.log)"), std::string::npos);
  EXPECT_NE(text.find("visits 7..20"), std::string::npos) << text;
  EXPECT_EQ(text.find("o<smtcal_measure_external> call [6]"), std::string::npos);
  fs::remove_all(dir);
}

// With the final approach every Pick and Place crosses to its target from
// target - final_approach_mm: the move before the crossing ends there.
TEST(LinuxCncMeasure, CompiledPlacementsEndWithTheFinalApproach) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  fs::path dir = Scratch("approach");
  fs::create_directories(dir / "cell");
  for (const auto& entry : fs::directory_iterator(kPaperCellDir)) {
    if (entry.path().extension() == ".csv") fs::copy(entry.path(), dir / "cell" / entry.path().filename());
  }
  std::string cell = ReadText(kPaperCellDir / "paper.cell.toml");
  cell.replace(cell.find("servo_period_s = 0.001"), 22, "servo_period_s = 0.001\nfinal_approach_mm = [0.5, -0.25]");
  std::ofstream(dir / "cell" / "paper.cell.toml") << cell;
  test::SmtcalRun compiled =
      Smtcal(fmt::format("compile {} --cell {} --target linuxcnc -o {} --dry-run-probe",
                         Quote(kPaperCellDir / "layers.place"), Quote(dir / "cell" / "paper.cell.toml"),
                         Quote(dir / "out")));
  ASSERT_EQ(compiled.exit_code, 0) << compiled.err;
  fs::path ini = test::WriteRs274Ini(dir / "ini", {dir / "out" / "dry-run", dir / "out" / "subroutines"});
  test::Rs274Result run = test::RunRs274(ini, dir / "out" / "layers.ngc");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // Every descent (a traverse down in z only) follows a crossing whose move
  // before it ended at the crossing's point less the approach, at its z.
  int descents = 0;
  for (std::size_t k = 2; k < run.moves.size(); ++k) {
    const auto& down = run.moves[k].xyzabc;
    const auto& onto = run.moves[k - 1].xyzabc;
    const auto& from = run.moves[k - 2].xyzabc;
    if (run.moves[k].kind != "STRAIGHT_TRAVERSE" || down[2] >= onto[2] - 1e-9 || std::abs(down[0] - onto[0]) > 1e-9 ||
        std::abs(down[1] - onto[1]) > 1e-9 || std::abs(onto[2] - from[2]) > 1e-9) {
      continue;
    }
    if (std::abs(onto[0] - from[0]) < 1e-9 && std::abs(onto[1] - from[1]) < 1e-9) continue;  // not a crossing
    ++descents;
    ASSERT_NEAR(onto[0] - from[0], 0.5, kPrintedMm) << "move " << k;
    ASSERT_NEAR(onto[1] - from[1], -0.25, kPrintedMm) << "move " << k;
  }
  EXPECT_GE(descents, 100 * 80);  // 100 boards, 40 picks and 40 places each
  fs::remove_all(dir);
}

}  // namespace
}  // namespace smtcal

// The example machine's SUBROUTINE_PATH holds the placing runtime's folder
// and the measuring runtime's (examples/linuxcnc/paper-cell.ini): LinuxCNC
// takes the first file of a name on the path, so a name both runtimes used
// would silently run the wrong one in one of them.
TEST(LinuxCncMeasureFiles, ShareNoNameWithThePlacingRuntime) {
  std::set<std::string> placing;
  for (const smtcal::EmbeddedFile& file : smtcal::LinuxCncRuntimeFiles()) placing.insert(file.name);
  placing.insert("smtcal_data.ngc");  // written beside the runtime by compile
  ASSERT_FALSE(smtcal::LinuxCncMeasureFiles().empty());
  for (const smtcal::EmbeddedFile& file : smtcal::LinuxCncMeasureFiles()) {
    EXPECT_EQ(placing.count(file.name), 0u) << file.name << " is in both runtimes";
  }
}
