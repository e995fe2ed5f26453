// The IR verifier: a well-formed IR passes; each broken invariant is found
// and named with its node and location.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ir/verifier.h"
#include "tests/unit/ir/ir_builder.h"

namespace smtcal {
namespace {

using test::IrBuilder;

std::vector<std::string> Problems(IrBuilder& b) {
  std::vector<std::string> problems;
  for (const VerifierIssue& issue : VerifyProgram(b.program)) {
    problems.push_back(FormatVerifierIssue(issue, b.sources, b.program.file));
  }
  return problems;
}

void SmallProgram(IrBuilder& b) {
  b.Header("T");
  b.Fixture("Board");
  b.Point("C1", {1, 2, 3, 90}, "Board");
  b.Function("Main");
  b.Cycle("Board");
  b.For("i", b.Int(1), b.Int(3));
  b.Place(b.Offset(b.Named("C1"), ir::Axis::X, b.Var("i")), b.Int(8));
  b.Next();
  b.If(b.Sw(b.Int(1)));
  b.SetOutput(true, b.Int(2));
  b.Else();
  b.Wait(b.Real(0.5));
  b.End();
  b.End();
  b.End();
}

ir::Function& Main(IrBuilder& b) { return std::get<ir::Function>(b.program.items[4]->node); }

TEST(Verifier, AcceptsAWellFormedProgram) {
  IrBuilder b;
  SmallProgram(b);
  b.Finish();
  EXPECT_EQ(Problems(b), std::vector<std::string>{});
}

TEST(Verifier, NamesANullOperandWithItsNodeAndLocation) {
  IrBuilder b;
  SmallProgram(b);
  b.Finish();
  ir::Stmt& cycle = *Main(b).body[0];
  ir::Stmt& loop = *std::get<ir::Cycle>(cycle.node).body[0];
  ir::Stmt& place = *std::get<ir::For>(loop.node).body[0];
  std::get<ir::PickPlace>(place.node).target.offsets[0].amount.reset();
  EXPECT_EQ(Problems(b), std::vector<std::string>{fmt::format(
                             "test.place:{}:1: PickPlace: a point offset's amount is null", place.loc.line)});
}

TEST(Verifier, FindsAFunctionInsideABlockAndAStatementAtTopLevel) {
  IrBuilder b;
  SmallProgram(b);
  b.Finish();
  // Move Main's Cycle to the top level and Main into a block of another function.
  ir::StmtPtr cycle = std::move(Main(b).body[0]);
  Main(b).body.clear();
  SourceLoc cycle_loc = cycle->loc;
  b.program.items.push_back(std::move(cycle));
  auto outer = std::make_unique<ir::Stmt>();
  outer->loc = b.program.items[4]->loc;
  ir::Function wrapper{"Wrapper", b.program.items[4]->loc, {}, {b.program.items[4]->loc, ""}};
  wrapper.body.push_back(std::move(b.program.items[4]));
  outer->node = std::move(wrapper);
  b.program.items[4] = std::move(outer);

  std::vector<std::string> problems = Problems(b);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0], "test.place:5:1: Function: is inside the block of a Function; it may appear only at top level");
  EXPECT_EQ(problems[1], fmt::format("test.place:{}:1: Cycle: is a statement at top level; statements belong "
                                     "inside a Function",
                                     cycle_loc.line));
}

TEST(Verifier, FindsUnknownLocationsEmptyNamesAndNonFiniteNumbers) {
  IrBuilder b;
  SmallProgram(b);
  b.Finish();
  auto& point = std::get<ir::PointDecl>(b.program.items[3]->node);
  point.coords.values[0] = std::numeric_limits<double>::quiet_NaN();
  point.name.clear();
  b.program.items[2]->loc = SourceLoc{};
  std::vector<std::string> problems = Problems(b);
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0], "<unknown location>: FixtureDecl: the statement has no known source location");
  EXPECT_EQ(problems[1], "test.place:4:1: PointDecl: the point name is empty");
  EXPECT_EQ(problems[2], "test.place:4:1: PointDecl: XY(...) holds a non-finite value nan");
}

TEST(Verifier, FindsMalformedIfsAndVarDecls) {
  IrBuilder b;
  b.Header("T");
  b.Variables(ir::VarType::Integer, {"a", "b"});
  b.Function("Main");
  b.If(b.OnOff(true));
  b.Else();
  b.End();
  b.End();
  b.Finish();
  std::get<ir::VarDecl>(b.program.items[2]->node).name_locs.pop_back();
  auto& branch = std::get<ir::If>(std::get<ir::Function>(b.program.items[3]->node).body[0]->node);
  std::swap(branch.branches[0], branch.branches[1]);  // Else first
  std::vector<std::string> problems = Problems(b);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0], "test.place:3:1: VarDecl: has 2 names but 1 name locations");
  EXPECT_EQ(problems[1], "test.place:5:1: If: branch 1 has no condition; only a last Else may lack one");
}

TEST(Verifier, FindsALiteralMarkedIntegerThatIsNot) {
  IrBuilder b;
  b.Header("T");
  b.Function("Main");
  b.Wait(b.Int(1));
  b.End();
  b.Finish();
  auto& wait = std::get<ir::WaitTime>(std::get<ir::Function>(b.program.items[2]->node).body[0]->node);
  std::get<ir::NumberLit>(wait.seconds->node).value = 1.5;
  wait.seconds->length = 0;
  std::vector<std::string> problems = Problems(b);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0], "test.place:4:1: NumberLit: has a caret length of 0");
  EXPECT_EQ(problems[1], "test.place:4:1: NumberLit: is marked Integer but holds 1.5");
}

}  // namespace
}  // namespace smtcal
