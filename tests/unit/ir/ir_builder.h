// Builds .place IR by hand for unit tests of the passes, without the parser:
// one statement per line, each line's text registered in a SourceManager so
// diagnostics point at real lines. Blocks are opened by Function/For/If/Cycle
// and closed by End()/Next(), like the language itself:
//
//   IrBuilder b;
//   b.Header("T");                 // Program T / Units mm
//   b.Fixture("Board");
//   b.Function("Main");
//     b.Cycle("Board");
//       b.Jump(b.Named("C1"));
//     b.End();
//   b.End();
//   ir::Program& program = b.Finish();
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "base/check.h"
#include "base/diagnostics.h"
#include "ir/ir.h"

namespace smtcal::test {

class IrBuilder {
 public:
  // A fresh SourceManager gives its first file id 1; the IR is built with it
  // before the text is complete, and Finish() registers the text.
  static constexpr std::uint32_t kFile = 1;

  // ---------------------------------------------------------------- expressions
  // Expressions sit on the line of the statement that takes them: the next one.

  ir::ExprPtr Int(long value) { return Expr(ir::NumberLit{static_cast<double>(value), true}); }
  ir::ExprPtr Real(double value) { return Expr(ir::NumberLit{value, false}); }
  ir::ExprPtr Var(std::string name) { return Expr(ir::VariableRef{std::move(name)}); }
  ir::ExprPtr OnOff(bool on) { return Expr(ir::OnOffLit{on}); }
  ir::ExprPtr Sw(ir::ExprPtr bit) { return Expr(ir::SwitchRead{std::move(bit)}); }
  ir::ExprPtr Unary(ir::UnaryOp op, ir::ExprPtr operand) { return Expr(ir::UnaryExpr{op, std::move(operand)}); }
  ir::ExprPtr Binary(ir::BinaryOp op, ir::ExprPtr lhs, ir::ExprPtr rhs) {
    return Expr(ir::BinaryExpr{op, std::move(lhs), std::move(rhs)});
  }

  ir::PointExpr Named(std::string name) {
    ir::PointExpr point;
    point.loc = NextLoc();
    auto length = static_cast<std::uint32_t>(name.size());
    point.base = ir::NamedPoint{std::move(name), length};
    return point;
  }
  ir::PointExpr Literal(std::array<double, 4> values) {
    ir::PointExpr point;
    point.loc = NextLoc();
    point.base = Coords(values);
    return point;
  }
  ir::PointExpr Pallet(ir::ExprPtr number, ir::ExprPtr i, ir::ExprPtr j = nullptr) {
    ir::PointExpr point;
    point.loc = NextLoc();
    point.base = ir::PalletPoint{std::move(number), std::move(i), std::move(j)};
    return point;
  }
  ir::PointExpr Offset(ir::PointExpr point, ir::Axis axis, ir::ExprPtr amount, bool negative = false) {
    point.offsets.push_back(ir::PointOffset{NextLoc(), negative, axis, std::move(amount)});
    return point;
  }

  // ---------------------------------------------------------------- top level

  void Header(const std::string& name) {
    Program(name);
    Units("mm");
  }
  ir::Stmt& Comment(const std::string& text) { return Add("'" + text, ir::Comment{text}); }
  // Keyword and name: the name starts after "Keyword ".
  ir::Stmt& Program(const std::string& name) {
    return Add("Program " + name, ir::ProgramDecl{name, Column(9)});
  }
  ir::Stmt& Units(const std::string& unit) { return Add("Units " + unit, ir::UnitsDecl{unit, Column(7)}); }
  ir::Stmt& Fixture(const std::string& name) {
    return Add("Fixture " + name, ir::FixtureDecl{name, Column(9)});
  }
  ir::Stmt& Vacuum(int output) {
    return Add(fmt::format("Vacuum {}", output), ir::VacuumDecl{output, Column(8)});
  }

  ir::Stmt& Local(const std::string& name, std::array<double, 4> origin, const std::string& frame = "") {
    std::string text = fmt::format("Local {} = XY({})", name, fmt::join(origin, ", "));
    SourceLoc frame_loc = FrameLoc(text, frame, " In ");
    return Add(text, ir::LocalDecl{name, Column(7), Coords(origin), frame, frame_loc});
  }
  ir::Stmt& Point(const std::string& name, std::array<double, 4> coords, const std::string& frame = "") {
    std::string text = fmt::format("Point {} = XY({})", name, fmt::join(coords, ", "));
    SourceLoc frame_loc = FrameLoc(text, frame, " In ");
    return Add(text, ir::PointDecl{name, Column(7), false, Coords(coords), frame, frame_loc});
  }
  ir::Stmt& Taught(const std::string& name, std::array<double, 4> coords, const std::string& fixture) {
    std::string text = fmt::format("Taught Point {} = XY({})", name, fmt::join(coords, ", "));
    SourceLoc frame_loc = FrameLoc(text, fixture, " On ");
    return Add(text, ir::PointDecl{name, Column(14), true, Coords(coords), fixture, frame_loc});
  }
  ir::Stmt& PalletDecl(int number, std::array<std::string, 3> corners, int columns, int rows) {
    ir::PalletDecl decl;
    decl.number = number;
    decl.number_loc = Column(8);
    decl.corners = corners;
    decl.columns = columns;
    decl.rows = rows;
    std::string text = fmt::format("Pallet {}", number);
    for (int i = 0; i < 3; ++i) {
      text += ", ";
      decl.corner_locs[i] = Column(text.size() + 1);
      text += corners[i];
    }
    text += ", ";
    decl.columns_loc = Column(text.size() + 1);
    text += fmt::format("{}, ", columns);
    decl.rows_loc = Column(text.size() + 1);
    text += fmt::format("{}", rows);
    return Add(text, std::move(decl));
  }
  ir::Stmt& Variables(ir::VarType type, std::vector<std::string> names) {
    std::string text = type == ir::VarType::Integer ? "Integer" : "Real";
    std::vector<SourceLoc> locs;
    for (std::size_t i = 0; i < names.size(); ++i) {
      text += i == 0 ? " " : ", ";
      locs.push_back(Column(text.size() + 1));
      text += names[i];
    }
    return Add(text, ir::VarDecl{type, std::move(names), std::move(locs)});
  }

  // Opens a Function; End() closes it with Fend.
  ir::Stmt& Function(const std::string& name) {
    ir::Stmt& stmt = Add("Function " + name, ir::Function{name, Column(10), {}, {}});
    auto& function = std::get<ir::Function>(stmt.node);
    open_.push_back({&function.body, &function.end, "Fend"});
    return stmt;
  }

  // ---------------------------------------------------------------- statements

  ir::Stmt& Assign(const std::string& name, ir::ExprPtr value) {
    return Add(name + " = ...", ir::Assign{name, std::move(value)});
  }
  ir::Stmt& Motion(ir::MotionKind kind, ir::PointExpr target, ir::ExprPtr limz = nullptr) {
    const char* word = kind == ir::MotionKind::Jump ? "Jump" : kind == ir::MotionKind::Go ? "Go" : "Move";
    std::string text = fmt::format("{} {}", word, TargetText(target));
    SourceLoc limz_loc;
    if (limz) {
      limz_loc = Column(text.size() + 2);
      text += " LimZ ...";
    }
    return Add(text, ir::Motion{kind, std::move(target), std::move(limz), limz_loc});
  }
  ir::Stmt& Jump(ir::PointExpr target, ir::ExprPtr limz = nullptr) {
    return Motion(ir::MotionKind::Jump, std::move(target), std::move(limz));
  }
  ir::Stmt& Pick(ir::PointExpr target, ir::ExprPtr vacuum = nullptr, ir::ExprPtr limz = nullptr) {
    return PickPlace(ir::PickPlaceKind::Pick, std::move(target), std::move(vacuum), std::move(limz));
  }
  ir::Stmt& Place(ir::PointExpr target, ir::ExprPtr vacuum = nullptr, ir::ExprPtr limz = nullptr) {
    return PickPlace(ir::PickPlaceKind::Place, std::move(target), std::move(vacuum), std::move(limz));
  }
  ir::Stmt& SetOutput(bool on, ir::ExprPtr bit) { return Add(on ? "On ..." : "Off ...", ir::SetOutput{on, std::move(bit)}); }
  ir::Stmt& Wait(ir::ExprPtr seconds) { return Add("Wait ...", ir::WaitTime{std::move(seconds)}); }
  ir::Stmt& WaitSw(ir::ExprPtr bit, bool on) { return Add("Wait Sw(...) = ...", ir::WaitSwitch{std::move(bit), on}); }
  ir::Stmt& Call(const std::string& name) { return Add("Call " + name, ir::Call{name, Column(6)}); }
  ir::Stmt& Scan(const std::string& fixture) { return Add("Scan " + fixture, ir::Scan{fixture, Column(6)}); }
  ir::Stmt& Exit() { return Add("Exit Function", ir::ExitFunction{}); }

  // Opens a For; Next() closes it.
  ir::Stmt& For(const std::string& var, ir::ExprPtr from, ir::ExprPtr to, ir::ExprPtr step = nullptr) {
    SourceLoc var_loc = Column(5);
    ir::Stmt& stmt = Add(fmt::format("For {} = ... To ...", var),
                         ir::For{var, var_loc, std::move(from), std::move(to), std::move(step), {}, {}, {}, {}});
    auto& loop = std::get<ir::For>(stmt.node);
    open_.push_back({&loop.body, &loop.end, "Next"});
    fors_.push_back(&loop);
    return stmt;
  }
  void Next(const std::string& var = "") {
    SMTCAL_CHECK(!fors_.empty(), "Next without For");
    ir::For& loop = *fors_.back();
    fors_.pop_back();
    loop.next_var = var;
    if (!var.empty()) loop.next_var_loc = Column(6);  // "Next var", on the line End() adds
    End(var.empty() ? "Next" : "Next " + var);
  }

  // Opens an If; ElseIf()/Else() start further branches, End() closes it.
  ir::Stmt& If(ir::ExprPtr condition) {
    SourceLoc loc = NextLoc();
    ir::Stmt& stmt = Add("If ... Then", ir::If{});
    auto& branch = std::get<ir::If>(stmt.node);
    branch.branches.push_back(ir::IfBranch{loc, std::move(condition), {}, {}});
    open_.push_back({&branch.branches.back().body, &branch.end, "EndIf"});
    ifs_.push_back(&branch);
    return stmt;
  }
  void ElseIf(ir::ExprPtr condition) { Branch("ElseIf ... Then", std::move(condition)); }
  void Else() { Branch("Else", nullptr); }

  // Opens a Cycle; End() closes it.
  ir::Stmt& Cycle(const std::string& fixture) {
    ir::Stmt& stmt = Add("Cycle " + fixture, ir::Cycle{fixture, Column(7), {}, {}});
    auto& cycle = std::get<ir::Cycle>(stmt.node);
    open_.push_back({&cycle.body, &cycle.end, "EndCycle"});
    return stmt;
  }

  // Closes the innermost open block with its end line (Fend, EndIf, EndCycle;
  // Next closes a For).
  void End(const std::string& text = "") {
    SMTCAL_CHECK(!open_.empty(), "End without an open block");
    Open block = open_.back();
    open_.pop_back();
    if (!ifs_.empty() && block.end == &ifs_.back()->end) ifs_.pop_back();
    block.end->loc = NewLine(text.empty() ? block.end_text : text);
  }

  // Registers the text; the IR is complete.
  ir::Program& Finish() {
    SMTCAL_CHECK(open_.empty(), "unclosed block");
    std::uint32_t id = sources.Add("test.place", text_);
    SMTCAL_CHECK(id == kFile, "IrBuilder needs a fresh SourceManager");
    program.file = id;
    return program;
  }

  // The line number a statement was put on, for expectations.
  static std::uint32_t LineOf(const ir::Stmt& stmt) { return stmt.loc.line; }

  SourceManager sources;
  ir::Program program;

 private:
  struct Open {
    ir::Block* block;
    ir::BlockEnd* end;
    const char* end_text;  // Fend, Next, EndIf, EndCycle
  };

  SourceLoc NextLoc() const { return SourceLoc{kFile, line_ + 1, 1}; }
  SourceLoc Column(std::size_t column) const {
    return SourceLoc{kFile, line_ + 1, static_cast<std::uint32_t>(column)};
  }
  SourceLoc NewLine(const std::string& text) {
    text_ += text + "\n";
    return SourceLoc{kFile, ++line_, 1};
  }

  ir::ExprPtr Expr(decltype(ir::Expr::node) node) {
    auto expr = std::make_unique<ir::Expr>();
    expr->loc = NextLoc();
    expr->node = std::move(node);
    return expr;
  }
  ir::Coords Coords(std::array<double, 4> values) {
    ir::Coords coords;
    coords.values = values;
    coords.loc = NextLoc();
    return coords;
  }
  // Appends " In FRAME" to text and returns the frame's location.
  SourceLoc FrameLoc(std::string& text, const std::string& frame, const char* keyword) {
    if (frame.empty()) return {};
    text += keyword;
    SourceLoc loc = Column(text.size() + 1);
    text += frame;
    return loc;
  }
  static std::string TargetText(const ir::PointExpr& target) {
    if (const auto* named = std::get_if<ir::NamedPoint>(&target.base)) return named->name;
    if (std::holds_alternative<ir::PalletPoint>(target.base)) return "Pallet(...)";
    return "XY(...)";
  }

  ir::Stmt& PickPlace(ir::PickPlaceKind kind, ir::PointExpr target, ir::ExprPtr vacuum, ir::ExprPtr limz) {
    std::string text = fmt::format("{} {}{}{}", kind == ir::PickPlaceKind::Pick ? "Pick" : "Place",
                                   TargetText(target), vacuum ? " Vacuum ..." : "", limz ? " LimZ ..." : "");
    return Add(text, ir::PickPlace{kind, std::move(target), std::move(vacuum), std::move(limz)});
  }

  void Branch(const std::string& text, ir::ExprPtr condition) {
    SMTCAL_CHECK(!ifs_.empty() && !open_.empty(), "ElseIf/Else without If");
    ir::If& branch = *ifs_.back();
    SourceLoc loc = NewLine(text);
    branch.branches.push_back(ir::IfBranch{loc, std::move(condition), {}, {}});
    open_.back().block = &branch.branches.back().body;
  }

  template <typename Node>
  ir::Stmt& Add(const std::string& text, Node node) {
    auto stmt = std::make_unique<ir::Stmt>();
    stmt->loc = NewLine(text);
    std::size_t space = text.find(' ');
    stmt->length = static_cast<std::uint32_t>(space == std::string::npos ? text.size() : space);
    stmt->node = std::move(node);
    ir::Block& block = open_.empty() ? program.items : *open_.back().block;
    block.push_back(std::move(stmt));
    return *block.back();
  }

  std::string text_;
  std::uint32_t line_ = 0;
  std::vector<Open> open_;
  std::vector<ir::If*> ifs_;
  std::vector<ir::For*> fors_;
};

}  // namespace smtcal::test
