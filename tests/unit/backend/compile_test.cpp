// End to end: the paper example compiled for the paper cell. Every static
// nominal lands on its required position under the direct calibration within
// 1e-9 mm; taught points convert consistently; the corrected program is a
// clean, canonical program; compiling twice gives the same bytes.
#include <gtest/gtest.h>

#include "backend/place/place_printer.h"
#include "frontend/cell_toml.h"
#include "frontend/parse.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"
#include "passes/pass_manager.h"
#include "tests/unit/parse_text.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

const std::string kExample = SMTCAL_SOURCE_DIR "/examples/paper-cell/layers.place";
const std::string kCell = SMTCAL_SOURCE_DIR "/examples/paper-cell/paper.cell.toml";

struct Compiled {
  SourceManager sources;
  std::unique_ptr<Diagnostics> diags;
  std::optional<cell::Cell> cell;
  ir::Program program;
};

std::unique_ptr<Compiled> CompileExample() {
  auto c = std::make_unique<Compiled>();
  c->diags = std::make_unique<Diagnostics>(c->sources);
  Result<std::uint32_t> file = c->sources.Load(kExample);
  EXPECT_TRUE(file.ok());
  c->program = ParseProgram(file.value(), *c->diags);
  EXPECT_TRUE(RunPasses(c->program, *c->diags, std::vector<std::string>{}, true).ok());
  Result<std::optional<cell::Cell>> cell = cell::LoadCell(kCell, c->sources, *c->diags);
  EXPECT_TRUE(cell.ok());
  c->cell = std::move(cell).value();
  EXPECT_TRUE(c->cell.has_value()) << c->diags->RenderText();
  if (!c->cell) return c;
  c->program.compile = std::make_shared<CompileState>();
  c->program.compile->cell = &*c->cell;
  std::vector<const PassInfo*> passes;
  for (const PassInfo& info : CorrectionPassRegistry()) passes.push_back(&info);
  RunPasses(c->program, *c->diags, passes, /*verify_each=*/true);
  return c;
}

TEST(CompileExample, IsCleanAndEveryStaticNominalLandsOnItsRequiredPosition) {
  auto c = CompileExample();
  ASSERT_TRUE(c->cell);
  EXPECT_EQ(c->diags->error_count(), 0u) << c->diags->RenderText();
  const CompileState& state = *c->program.compile;
  int statics = 0;
  for (const Target& target : state.targets) {
    ASSERT_TRUE(target.known) << target.text;
    ASSERT_NE(target.region, nullptr) << target.text;
    if (target.kind != CorrectionKind::kStatic) continue;
    ++statics;
    InverseSolver solver(target.region->table);
    Solution reached = DirectCalibrate(solver.map(), {target.nominal[0], target.nominal[1]}, OutsidePolicy::kError);
    ASSERT_EQ(reached.status, SolveStatus::kOk) << target.text;
    EXPECT_NEAR(reached.point.x(), target.required[0], 1e-9) << target.text;
    EXPECT_NEAR(reached.point.y(), target.required[1], 1e-9) << target.text;
    EXPECT_EQ(target.nominal[2], target.required[2]) << "z passes through";
    EXPECT_EQ(target.nominal[3], target.required[3]) << "u passes through";
  }
  EXPECT_EQ(statics, 15);  // the distinct feeder slots the example picks from
  int placements = 0;
  for (const Target& target : state.targets) placements += target.is_placement() ? 1 : 0;
  EXPECT_EQ(placements, 40);  // the paper: 40 parts per cycle
  ASSERT_EQ(state.cycles.size(), 1u);
  EXPECT_EQ(state.cycles[0].placements, 40);
  EXPECT_GT(state.cycles[0].scan_s, 0);
}

TEST(CompileExample, TaughtPointsConvertToFixposThatLeadsBackToWhereTheRobotWas) {
  auto c = CompileExample();
  ASSERT_TRUE(c->cell);
  const CompileState& state = *c->program.compile;
  ASSERT_EQ(state.taught.size(), 1u);
  const TaughtPoint& taught = state.taught[0];
  ASSERT_TRUE(state.fixtures[0].fix0);
  Pose4 back = PoseToBase(*state.fixtures[0].fix0, taught.fixpos0);
  EXPECT_NEAR(back[0], taught.reached[0], 1e-9);
  EXPECT_NEAR(back[1], taught.reached[1], 1e-9);
  // F moved it: the robot's error at the taught spot is tens of micrometres.
  double moved = std::hypot(taught.reached[0] - taught.taught[0], taught.reached[1] - taught.taught[1]);
  EXPECT_GT(moved, 1e-3);
  EXPECT_LT(moved, 0.3);
  const auto& decl = std::get<ir::PointDecl>(taught.decl->node);
  EXPECT_FALSE(decl.taught) << "the declaration becomes a programmed point In the fixture";
}

TEST(CompileExample, CorrectedProgramIsCleanCanonicalAndDeterministic) {
  auto first = CompileExample();
  auto second = CompileExample();
  ASSERT_TRUE(first->cell && second->cell);
  std::string text = PrintPlace(first->program);
  EXPECT_EQ(text, PrintPlace(second->program));
  EXPECT_NE(text.find("Scan Board  ' injected by smtcal"), std::string::npos);

  test::ParsedText reparsed = test::ParseText(text);
  ASSERT_TRUE(reparsed.ok()) << reparsed.diagnostics;
  EXPECT_EQ(PrintPlace(reparsed.program), text) << "the corrected program is canonical";
  SourceManager sources;
  std::uint32_t file = sources.Add("corrected.place", text);
  Diagnostics diags(sources);
  ir::Program program = ParseProgram(file, diags);
  ASSERT_TRUE(RunPasses(program, diags, std::vector<std::string>{}, true).ok());
  EXPECT_EQ(diags.error_count(), 0u) << diags.RenderText();
}

TEST(CompileExample, CompileCommandWritesNothingOnError) {
  std::string out = testing::TempDir() + "/compile_on_error.place";
  std::remove(out.c_str());
  test::SmtcalRun run = test::RunSmtcal(
      std::string("compile ") + SMTCAL_SOURCE_DIR + "/tests/golden/compile/fail_target_outside_regions.place" +
          " --cell " + kCell + " -o " + out,
      SMTCAL_SOURCE_DIR);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace smtcal
