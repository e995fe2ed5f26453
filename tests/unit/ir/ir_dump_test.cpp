// DumpIr: every field printed, deterministic, and locations only on request.
#include "ir/ir_dump.h"

#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace smtcal {
namespace {

ir::ExprPtr Num(double value, bool is_integer, SourceLoc loc = {}, std::uint32_t length = 1) {
  auto expr = std::make_unique<ir::Expr>();
  expr->loc = loc;
  expr->length = length;
  expr->node = ir::NumberLit{value, is_integer};
  return expr;
}
ir::ExprPtr Var(std::string name) {
  auto expr = std::make_unique<ir::Expr>();
  expr->node = ir::VariableRef{std::move(name)};
  return expr;
}
ir::ExprPtr Make(decltype(ir::Expr::node) node) {
  auto expr = std::make_unique<ir::Expr>();
  expr->node = std::move(node);
  return expr;
}
template <typename Node>
ir::StmtPtr Stmt(Node node, SourceLoc loc = {}, std::uint32_t length = 1) {
  auto stmt = std::make_unique<ir::Stmt>();
  stmt->loc = loc;
  stmt->length = length;
  stmt->node = std::move(node);
  return stmt;
}
ir::PointExpr Named(std::string name) {
  ir::PointExpr point;
  point.base = ir::NamedPoint{std::move(name), 1};
  return point;
}

// A program with every kind of statement and expression.
ir::Program EveryNode() {
  ir::Program program;
  program.file = 1;
  program.items.push_back(Stmt(ir::Comment{" header"}));
  program.items.push_back(Stmt(ir::ProgramDecl{"LayerA", {}}));
  program.items.push_back(Stmt(ir::UnitsDecl{"mm", {}}));
  program.items.push_back(Stmt(ir::FixtureDecl{"Board", {}}));
  program.items.push_back(Stmt(ir::LocalDecl{"L1", {}, ir::Coords{{1, 2, 0, 0}, {}}, "Board", {}}));
  program.items.push_back(
      Stmt(ir::PointDecl{"U3", {}, true, ir::Coords{{171.204, 97.311, -3, 0}, {}}, "Board", {}}));
  program.items.push_back(Stmt(ir::PointDecl{"Feed", {}, false, ir::Coords{{0.1, -0.0, 1e21, 90}, {}}, "", {}}));
  program.items.push_back(Stmt(ir::PalletDecl{1, {}, {"A", "B", "C"}, {}, 3, {}, 4, {}}));
  program.items.push_back(Stmt(ir::VacuumDecl{2, {}}));
  program.items.push_back(Stmt(ir::VarDecl{ir::VarType::Real, {"d", "e"}, {}}));

  ir::Function main;
  main.name = "Main";
  main.body.push_back(Stmt(ir::VarDecl{ir::VarType::Integer, {"i"}, {}}));
  ir::ExprPtr minus = Make(ir::UnaryExpr{ir::UnaryOp::Negate, Num(2.5, false)});
  main.body.push_back(
      Stmt(ir::Assign{"x", Make(ir::BinaryExpr{ir::BinaryOp::Add, Num(1, true), std::move(minus)})}));
  ir::Motion jump;
  jump.target = Named("P");
  ir::PointOffset offset;
  offset.negative = true;
  offset.axis = ir::Axis::U;
  offset.amount = Num(90, true);
  jump.target.offsets.push_back(std::move(offset));
  jump.limz = Num(-3, true);
  main.body.push_back(Stmt(std::move(jump)));
  ir::Motion go;
  go.kind = ir::MotionKind::Go;
  go.target.base = ir::Coords{{1, 2, 3, 4}, {}};
  main.body.push_back(Stmt(std::move(go)));
  ir::Motion move;
  move.kind = ir::MotionKind::Move;
  move.target.base = ir::PalletPoint{Num(1, true), Var("i"), nullptr};
  main.body.push_back(Stmt(std::move(move)));
  ir::PickPlace pick;
  pick.target.base = ir::PalletPoint{Num(1, true), Num(2, true), Num(3, true)};
  pick.vacuum = Num(2, true);
  main.body.push_back(Stmt(std::move(pick)));
  ir::PickPlace place;
  place.kind = ir::PickPlaceKind::Place;
  place.target = Named("C1");
  place.limz = Num(0, true);
  main.body.push_back(Stmt(std::move(place)));
  main.body.push_back(Stmt(ir::SetOutput{true, Num(3, true)}));
  main.body.push_back(Stmt(ir::SetOutput{false, Make(ir::SwitchRead{Num(4, true)})}));
  main.body.push_back(Stmt(ir::WaitTime{Num(0.5, false)}));
  main.body.push_back(Stmt(ir::WaitSwitch{Num(1, true), false}));

  ir::For loop;
  loop.var = "layer";
  loop.from = Num(0, true);
  loop.to = Num(2, true);
  loop.step = Num(1, true);
  loop.next_var = "layer";
  loop.body.push_back(Stmt(ir::Call{"Feed", {}}));
  loop.end.comment = " next";
  ir::StmtPtr for_stmt = Stmt(std::move(loop));
  for_stmt->blank_line_before = true;
  for_stmt->trailing_comment = " loop";
  main.body.push_back(std::move(for_stmt));

  ir::If branch;
  ir::IfBranch first;
  first.condition = Make(ir::BinaryExpr{ir::BinaryOp::Eq, Var("a"), Make(ir::OnOffLit{true})});
  first.body.push_back(Stmt(ir::ExitFunction{}));
  branch.branches.push_back(std::move(first));
  ir::IfBranch second;
  second.condition = Make(ir::UnaryExpr{ir::UnaryOp::Not, Make(ir::OnOffLit{false})});
  second.comment = " second";
  branch.branches.push_back(std::move(second));
  ir::IfBranch otherwise;
  otherwise.body.push_back(Stmt(ir::Scan{"Board", {}}));
  branch.branches.push_back(std::move(otherwise));
  main.body.push_back(Stmt(std::move(branch)));

  ir::Cycle cycle;
  cycle.fixture = "Board";
  main.body.push_back(Stmt(std::move(cycle)));
  main.end.comment = " done";
  program.items.push_back(Stmt(std::move(main)));
  return program;
}

TEST(IrDump, PrintsEveryNode) {
  EXPECT_EQ(DumpIr(EveryNode()),
            "(program\n"
            "  (comment \" header\")\n"
            "  (program-decl LayerA)\n"
            "  (units mm)\n"
            "  (fixture Board)\n"
            "  (local L1 (xy 1 2 0 0) :frame Board)\n"
            "  (point-decl U3 :taught (xy 171.204 97.311 -3 0) :frame Board)\n"
            "  (point-decl Feed (xy 0.1 -0 1e+21 90))\n"
            "  (pallet-decl 1 A B C 3 4)\n"
            "  (vacuum-decl 2)\n"
            "  (real d e)\n"
            "  (function Main\n"
            "    (integer i)\n"
            "    (assign x (+ (int 1) (neg (real 2.5))))\n"
            "    (jump (point (name P) (-u (int 90))) :limz (int -3))\n"
            "    (go (point (xy 1 2 3 4)))\n"
            "    (move (point (pallet (int 1) (var i))))\n"
            "    (pick (point (pallet (int 1) (int 2) (int 3))) :vacuum (int 2))\n"
            "    (place (point (name C1)) :limz (int 0))\n"
            "    (on (int 3))\n"
            "    (off (sw (int 4)))\n"
            "    (wait (real 0.5))\n"
            "    (wait-sw (int 1) off)\n"
            "    (for layer (int 0) (int 2) :step (int 1) :next layer :blank :comment \" loop\"\n"
            "      (call Feed)\n"
            "      (end :comment \" next\"))\n"
            "    (if\n"
            "      (branch (= (var a) (on))\n"
            "        (exit-function))\n"
            "      (branch (not (off)) :comment \" second\")\n"
            "      (else\n"
            "        (scan Board))\n"
            "      (end))\n"
            "    (cycle Board\n"
            "      (end))\n"
            "    (end :comment \" done\")))\n");
}

TEST(IrDump, QuotesOddNamesAndEscapesComments) {
  ir::Program program;
  program.items.push_back(Stmt(ir::ProgramDecl{"has space", {}}));
  program.items.push_back(Stmt(ir::FixtureDecl{"", {}}));
  program.items.push_back(Stmt(ir::Comment{"a \"quote\" \\ tab\t cr\r bell\x07 \xC2\xB0"}));
  EXPECT_EQ(DumpIr(program),
            "(program\n"
            "  (program-decl \"has space\")\n"
            "  (fixture \"\")\n"
            "  (comment \"a \\\"quote\\\" \\\\ tab\\t cr\\r bell\\x07 \xC2\xB0\"))\n");
}

TEST(IrDump, NumbersRoundTrip) {
  EXPECT_EQ(DumpExpr(*Num(0.1, false)), "(real 0.1)");
  EXPECT_EQ(DumpExpr(*Num(1.0000000000000002, false)), "(real 1.0000000000000002)");
  EXPECT_EQ(DumpExpr(*Num(1e21, true)), "(int 1e+21)");
  EXPECT_EQ(DumpExpr(*Num(12, true)), "(int 12)");
  EXPECT_EQ(DumpExpr(*Num(12, false)), "(real 12)");
}

TEST(IrDump, LocationsOnlyWhenAsked) {
  ir::Program program;
  program.file = 1;
  ir::Assign assign{"x", Num(1.5, false, SourceLoc{1, 2, 7}, 3)};
  program.items.push_back(Stmt(std::move(assign), SourceLoc{1, 2, 3}, 1));
  ir::Motion jump;
  jump.target = Named("P");
  jump.target.loc = SourceLoc{1, 3, 8};
  program.items.push_back(Stmt(std::move(jump), SourceLoc{1, 3, 3}, 4));
  EXPECT_EQ(DumpIr(program), "(program\n  (assign x (real 1.5))\n  (jump (point (name P))))\n");
  EXPECT_EQ(DumpIr(program, true),
            "(program @1\n"
            "  (assign @1:2:3/1 x (real @1:2:7/3 1.5))\n"
            "  (jump @1:3:3/4 (point @1:3:8 (name /1 P))))\n");
}

TEST(IrDump, NullExpressionsPrintAsNil) {
  ir::Program program;
  program.items.push_back(Stmt(ir::Assign{"x", nullptr}));
  program.items.push_back(nullptr);
  EXPECT_EQ(DumpIr(program), "(program\n  (assign x nil)\n  nil)\n");
}

// "Same IR exactly when the dumps are equal": changing any one field of the
// full program changes the dump.
TEST(IrDump, EveryFieldShowsInTheDump) {
  std::string base = DumpIr(EveryNode());
  auto body = [](ir::Program& p) -> ir::Block& { return std::get<ir::Function>(p.items.back()->node).body; };
  std::vector<std::function<void(ir::Program&)>> changes = {
      [](ir::Program& p) { std::get<ir::Comment>(p.items[0]->node).text = " Header"; },
      [](ir::Program& p) { p.items[1]->blank_line_before = true; },
      [](ir::Program& p) { p.items[1]->trailing_comment = "x"; },
      [](ir::Program& p) { std::get<ir::PointDecl>(p.items[5]->node).taught = false; },
      [](ir::Program& p) { std::get<ir::PointDecl>(p.items[5]->node).coords.values[3] = 1e-300; },
      [](ir::Program& p) { std::get<ir::PointDecl>(p.items[6]->node).coords.values[1] = 0.0; },
      [](ir::Program& p) { std::get<ir::PalletDecl>(p.items[7]->node).rows = 5; },
      [](ir::Program& p) { std::get<ir::VarDecl>(p.items[9]->node).type = ir::VarType::Integer; },
      [&](ir::Program& p) {
        auto& assign = std::get<ir::Assign>(body(p)[1]->node);
        std::get<ir::NumberLit>(std::get<ir::BinaryExpr>(assign.value->node).lhs->node).is_integer = false;
      },
      [&](ir::Program& p) { std::get<ir::Motion>(body(p)[2]->node).target.offsets[0].negative = false; },
      [&](ir::Program& p) { std::get<ir::Motion>(body(p)[2]->node).limz = nullptr; },
      [&](ir::Program& p) { std::get<ir::PickPlace>(body(p)[5]->node).vacuum = nullptr; },
      [&](ir::Program& p) { std::get<ir::WaitSwitch>(body(p)[10]->node).on = true; },
      [&](ir::Program& p) { std::get<ir::For>(body(p)[11]->node).next_var.clear(); },
      [&](ir::Program& p) { std::get<ir::For>(body(p)[11]->node).end.comment.clear(); },
      [&](ir::Program& p) { std::get<ir::If>(body(p)[12]->node).branches[1].comment.clear(); },
      [&](ir::Program& p) { std::get<ir::If>(body(p)[12]->node).branches.pop_back(); },
      [](ir::Program& p) { std::get<ir::Function>(p.items.back()->node).end.comment.clear(); },
  };
  for (std::size_t i = 0; i < changes.size(); ++i) {
    ir::Program program = EveryNode();
    changes[i](program);
    EXPECT_NE(DumpIr(program), base) << "change " << i;
  }
  // Locations are not part of the IR's identity.
  ir::Program moved = EveryNode();
  moved.items[1]->loc = SourceLoc{1, 9, 9};
  EXPECT_EQ(DumpIr(moved), base);
  EXPECT_NE(DumpIr(moved, true), DumpIr(EveryNode(), true));
}

}  // namespace
}  // namespace smtcal
