// The compile-time run that finds motion targets (passes/correction/target_trace.h):
// loops, branches on inputs, calls, pallets and frames, table-driven.
#include <gtest/gtest.h>

#include <cmath>

#include "passes/correction/target_trace.h"
#include "passes/pass_manager.h"
#include "tests/unit/parse_text.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

struct Traced {
  test::ParsedText parsed;
  CompileState state;
};

// Parses, checks (must be clean) and traces `body` inside a standard header.
std::unique_ptr<Traced> Trace(const std::string& declarations, const std::string& main_body) {
  auto traced = std::make_unique<Traced>();
  std::string text = "Program T\nUnits mm\nFixture Board\nVacuum 8\n" + declarations + "Function Main\n" + main_body +
                     "Fend\n";
  traced->parsed = test::ParseText(text);
  EXPECT_TRUE(traced->parsed.ok()) << traced->parsed.diagnostics;
  FixtureBinding board;
  board.name = "Board";
  traced->state.fixtures.push_back(board);
  sema::SymbolTable symbols = sema::SymbolTable::Build(traced->parsed.program);
  SourceManager sources;
  Diagnostics diags(sources);
  TraceTargets(traced->parsed.program, symbols, traced->state, diags);
  EXPECT_FALSE(diags.has_errors());
  return traced;
}

TEST(TargetTrace, LoopWithConstantBoundsGivesOneTargetPerPosition) {
  auto t = Trace("Point P = XY(10, 20, -3, 0)\n",
                 "  Integer i\n  For i = 0 To 2\n    Jump P + X(i * 5)\n  Next i\n"
                 "  For i = 0 To 2\n    Jump P\n  Next i\n");
  ASSERT_EQ(t->state.targets.size(), 4u);  // three offsets, then P once
  EXPECT_DOUBLE_EQ(t->state.targets[0].in_frame[0], 10);
  EXPECT_DOUBLE_EQ(t->state.targets[2].in_frame[0], 20);
  EXPECT_DOUBLE_EQ(t->state.targets[3].in_frame[0], 10);
  EXPECT_TRUE(t->state.trace_complete);
}

TEST(TargetTrace, AnInputBranchRunsBothBranchesAndForgetsWhatTheyDisagreeOn) {
  auto t = Trace("Point P = XY(10, 20, -3, 0)\n",
                 "  Real d\n  If Sw(3) = On Then\n    d = 1\n    Jump P + X(100)\n  Else\n    d = 2\n  EndIf\n"
                 "  Jump P + X(d)\n");
  ASSERT_EQ(t->state.targets.size(), 2u);
  EXPECT_TRUE(t->state.targets[0].known);
  EXPECT_DOUBLE_EQ(t->state.targets[0].in_frame[0], 110);
  EXPECT_FALSE(t->state.targets[1].known);
  EXPECT_EQ(t->state.targets[1].unknown_because, "d");
}

TEST(TargetTrace, AKnownConditionTakesOnlyItsBranch) {
  auto t = Trace("Point P = XY(10, 20, -3, 0)\n",
                 "  Integer n\n  n = 3\n  If n > 2 Then\n    Jump P\n  Else\n    Jump P + Y(1)\n  EndIf\n");
  ASSERT_EQ(t->state.targets.size(), 1u);
  EXPECT_DOUBLE_EQ(t->state.targets[0].in_frame[1], 20);
}

TEST(TargetTrace, PalletSlotsInterpolateTheCorners) {
  struct Case {
    std::string index;
    double x, y;
  } cases[] = {{"1, 1", 0, 0}, {"3, 1", 20, 0}, {"2, 2", 10, 12}, {"5", 10, 12}, {"6", 20, 12}, {"1", 0, 0}};
  for (const Case& c : cases) {
    auto t = Trace("Point A = XY(0, 0, -12, 0)\nPoint B = XY(20, 0, -12, 0)\nPoint C = XY(0, 12, -12, 0)\n"
                   "Pallet 1, A, B, C, 3, 2\n",
                   "  Pick Pallet(1, " + c.index + ")\n");
    ASSERT_EQ(t->state.targets.size(), 1u) << c.index;
    EXPECT_NEAR(t->state.targets[0].in_frame[0], c.x, 1e-12) << c.index;
    EXPECT_NEAR(t->state.targets[0].in_frame[1], c.y, 1e-12) << c.index;
  }
}

TEST(TargetTrace, LocalFramesRotateAndTranslateIntoTheFixture) {
  auto t = Trace("Local L = XY(100, 50, 0, 90) In Board\nPoint P = XY(10, 0, -3, 5) In L\n",
                 "  Cycle Board\n    Place P\n  EndCycle\n");
  ASSERT_EQ(t->state.targets.size(), 1u);
  const Target& target = t->state.targets[0];
  EXPECT_EQ(target.fixture, 0);
  EXPECT_NEAR(target.in_frame[0], 100, 1e-12);
  EXPECT_NEAR(target.in_frame[1], 60, 1e-12);
  EXPECT_NEAR(target.in_frame[3], 95, 1e-12);
  ASSERT_EQ(t->state.cycle_traces.size(), 1u);
  EXPECT_EQ(t->state.cycle_traces.begin()->second.size(), 1u);
}

TEST(TargetTrace, CallsAndExitFunctionAreFollowed) {
  auto t = Trace("Point P = XY(10, 20, -3, 0)\nFunction Sub\n  Jump P\n  Exit Function\n  Jump P + X(1)\nFend\n",
                 "  Call Sub\n");
  ASSERT_EQ(t->state.targets.size(), 1u);
  EXPECT_EQ(t->state.targets[0].call_path, "Main > Sub");
}

TEST(TargetTrace, UnknownLoopBoundsRunTheBodyOnceWithAnUnknownVariable) {
  auto t = Trace("Point P = XY(10, 20, -3, 0)\n",
                 "  Integer i, n\n  If Sw(1) = On Then\n    n = 4\n  EndIf\n  For i = 1 To n\n    Jump P + X(i)\n"
                 "  Next i\n  Jump P\n");
  ASSERT_EQ(t->state.targets.size(), 2u);
  EXPECT_FALSE(t->state.targets[0].known);
  EXPECT_TRUE(t->state.targets[1].known);
}

}  // namespace
}  // namespace smtcal
