// The LinuxCNC target's output run by LinuxCNC's own interpreter rs274
// (tests/unit/backend/rs274_runner.h): the example and every golden case of
// tests/golden/linuxcnc/ run to their end; the example's static placements
// are commanded at the compiler's nominal coordinates and its fixture
// placements, for a board shifted and turned, where the C++ implementation
// puts them (FIX . f, then the inverse of the error tables), to the 4
// decimals rs274 prints; with the real probe file the first scan aborts
// before anything is placed. The standalone interpreter's probe never
// trips, so a replacement smtcal_probe_trips.ngc earlier on the subroutine
// path supplies the trips of a chosen board pose. Also: the output
// directory (what it holds, replacing an earlier output, refusing anything
// else, byte-identical output).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "backend/linuxcnc/embedded_files.h"
#include "backend/linuxcnc/linuxcnc_data.h"
#include "backend/linuxcnc/linuxcnc_emit.h"
#include "calibration/fixture_estimation.h"
#include "calibration/fixture_geometry.h"
#include "frontend/cell_toml.h"
#include "frontend/parse.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"
#include "passes/pass_manager.h"
#include "tests/unit/backend/rs274_runner.h"
#include "tests/unit/calibration/fixture_test_cell.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = SMTCAL_SOURCE_DIR;
const fs::path kExample = kSource / "examples" / "paper-cell" / "layers.place";
const fs::path kCell = kSource / "examples" / "paper-cell" / "paper.cell.toml";
const fs::path kGolden = kSource / "tests" / "golden" / "linuxcnc";

// rs274 prints 4 decimals: a printed coordinate is within half a unit of
// the last digit of the true one (plus what the runtime's iterative inverse
// may differ from C++'s, far below that).
constexpr double kPrintedMm = 0.5e-4 + 1e-7;

std::string Quote(const fs::path& path) { return "'" + path.string() + "'"; }

fs::path Scratch(const std::string& name) {
  static int count = 0;
  fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_lcnc_emit_{}_{}_{}", name, ::getpid(), ++count);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// `smtcal compile PROGRAM --cell CELL --target linuxcnc -o OUTDIR`.
test::SmtcalRun CompileToDir(const fs::path& program, const fs::path& cell, const fs::path& outdir) {
  return test::RunSmtcal(fmt::format("compile {} --cell {} --target linuxcnc -o {}", Quote(program), Quote(cell),
                                     Quote(outdir)));
}

// A smtcal_probe_trips.ngc that fills fixture k's trip parameters with
// `trips[k]` (base frame, all tripped), as runtime/linuxcnc/README.md lays
// them out: the fixture record at #[#35 + k], its trips' address at +30,
// their flags' address at +31.
std::string ProbeReplacement(const std::vector<std::vector<Eigen::Vector2d>>& trips) {
  std::string out = "; test replacement (tests/unit/backend/linuxcnc_emit_test.cpp): known trips\n";
  out += "o<smtcal_probe_trips> sub\n";
  for (std::size_t k = 0; k < trips.size(); ++k) {
    out += fmt::format("o<tp{0}> if [#1 EQ {0}]\n", k);
    for (std::size_t i = 0; i < trips[k].size(); ++i) {
      out += fmt::format("#[#[#[#35 + {}] + 30] + {}] = {}\n", k, 2 * i, LinuxCncNumber(trips[k][i].x()));
      out += fmt::format("#[#[#[#35 + {}] + 30] + {}] = {}\n", k, 2 * i + 1, LinuxCncNumber(trips[k][i].y()));
      out += fmt::format("#[#[#[#35 + {}] + 31] + {}] = 1\n", k, i);
    }
    out += fmt::format("o<tp{}> endif\n", k);
  }
  return out + "o<smtcal_probe_trips> endsub\n";
}

// The trips every fixture of the cell records with its board at a pose
// (nullopt: its nominal pose): where the robot is commanded when it really
// is at the edge, as the cell's tables say (the runtime calibrates them back).
std::vector<std::vector<Eigen::Vector2d>> TripsAt(const cell::Cell& cell,
                                                  const std::optional<Eigen::Affine3d>& pose = std::nullopt) {
  std::vector<std::vector<Eigen::Vector2d>> trips;
  for (const cell::Fixture& fixture : cell.fixtures) {
    trips.push_back(CommandedTrips(fixture, cell.regions, pose ? *pose : NominalFix(fixture)));
  }
  return trips;
}

// rs274 on OUTDIR/<main>, with `probe` (when given) first on the path.
test::Rs274Result RunCompiled(const fs::path& outdir, const std::string& main_name, const std::string& probe) {
  std::vector<fs::path> path;
  if (!probe.empty()) {
    fs::create_directories(outdir.parent_path() / "first");
    std::ofstream(outdir.parent_path() / "first" / "smtcal_probe_trips.ngc", std::ios::binary) << probe;
    path.push_back(outdir.parent_path() / "first");
  }
  path.push_back(outdir / "subroutines");
  fs::path ini = test::WriteRs274Ini(outdir.parent_path() / "ini", path);
  return test::RunRs274(ini, outdir / main_name);
}

bool RanToTheEnd(const test::Rs274Result& run) {
  return run.exit_code == 0 && std::find(run.canon.begin(), run.canon.end(), "PROGRAM_END()") != run.canon.end();
}

std::string Tail(const std::string& text) { return text.size() > 2000 ? text.substr(text.size() - 2000) : text; }

// ------------------------------------------------------------------ compiled in-process

struct Compiled {
  SourceManager sources;
  std::unique_ptr<Diagnostics> diags;
  std::optional<cell::Cell> cell;
  ir::Program program;
};

std::unique_ptr<Compiled> CompileInProcess(const fs::path& program_path, const fs::path& cell_path) {
  auto c = std::make_unique<Compiled>();
  c->diags = std::make_unique<Diagnostics>(c->sources);
  Result<std::uint32_t> file = c->sources.Load(program_path.string());
  EXPECT_TRUE(file.ok());
  c->program = ParseProgram(file.value(), *c->diags);
  EXPECT_TRUE(RunPasses(c->program, *c->diags, std::vector<std::string>{}, false).ok());
  Result<std::optional<cell::Cell>> cell = cell::LoadCell(cell_path.string(), c->sources, *c->diags);
  EXPECT_TRUE(cell.ok());
  c->cell = std::move(cell).value();
  if (!c->cell) return c;
  c->program.compile = std::make_shared<CompileState>();
  c->program.compile->cell = &*c->cell;
  std::vector<const PassInfo*> passes;
  for (const PassInfo& info : CorrectionPassRegistry()) passes.push_back(&info);
  RunPasses(c->program, *c->diags, passes, false);
  EXPECT_FALSE(c->diags->has_errors()) << c->diags->RenderText();
  return c;
}

// The moves rs274 prints for one target: a Jump, Pick or Place rises,
// crosses and descends (the crossing commands x, y, c; the descent z); Go
// and Move are one move.
int MovesOf(const ir::Stmt& stmt) {
  if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) return motion->kind == ir::MotionKind::Jump ? 3 : 1;
  return 3;
}

// ------------------------------------------------------------------ tests

TEST(LinuxCncEmit, ExampleAndEveryGoldenCaseRunToTheEndInRs274) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(kCell.string(), sources, diags);
  ASSERT_TRUE(loaded.ok() && loaded.value().has_value()) << diags.RenderText();
  const std::string probe = ProbeReplacement(TripsAt(*loaded.value()));
  std::vector<fs::path> programs;
  for (const fs::directory_entry& entry : fs::directory_iterator(kGolden)) {
    std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".place" && !name.starts_with("fail_")) programs.push_back(entry.path());
  }
  std::sort(programs.begin(), programs.end());
  ASSERT_GE(programs.size(), 2u);
  for (const fs::path& program : programs) {
    SCOPED_TRACE(program.string());
    fs::path dir = Scratch(program.stem().string());
    test::SmtcalRun compiled = CompileToDir(program, kCell, dir / "out");
    ASSERT_EQ(compiled.exit_code, 0) << compiled.err;
    test::Rs274Result run = RunCompiled(dir / "out", LinuxCncMainName(program.string()), probe);
    EXPECT_TRUE(RanToTheEnd(run)) << "exit " << run.exit_code << "\n" << run.err << Tail(run.out);
    EXPECT_EQ(run.err.find("rror"), std::string::npos) << run.err;
    fs::remove_all(dir);
  }
}

// The example for a board 0.5 mm and 0.15 deg off its nominal pose: every
// move of every cycle where the compiler (static) or the C++ runtime math
// (fixture) says, and every cycle the same.
TEST(LinuxCncEmit, ExampleTargetsMatchTheCompilerForAShiftedBoard) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  auto c = CompileInProcess(kExample, kCell);
  ASSERT_TRUE(c->cell);
  CompileState& state = *c->program.compile;
  const cell::Cell& cell = *c->cell;
  ASSERT_EQ(cell.fixtures.size(), 1u);
  const cell::Fixture& fixture = cell.fixtures[0];
  const Eigen::Affine3d shifted = PlanarFix(FixOrigin(NominalFix(fixture)) + Eigen::Vector2d(0.4, -0.3),
                                            FixAngleRad(NominalFix(fixture)) + Radians(0.15));
  const std::vector<std::vector<Eigen::Vector2d>> trips = TripsAt(cell, shifted);
  ScanOptions options;
  options.estimator = fixture.estimator;
  options.regions = &cell.regions;
  ScanResult scan = ScanFixture(fixture, test::Present(trips[0]), options);
  ASSERT_TRUE(scan.ok()) << DescribeFailure(scan, fixture);
  const Eigen::Affine3d fix = *scan.fix;

  // The commands of the first cycle, in order, from the compile-time trace.
  ASSERT_EQ(state.cycle_traces.size(), 1u);
  const std::vector<TraceEvent>& trace = state.cycle_traces.begin()->second;
  struct Expected {
    std::string what;
    std::array<double, 4> xyzc;  // the crossing's x, y, c and the descent's z
    int moves;
  };
  std::vector<Expected> expected;
  int statics = 0, fixtures = 0;
  for (const TraceEvent& event : trace) {
    if (event.kind != TraceEvent::Kind::kMotion) continue;
    const Target& target = state.targets[event.target];
    Expected e{fmt::format("{} {} ({})", TargetKeyword(*target.stmt), target.text, target.stmt->loc.line), {}, 0};
    e.moves = MovesOf(*target.stmt);
    if (target.kind == CorrectionKind::kStatic) {
      ++statics;
      e.xyzc = {target.nominal[0], target.nominal[1], target.nominal[2], target.nominal[3]};
    } else {
      ASSERT_EQ(target.kind, CorrectionKind::kFixture) << e.what;
      ++fixtures;
      Pose4 required = PoseToBase(fix, target.in_frame);
      const cell::Region* region = cell.RegionAt(Xy(required));
      ASSERT_NE(region, nullptr) << e.what;
      Solution solution = state.SolverFor(*region).Solve(Xy(required), region->outside);
      ASSERT_EQ(solution.status, SolveStatus::kOk) << e.what;
      e.xyzc = {solution.point.x(), solution.point.y(), required[2], required[3]};
    }
    expected.push_back(e);
  }
  EXPECT_EQ(statics, 40);   // every Pick: the feeder slots
  EXPECT_EQ(fixtures, 40);  // every Place: the paper's 40 parts per cycle

  fs::path dir = Scratch("shifted");
  test::SmtcalRun compiled = CompileToDir(kExample, kCell, dir / "out");
  ASSERT_EQ(compiled.exit_code, 0) << compiled.err;
  test::Rs274Result run = RunCompiled(dir / "out", "layers.ngc", ProbeReplacement(trips));
  ASSERT_TRUE(RanToTheEnd(run)) << run.err << Tail(run.out);
  for (const test::CanonMove& move : run.moves) ASSERT_NE(move.kind, "STRAIGHT_PROBE") << "the trips are supplied";

  int per_cycle = 0;
  for (const Expected& e : expected) per_cycle += e.moves;
  const int boards = 100;  // layers.place: boardsToBuild
  ASSERT_EQ(run.moves.size(), static_cast<std::size_t>(boards * per_cycle));
  for (int board = 0; board < boards; ++board) {
    std::size_t at = static_cast<std::size_t>(board * per_cycle);
    for (const Expected& e : expected) {
      const test::CanonMove& across = run.moves[at + (e.moves == 3 ? 1 : 0)];
      const test::CanonMove& down = run.moves[at + static_cast<std::size_t>(e.moves - 1)];
      ASSERT_NEAR(across.xyzabc[0], e.xyzc[0], kPrintedMm) << e.what << ", board " << board + 1;
      ASSERT_NEAR(across.xyzabc[1], e.xyzc[1], kPrintedMm) << e.what << ", board " << board + 1;
      ASSERT_NEAR(down.xyzabc[2], e.xyzc[2], kPrintedMm) << e.what << ", board " << board + 1;
      ASSERT_NEAR(across.xyzabc[5], e.xyzc[3], kPrintedMm) << e.what << ", board " << board + 1;
      at += static_cast<std::size_t>(e.moves);
    }
  }
  // The board really is off: the fixture targets moved against the nominal pose.
  double largest = 0;
  for (const Target& target : state.targets) {
    if (target.kind != CorrectionKind::kFixture) continue;
    largest = std::max(largest, (Xy(PoseToBase(fix, target.in_frame)) - Xy(target.required)).norm());
  }
  EXPECT_GT(largest, 0.3);
  fs::remove_all(dir);
}

TEST(LinuxCncEmit, ExampleWithTheRealProbeAbortsBeforeTheFirstPlacement) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  fs::path dir = Scratch("abort");
  test::SmtcalRun compiled = CompileToDir(kExample, kCell, dir / "out");
  ASSERT_EQ(compiled.exit_code, 0) << compiled.err;
  test::Rs274Result run = RunCompiled(dir / "out", "layers.ngc", "");
  EXPECT_EQ(run.exit_code, 1) << Tail(run.out);
  EXPECT_NE(run.err.find("smtcal: marker scan of fixture"), std::string::npos) << run.err;
  bool probed = false;
  for (const std::string& canon : run.canon) {
    EXPECT_EQ(canon.find("SET_AUX_OUTPUT_BIT"), std::string::npos) << "the vacuum went on before the abort";
    probed = probed || canon.starts_with("STRAIGHT_PROBE");
  }
  EXPECT_TRUE(probed) << "the real probe file moves the sensor";
  fs::remove_all(dir);
}

// --dry-run-probe: OUTDIR/dry-run/ first on rs274's path runs the whole
// example (100 boards) with the nominal trips, says so at every scan, moves
// no probe; compiling again replaces the output with its dry-run folder.
TEST(LinuxCncEmit, DryRunProbeFileRunsTheWholeExampleInRs274) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  fs::path dir = Scratch("dryrun");
  const std::string compile = fmt::format("compile {} --cell {} --target linuxcnc -o {} --dry-run-probe",
                                          Quote(kExample), Quote(kCell), Quote(dir / "out"));
  test::SmtcalRun compiled = test::RunSmtcal(compile);
  ASSERT_EQ(compiled.exit_code, 0) << compiled.err;
  const std::string probe = test::ReadFileText(dir / "out" / "dry-run" / "smtcal_probe_trips.ngc");
  EXPECT_TRUE(probe.starts_with("; smtcal_probe_trips.ngc - DRY RUN ONLY")) << probe;
  fs::path ini = test::WriteRs274Ini(dir / "ini", {dir / "out" / "dry-run", dir / "out" / "subroutines"});
  test::Rs274Result run = test::RunRs274(ini, dir / "out" / "layers.ngc");
  EXPECT_TRUE(RanToTheEnd(run)) << "exit " << run.exit_code << "\n" << run.err << Tail(run.out);
  const auto said = std::count(run.messages.begin(), run.messages.end(),
                               "smtcal dry run: fixture Board gets the trips of its nominal pose; no scan");
  EXPECT_EQ(said, 100) << "one message per scan";
  for (const test::CanonMove& move : run.moves) ASSERT_NE(move.kind, "STRAIGHT_PROBE");
  test::SmtcalRun again = test::RunSmtcal(compile);
  EXPECT_EQ(again.exit_code, 0) << again.err;
  test::SmtcalRun wrong_target = test::RunSmtcal(
      fmt::format("compile {} --cell {} -o {} --dry-run-probe", Quote(kExample), Quote(kCell), Quote(dir / "x.place")));
  EXPECT_EQ(wrong_target.exit_code, 2) << wrong_target.err;
  EXPECT_FALSE(fs::exists(dir / "x.place"));
  fs::remove_all(dir);
}

// The shipped configuration (examples/linuxcnc/) finds the compiled
// subroutines through its relative SUBROUTINE_PATH when run from its folder.
TEST(LinuxCncEmit, ShippedExampleConfigurationFindsTheSubroutines) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  fs::path dir = Scratch("config");
  for (const char* name : {"paper-cell.ini", "paper-cell.hal", "paper-cell.tbl", "paper-cell.var"}) {
    fs::copy_file(kSource / "examples" / "linuxcnc" / name, dir / name);
  }
  // As examples/linuxcnc/README.md compiles it: against the machine's INI,
  // the runtime into the folder its SUBROUTINE_PATH names first.
  test::SmtcalRun compiled = test::RunSmtcal(fmt::format("compile {} --cell {} --target linuxcnc --ini {} -o {}",
                                                         Quote(kExample), Quote(kCell), Quote(dir / "paper-cell.ini"),
                                                         Quote(dir / "layers")));
  ASSERT_EQ(compiled.exit_code, 0) << compiled.err;
  // HOME=.: rs274 maps $HOME/.tool.mmap; parallel runs must not share it.
  std::string command = fmt::format("cd {} && HOME=. rs274 -i paper-cell.ini -g layers/layers.ngc </dev/null >out 2>err",
                                    Quote(dir));
  int status = std::system(command.c_str());
  std::string err = test::ReadFileText(dir / "err");
  // The probe never trips in rs274: the scan's abort shows that smtcal_data,
  // smtcal_scan and its subroutines were all found.
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << err;
  EXPECT_NE(err.find("smtcal: marker scan of fixture Board failed check missing_trip"), std::string::npos) << err;
  fs::remove_all(dir);
}

TEST(LinuxCncEmit, OutputDirectoryHoldsTheProgramTheRuntimeAndTheData) {
  fs::path dir = Scratch("dir");
  test::SmtcalRun first = CompileToDir(kExample, kCell, dir / "out");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_TRUE(fs::is_regular_file(dir / "out" / "layers.ngc"));
  for (const EmbeddedFile& file : LinuxCncRuntimeFiles()) {
    EXPECT_EQ(test::ReadFileText(dir / "out" / "subroutines" / file.name), file.text) << file.name;
  }
  std::string data = test::ReadFileText(dir / "out" / "subroutines" / "smtcal_data.ngc");
  EXPECT_NE(data.find("o<smtcal_data> sub"), std::string::npos);
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1u) << "no temporary left beside the output";

  // Compiling again replaces the earlier output with the same bytes.
  std::string main = test::ReadFileText(dir / "out" / "layers.ngc");
  test::SmtcalRun again = CompileToDir(kExample, kCell, dir / "out");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(test::ReadFileText(dir / "out" / "layers.ngc"), main);
  EXPECT_EQ(test::ReadFileText(dir / "out" / "subroutines" / "smtcal_data.ngc"), data);

  // -o - prints the same program and data for review.
  test::SmtcalRun review = test::RunSmtcal(
      fmt::format("compile {} --cell {} --target linuxcnc -o -", Quote(kExample), Quote(kCell)));
  ASSERT_EQ(review.exit_code, 0) << review.err;
  const std::string aborts = test::ReadFileText(dir / "out" / "subroutines" / "smtcal_scan_abort.ngc");
  EXPECT_NE(aborts.find("(abort,smtcal: marker scan of fixture Board failed check missing_trip: "), std::string::npos);
  const std::string record = test::ReadFileText(dir / "out" / "subroutines" / "smtcal_record.ngc");
  const std::string record_open = test::ReadFileText(dir / "out" / "subroutines" / "smtcal_record_open.ngc");
  EXPECT_EQ(review.out, "(smtcal file: layers.ngc)\n" + main + "(smtcal file: subroutines/smtcal_data.ngc)\n" + data +
                            "(smtcal file: subroutines/smtcal_record.ngc)\n" + record +
                            "(smtcal file: subroutines/smtcal_record_open.ngc)\n" + record_open +
                            "(smtcal file: subroutines/smtcal_scan_abort.ngc)\n" + aborts);
  fs::remove_all(dir);
}

TEST(LinuxCncEmit, RefusesToReplaceADirectorySmtcalDidNotWrite) {
  fs::path dir = Scratch("foreign");
  fs::create_directories(dir / "out");
  std::ofstream(dir / "out" / "notes.txt") << "mine\n";
  test::SmtcalRun run = CompileToDir(kExample, kCell, dir / "out");
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.err.find("will not replace"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("notes.txt"), std::string::npos) << run.err;
  EXPECT_EQ(test::ReadFileText(dir / "out" / "notes.txt"), "mine\n");

  // A .ngc file someone else wrote is refused as well.
  fs::remove(dir / "out" / "notes.txt");
  std::ofstream(dir / "out" / "layers.ngc") << "G0 X0\nM2\n";
  run = CompileToDir(kExample, kCell, dir / "out");
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_EQ(test::ReadFileText(dir / "out" / "layers.ngc"), "G0 X0\nM2\n");
  fs::remove_all(dir);
}

// Comments rs274 would misread: parentheses and commas in source text. Every
// block names the source line it came from, except those of the Pick and
// Place subroutine, which serves them all.
TEST(LinuxCncEmit, CommentsHoldNoParenthesesOrCommas) {
  fs::path dir = Scratch("comments");
  test::SmtcalRun run = CompileToDir(kExample, kCell, dir / "out");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream lines(test::ReadFileText(dir / "out" / "layers.ngc"));
  std::string line;
  int blocks = 0, subroutine_lines = 0;
  bool in_subroutine = false;
  while (std::getline(lines, line)) {
    std::size_t first = line.find_first_not_of(' ');
    if (line.compare(first, 17, "o<pick_place> sub") == 0) in_subroutine = true;
    const bool subroutine = in_subroutine;
    if (line.compare(first, 20, "o<pick_place> endsub") == 0) in_subroutine = false;
    std::size_t open = line.find('(');
    if (subroutine) {
      ++subroutine_lines;
      if (open == std::string::npos) continue;
    }
    ASSERT_NE(open, std::string::npos) << "every line carries a comment: " << line;
    std::string comment = line.substr(open + 1);
    ASSERT_TRUE(comment.ends_with(")")) << line;
    comment.pop_back();
    EXPECT_EQ(comment.find_first_of("()"), std::string::npos) << line;
    if (comment.starts_with("abort,")) comment = comment.substr(6);
    EXPECT_EQ(comment.find(','), std::string::npos) << line;
    if (!subroutine && open > 0 && first < open) {
      ++blocks;
      EXPECT_TRUE(comment.starts_with("layers.place:")) << "a block names its source line: " << line;
    }
  }
  EXPECT_GT(blocks, 50);
  EXPECT_GT(subroutine_lines, 10) << "the Pick and Place subroutine";
  fs::remove_all(dir);
}

// control.place in rs274 with the board at its nominal pose and every input
// off: the loops, branches, pallets, offsets, waits and outputs do what the
// language says, and every target is commanded at the compiler's nominal
// (run-time and fixture targets: as the runtime corrects them).
TEST(LinuxCncEmit, ControlFlowAndTargetsOfTheControlCase) {
  ASSERT_TRUE(test::HaveRs274()) << "rs274 is not installed: install linuxcnc-uspace (tools/install-deps.sh)";
  const fs::path program = kGolden / "control.place";
  auto c = CompileInProcess(program, kCell);
  ASSERT_TRUE(c->cell);
  const CompileState& state = *c->program.compile;
  // The targets of one source line, in the order the compile-time run met them.
  auto targets_at = [&](std::uint32_t line) {
    std::vector<const Target*> found;
    for (const Target& target : state.targets) {
      if (target.stmt->loc.line == line) found.push_back(&target);
    }
    return found;
  };
  fs::path dir = Scratch("control");
  test::SmtcalRun compiled = CompileToDir(program, kCell, dir / "out");
  ASSERT_EQ(compiled.exit_code, 0) << compiled.err;
  test::Rs274Result run = RunCompiled(dir / "out", "control.ngc", ProbeReplacement(TripsAt(*c->cell)));
  ASSERT_TRUE(RanToTheEnd(run)) << run.err << Tail(run.out);

  // 6 x (Pick, Place), 3 x (Pick, Place), Go, Move, Jump.
  ASSERT_EQ(run.moves.size(), 59u);
  auto expect_at = [&](std::size_t move, const Target& target, const char* what) {
    SCOPED_TRACE(fmt::format("{} {} (line {}), move {}", what, target.text, target.stmt->loc.line, move));
    EXPECT_NEAR(run.moves[move].xyzabc[0], target.nominal[0], kPrintedMm);
    EXPECT_NEAR(run.moves[move].xyzabc[1], target.nominal[1], kPrintedMm);
    EXPECT_NEAR(run.moves[move].xyzabc[5], target.nominal[3], kPrintedMm);
  };
  std::vector<const Target*> picks = targets_at(32), places = targets_at(33);
  ASSERT_EQ(picks.size(), 6u);
  ASSERT_EQ(places.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_EQ(picks[k]->kind, CorrectionKind::kRunTimeBase);
    EXPECT_EQ(places[k]->kind, CorrectionKind::kFixture);
    expect_at(6 * k + 1, *picks[k], "Pick Pallet(1, k)");
    expect_at(6 * k + 4, *places[k], "Place Pallet(2, k) + X(pitch) - U(90.0)");
    EXPECT_NEAR(run.moves[6 * k + 5].xyzabc[2], places[k]->nominal[2], kPrintedMm);
  }
  // k = 3, 2, 1: Sw(14) is off, so the first ElseIf picks Pallet(1, 2, 2) at LimZ -2.
  std::vector<const Target*> spare = targets_at(40), on_a = targets_at(46);
  ASSERT_EQ(spare.size(), 1u);
  ASSERT_EQ(on_a.size(), 3u);
  for (std::size_t n = 0; n < 3; ++n) {
    std::size_t at = 36 + 6 * n;
    EXPECT_NEAR(run.moves[at].xyzabc[2], -2.0, kPrintedMm) << "LimZ -2.0";
    expect_at(at + 1, *spare[0], "Pick Pallet(1, 2, 2)");
    EXPECT_NEAR(run.moves[at + 3].xyzabc[2], -1.0, kPrintedMm) << "LimZ -1.0";
    expect_at(at + 4, *on_a[n], "Place A + Y(k * 1.5)");
  }
  EXPECT_EQ(run.moves[54].kind, "STRAIGHT_TRAVERSE");
  EXPECT_NEAR(run.moves[54].xyzabc[0], 100.0, kPrintedMm) << "Go outside every region: as written";
  EXPECT_EQ(run.moves[55].kind, "STRAIGHT_FEED");
  expect_at(55, *targets_at(56)[0], "Move");
  expect_at(57, *targets_at(57)[0], "Jump Feed + Z(5.0)");
  EXPECT_NEAR(run.moves[58].xyzabc[2], -7.0, kPrintedMm);

  // Waits: Unload's 0.5 s, then For t = 0.5 To 0.0 Step -0.25.
  std::vector<std::string> dwells, outputs;
  for (const std::string& canon : run.canon) {
    if (canon.starts_with("DWELL(")) dwells.push_back(canon);
    if (canon.starts_with("SET_AUX_OUTPUT_BIT(") || canon.starts_with("CLEAR_AUX_OUTPUT_BIT(")) {
      outputs.push_back(canon);
    }
  }
  EXPECT_EQ(dwells, (std::vector<std::string>{"DWELL(0.5000)", "DWELL(0.5000)", "DWELL(0.2500)", "DWELL(0.0000)"}));
  // Vacuum 8 on and off for 9 parts, Unload's output 14, Drain's 15 once
  // (Exit Function leaves its loop at i = 2).
  std::vector<std::string> want;
  for (int part = 0; part < 9; ++part) {
    want.push_back("SET_AUX_OUTPUT_BIT(8)");
    want.push_back("CLEAR_AUX_OUTPUT_BIT(8)");
  }
  want.insert(want.end(), {"SET_AUX_OUTPUT_BIT(14)", "CLEAR_AUX_OUTPUT_BIT(14)", "SET_AUX_OUTPUT_BIT(15)"});
  EXPECT_EQ(outputs, want);
  fs::remove_all(dir);
}

// The rotation axis comes from the cell's [linuxcnc] table.
TEST(LinuxCncEmit, RotationGoesOnTheCellsAxis) {
  fs::path dir = Scratch("axis");
  std::string cell = test::ReadFileText(kCell);
  std::string tables = (kSource / "examples" / "paper-cell").string() + "/";
  for (std::size_t at = 0; (at = cell.find("table = \"", at)) != std::string::npos; at += 9 + tables.size()) {
    cell.insert(at + 9, tables);
  }
  std::size_t axis = cell.find("rotation_axis = \"C\"");
  ASSERT_NE(axis, std::string::npos);
  cell.replace(axis, 19, "rotation_axis = \"B\"");
  std::ofstream(dir / "b.cell.toml") << cell;
  test::SmtcalRun run = test::RunSmtcal(
      fmt::format("compile {} --cell {} --target linuxcnc -o -", Quote(kExample), Quote(dir / "b.cell.toml")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // Every Pick and Place moves through the one subroutine: its crossing
  // commands u on B, with the fixture's angle already added to it.
  EXPECT_NE(run.out.find("  G0 X#2 Y#3 B#5\n"), std::string::npos);
  EXPECT_NE(run.out.find("o<pick_place> call [-2] [240.0857889872] [21.9298677895] "), std::string::npos);
  EXPECT_NE(run.out.find("#5 = [#5 + #<_smtcal_angle>]"), std::string::npos);
  std::istringstream lines(run.out);
  int moves = 0;
  for (std::string line; std::getline(lines, line);) {
    std::string block = line.substr(0, line.find('('));
    if (block.find("G0 ") == std::string::npos && block.find("G1 ") == std::string::npos) continue;
    ++moves;
    EXPECT_EQ(block.find(" C"), std::string::npos) << "nothing commands C: " << line;
  }
  EXPECT_EQ(moves, 3);  // the subroutine's rise, crossing and descent: the example has no Jump, Go or Move
  fs::remove_all(dir);
}

}  // namespace
}  // namespace smtcal
