// Lowering a compiled program to RS274NGC (backend/linuxcnc/linuxcnc_emit.h,
// docs/linuxcnc.md).
//
// Every .place Function becomes an O-word subroutine `o<fn_NAME>` in the main
// file, defined before the program body calls `o<fn_main>`, so Main's and
// every function's variables are the interpreter's subroutine locals
// (#<v_NAME>) and `Exit Function` is a `return`. Globals are #<_v_NAME>,
// points #<_p_NAME_x|y|z|u> (in their root frame: the fixture's or the
// robot base's, Local frames folded in at compile time), temporaries
// #<t_...>. Control flow follows the compile-time run (passes/correction/target_trace.cpp)
// exactly: For bounds and step are evaluated once before the loop and the
// loop variable is set from a hidden counter at the top of each pass; `=`
// and `<>` compare exactly (rs274's EQ/NE have a tolerance); `Mod` is C's
// fmod. Every block ends with a comment naming its source line.
#include "backend/linuxcnc/linuxcnc_emit.h"

#include <stdio.h>  // renameat2
#include <fcntl.h>  // AT_FDCWD
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "backend/c/c_data.h"
#include "backend/linuxcnc/linuxcnc_data.h"
#include "backend/linuxcnc/linuxcnc_dry_run.h"
#include "backend/linuxcnc/linuxcnc_scan_abort.h"
#include "ir/constant_fold.h"
#include "ir/ir_text.h"
#include "ir/ir_walk.h"
#include "ir/symbols.h"
#include "passes/correction/target_trace.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

// The first line of every main program smtcal writes; an output directory
// whose .ngc files open with it is an earlier smtcal output.
constexpr std::string_view kHeaderMark = "(smtcal ";
constexpr int kFirstOWord = 100;
// rs274 refuses a line of 255 characters or more ("Command too long").
constexpr std::size_t kMaxLineChars = 254;
// Source text quoted in comments (target texts, names) is cut to this.
constexpr std::size_t kMaxQuotedChars = 60;
// A `Wait Sw(n) = On` waits in slices of this many seconds (M66 needs a
// timeout) until the input has the state: the language's Wait has none.
constexpr double kWaitSliceS = 3600;

// Comment text rs274 accepts: no parentheses (they would end the comment),
// no commas right after a word rs274 treats as a command (msg, debug, abort,
// ...): every comma becomes ';'. Printable ASCII only.
std::string Sanitize(std::string_view text) {
  std::string out;
  for (char c : text) {
    unsigned char u = static_cast<unsigned char>(c);
    if (c == '(') {
      out += '[';
    } else if (c == ')') {
      out += ']';
    } else if (c == ',') {
      out += ';';
    } else if (u < 0x20 || u >= 0x7f) {
      out += '?';
    } else {
      out += c;
    }
  }
  return out;
}

// Source text for a comment, cut so the line stays within kMaxLineChars.
std::string Quoted(std::string_view text) {
  if (text.size() <= kMaxQuotedChars) return std::string(text);
  return std::string(text.substr(0, kMaxQuotedChars - 3)) + "...";
}

std::string Lower(std::string_view name) { return sema::Lowercase(name); }

std::string Num(double value) { return LinuxCncNumber(value); }

// The expression text rs274 evaluates: a number, a parameter or [ ... ].
using GExpr = std::string;

class Emitter {
 public:
  Emitter(const ir::Program& program, const CompileState& state, std::string source_name, Diagnostics& diags)
      : program_(program),
        state_(state),
        cell_(*state.cell),
        symbols_(sema::SymbolTable::Build(program)),
        source_name_(std::move(source_name)),
        diags_(diags) {}

  std::optional<std::string> Run() {
    if (!cell_.linuxcnc) {
      diags_.Report(DiagKind::LinuxCncNoCellTable, SourceRange(SourceLoc{cell_.file, 1, 1}));
      return std::nullopt;
    }
    linuxcnc_ = &*cell_.linuxcnc;
    CheckProgram();
    if (diags_.has_errors()) return std::nullopt;
    ClassifyTargets();
    EmitHeader();
    EmitPoints();
    EmitGlobals();
    for (const ir::StmtPtr& item : program_.items) {
      if (const auto* function = std::get_if<ir::Function>(&item->node)) EmitFunction(*item, *function);
    }
    Line("o<fn_main> call", MainLoc());
    Line("M2", MainLoc());
    return out_;
  }

 private:
  // How a motion statement's target is commanded (from its CorrectionKind).
  enum class Command { kAsWritten, kRunTimeBase, kFixture };

  // ---------------------------------------------------------------- checks

  // What LinuxCNC cannot do, reported before anything is emitted.
  void CheckProgram() {
    ir::ForEachStmt(program_.items, [&](const ir::Stmt& stmt) {
      if (const auto* set = std::get_if<ir::SetOutput>(&stmt.node)) CheckBit(set->bit.get(), "output bit", "output");
      if (const auto* wait = std::get_if<ir::WaitSwitch>(&stmt.node)) CheckBit(wait->bit.get(), "input bit", "input");
      if (const auto* decl = std::get_if<ir::VacuumDecl>(&stmt.node)) {
        if (decl->output < 0 || decl->output >= cell::kLinuxCncMaxDio) {
          diags_.Report(DiagKind::LinuxCncIoBitOutOfRange, SourceRange(decl->output_loc), "vacuum output",
                        decl->output, "output", cell::kLinuxCncMaxDio - 1, "out");
        }
      }
      if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) {
        CheckBit(pick->vacuum.get(), "vacuum output", "output");
        CheckPoint(pick->target);
      }
      if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) CheckPoint(motion->target);
      ForEachExprOf(stmt, [&](const ir::Expr& expr) {
        if (const auto* sw = std::get_if<ir::SwitchRead>(&expr.node)) CheckBit(sw->bit.get(), "input bit", "input");
      });
    });
  }

  void CheckBit(const ir::Expr* bit, std::string_view what, std::string_view direction) {
    if (bit == nullptr) return;
    std::optional<int> value = sema::FoldInteger(bit);
    if (!value || (*value >= 0 && *value < cell::kLinuxCncMaxDio)) return;
    diags_.Report(DiagKind::LinuxCncIoBitOutOfRange, sema::ExprRange(*bit), what, *value, direction,
                  cell::kLinuxCncMaxDio - 1, direction == "input" ? "in" : "out");
  }

  void CheckPoint(const ir::PointExpr& point) {
    const auto* pallet = std::get_if<ir::PalletPoint>(&point.base);
    if (pallet == nullptr || sema::FoldInteger(pallet->number.get())) return;
    diags_.Report(DiagKind::LinuxCncPalletNumberNotConstant, sema::ExprRange(*pallet->number),
                  PrintPointText(point));
  }

  static std::string PrintPointText(const ir::PointExpr& point) { return PrintPointExpr(point); }

  // Every expression a statement holds directly (not those of nested blocks).
  template <typename Visit>
  static void ForEachExprOf(const ir::Stmt& stmt, Visit&& visit) {
    auto point = [&](const ir::PointExpr& p) {
      if (const auto* pallet = std::get_if<ir::PalletPoint>(&p.base)) {
        ir::ForEachExpr(pallet->number.get(), visit);
        ir::ForEachExpr(pallet->i.get(), visit);
        ir::ForEachExpr(pallet->j.get(), visit);
      }
      for (const ir::PointOffset& offset : p.offsets) ir::ForEachExpr(offset.amount.get(), visit);
    };
    if (const auto* assign = std::get_if<ir::Assign>(&stmt.node)) ir::ForEachExpr(assign->value.get(), visit);
    if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) {
      point(motion->target);
      ir::ForEachExpr(motion->limz.get(), visit);
    }
    if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) {
      point(pick->target);
      ir::ForEachExpr(pick->vacuum.get(), visit);
      ir::ForEachExpr(pick->limz.get(), visit);
    }
    if (const auto* set = std::get_if<ir::SetOutput>(&stmt.node)) ir::ForEachExpr(set->bit.get(), visit);
    if (const auto* wait = std::get_if<ir::WaitTime>(&stmt.node)) ir::ForEachExpr(wait->seconds.get(), visit);
    if (const auto* wait = std::get_if<ir::WaitSwitch>(&stmt.node)) ir::ForEachExpr(wait->bit.get(), visit);
    if (const auto* loop = std::get_if<ir::For>(&stmt.node)) {
      ir::ForEachExpr(loop->from.get(), visit);
      ir::ForEachExpr(loop->to.get(), visit);
      ir::ForEachExpr(loop->step.get(), visit);
    }
  }

  // ---------------------------------------------------------------- targets

  // Base-frame statements: commanded as written when every target the
  // compile-time run found is static (the IR already holds its nominal
  // XY(...)) or uncorrected; corrected on the controller otherwise.
  // Also remembers each statement's first target text and the program's
  // Vacuum default, so emitting stays linear in the program's size.
  void ClassifyTargets() {
    for (const Target& target : state_.targets) {
      bool as_written = target.kind == CorrectionKind::kStatic || target.kind == CorrectionKind::kUncorrected;
      auto [it, inserted] = as_written_.emplace(target.stmt, as_written);
      if (!inserted) it->second = it->second && as_written;
      target_text_.emplace(target.stmt, target.text);
    }
    for (const ir::StmtPtr& item : program_.items) {
      if (const auto* decl = std::get_if<ir::VacuumDecl>(&item->node)) default_vacuum_ = decl->output;
    }
  }

  // The cell's index of the fixture a point expression hangs on, or -1.
  int FixtureIndexOf(const ir::PointExpr& point) const {
    const sema::Symbol* fixture = nullptr;
    if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      if (const sema::Symbol* symbol = symbols_.Find(named->name)) fixture = symbols_.FixtureOfPoint(*symbol);
    } else if (const auto* pallet = std::get_if<ir::PalletPoint>(&point.base)) {
      if (std::optional<int> number = sema::FoldInteger(pallet->number.get())) {
        fixture = symbols_.FixtureOfPallet(*number);
      }
    }
    if (fixture == nullptr) return -1;
    return CellFixtureIndex(fixture->name);
  }

  int CellFixtureIndex(std::string_view name) const {
    const cell::Fixture* fixture = cell_.FindFixture(name);
    SMTCAL_CHECK(fixture != nullptr, "bind made sure every program fixture is in the cell");
    return static_cast<int>(fixture - cell_.fixtures.data());
  }

  Command CommandOf(const ir::Stmt& stmt, const ir::PointExpr& point) const {
    if (FixtureIndexOf(point) >= 0) return Command::kFixture;
    auto it = as_written_.find(&stmt);
    // A statement the compile-time run never reached is corrected on the
    // controller, like any base target smtcal could not compute.
    if (it == as_written_.end()) return Command::kRunTimeBase;
    return it->second ? Command::kAsWritten : Command::kRunTimeBase;
  }

  // ---------------------------------------------------------------- output

  SourceLoc MainLoc() const {
    const sema::Symbol* main = symbols_.Find("Main");
    return main != nullptr ? main->decl->loc : SourceLoc{};
  }

  std::string Where(SourceLoc loc) const { return fmt::format("{}:{}", Quoted(source_name_), loc.line); }

  // One block: indentation, the text, the source-line comment.
  void Line(std::string_view text, SourceLoc loc) {
    Emit(fmt::format("{}{} ({})", std::string(static_cast<std::size_t>(indent_) * 2, ' '), text,
                     Sanitize(Where(loc))), loc);
  }
  // A comment line is cut to fit: it only informs.
  void Comment(std::string_view text) {
    std::string indent(static_cast<std::size_t>(indent_) * 2, ' ');
    std::string body = Sanitize(text);
    std::size_t room = kMaxLineChars - indent.size() - 2;
    if (body.size() > room) body = body.substr(0, room - 3) + "...";
    Emit(fmt::format("{}({})", indent, body), SourceLoc{});
  }
  // A line rs274 cannot read is an error of the statement it came from
  // (once per statement), never output.
  void Emit(const std::string& line, SourceLoc loc) {
    if (line.size() > kMaxLineChars) {
      SMTCAL_CHECK(loc.known(), "only blocks from statements can grow long; comments are cut");
      if (too_long_.insert({loc.line, loc.column}).second) {
        diags_.Report(DiagKind::LinuxCncLineTooLong, SourceRange(loc), line.size(), kMaxLineChars);
      }
    }
    out_ += line;
    out_ += '\n';
  }
  void Comment(std::string_view text, SourceLoc loc) { Comment(fmt::format("{} {}", text, Where(loc))); }
  std::set<std::pair<std::uint32_t, std::uint32_t>> too_long_;  // statements reported
  void Abort(std::string_view message, SourceLoc loc) {
    // The abort's own text is the message; the location is inside it.
    Emit(fmt::format("{}(abort,smtcal: {} at {})", std::string(static_cast<std::size_t>(indent_) * 2, ' '),
                     Sanitize(message), Sanitize(Where(loc))),
         loc);
  }
  int NextOWord() { return next_oword_++; }
  // Temporaries live for one statement, so their names repeat; only the
  // inputs one statement reads are numbered.
  static std::string Temp(std::string_view what) { return fmt::format("#<t_{}>", what); }
  std::string SwitchTemp() { return fmt::format("#<t_sw{}>", next_switch_++); }

  void EmitHeader() {
    out_ += fmt::format("{}{})\n", kHeaderMark,
                        Sanitize(fmt::format("{}: {} for LinuxCNC and cell {}. Do not edit: compile the source again.",
                                             SMTCAL_VERSION, Quoted(source_name_), Quoted(cell_.name))));
    out_ += "(Needs the subroutines directory of this output on [RS274NGC]SUBROUTINE_PATH; docs/linuxcnc.md.)\n";
    out_ += fmt::format("(mm and degrees; u on the {} axis; vacuum sensor on motion.digital-in-{:02}.)\n",
                        linuxcnc_->rotation_axis, linuxcnc_->vacuum_sensor_input);
    SourceLoc loc = ProgramLoc();
    Line("G21 G90 G17 G94", loc);
    Line("o<smtcal_data> call", loc);
  }

  SourceLoc ProgramLoc() const {
    for (const ir::StmtPtr& item : program_.items) {
      if (std::holds_alternative<ir::ProgramDecl>(item->node)) return item->loc;
    }
    return SourceLoc{};
  }

  // Points: their coordinates in the root frame (a fixture's or the base's).
  void EmitPoints() {
    for (const ir::StmtPtr& item : program_.items) {
      const auto* decl = std::get_if<ir::PointDecl>(&item->node);
      if (decl == nullptr) continue;
      Pose4 root = RootOf(*decl).pose;
      std::string frame = RootOf(*decl).fixture.empty() ? "robot base" : "fixture " + RootOf(*decl).fixture;
      Comment(fmt::format("{}Point {} = XY[{}; {}; {}; {}]{}{} -> {} frame", decl->taught ? "Taught " : "",
                          Quoted(decl->name), Num(decl->coords.values[0]), Num(decl->coords.values[1]),
                          Num(decl->coords.values[2]), Num(decl->coords.values[3]),
                          decl->frame.empty() ? "" : decl->taught ? " On " : " In ", Quoted(decl->frame),
                          Quoted(frame)),
              item->loc);
      static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
      for (int a = 0; a < 4; ++a) {
        Line(fmt::format("{} = {}", PointParam(decl->name, kAxes[a]), Num(RoundForProgramText(root[a]))), item->loc);
      }
    }
  }

  RootedPose RootOf(const ir::PointDecl& decl) const {
    if (decl.taught && !decl.frame.empty()) return RootedPose{decl.frame, decl.coords.values};
    return ResolveFrame(symbols_, decl.frame, decl.coords.values);
  }

  static std::string PointParam(std::string_view name, char axis) {
    return fmt::format("#<_p_{}_{}>", Lower(name), axis);
  }

  void EmitGlobals() {
    for (const ir::StmtPtr& item : program_.items) {
      const auto* decl = std::get_if<ir::VarDecl>(&item->node);
      if (decl == nullptr) continue;
      for (const std::string& name : decl->names) Line(fmt::format("#<_v_{}> = 0", Lower(name)), item->loc);
    }
  }

  // ---------------------------------------------------------------- functions

  void EmitFunction(const ir::Stmt& stmt, const ir::Function& function) {
    function_ = Lower(function.name);
    locals_.clear();
    ir::ForEachStmt(function.body, [&](const ir::Stmt& s) {
      if (const auto* decl = std::get_if<ir::VarDecl>(&s.node)) {
        for (const std::string& name : decl->names) locals_.insert(Lower(name));
      }
    });
    Line(fmt::format("o<fn_{}> sub", function_), stmt.loc);
    ++indent_;
    // A local is visible from its declaration to Fend whatever block holds
    // it; start every one at 0 so a read never finds it undefined.
    for (const std::string& local : locals_) Line(fmt::format("#<v_{}> = 0", local), stmt.loc);
    EmitBlock(function.body);
    --indent_;
    Line(fmt::format("o<fn_{}> endsub", function_), function.end.loc.known() ? function.end.loc : stmt.loc);
  }

  void EmitBlock(const ir::Block& block) {
    for (const ir::StmtPtr& stmt : block) EmitStmt(*stmt);
  }

  void EmitStmt(const ir::Stmt& stmt) {
    std::visit(
        [&](const auto& node) {
          using Node = std::decay_t<decltype(node)>;
          if constexpr (std::is_same_v<Node, ir::VarDecl>) {
            for (const std::string& name : node.names) Line(fmt::format("{} = 0", Variable(name)), stmt.loc);
          } else if constexpr (std::is_same_v<Node, ir::Assign>) {
            ReadSwitches(stmt);
            Line(fmt::format("{} = {}", Variable(node.name), Expr(*node.value)), stmt.loc);
          } else if constexpr (std::is_same_v<Node, ir::Motion>) {
            EmitMotion(stmt, node);
          } else if constexpr (std::is_same_v<Node, ir::PickPlace>) {
            EmitPickPlace(stmt, node);
          } else if constexpr (std::is_same_v<Node, ir::SetOutput>) {
            ReadSwitches(stmt);
            Line(fmt::format("{} P{}", node.on ? "M64" : "M65", Expr(*node.bit)), stmt.loc);
          } else if constexpr (std::is_same_v<Node, ir::WaitTime>) {
            ReadSwitches(stmt);
            Line(fmt::format("G4 P{}", Expr(*node.seconds)), stmt.loc);
          } else if constexpr (std::is_same_v<Node, ir::WaitSwitch>) {
            EmitWaitSwitch(stmt, node);
          } else if constexpr (std::is_same_v<Node, ir::For>) {
            EmitFor(stmt, node);
          } else if constexpr (std::is_same_v<Node, ir::If>) {
            EmitIf(stmt, node);
          } else if constexpr (std::is_same_v<Node, ir::Call>) {
            Line(fmt::format("o<fn_{}> call", Lower(node.name)), stmt.loc);
          } else if constexpr (std::is_same_v<Node, ir::Cycle>) {
            Comment(fmt::format("Cycle {}", Quoted(node.fixture)), stmt.loc);
            EmitBlock(node.body);
            Comment(fmt::format("EndCycle {}", Quoted(node.fixture)), node.end.loc.known() ? node.end.loc : stmt.loc);
          } else if constexpr (std::is_same_v<Node, ir::Scan>) {
            Line(fmt::format("o<smtcal_scan> call [{}]", CellFixtureIndex(node.fixture)), stmt.loc);
          } else if constexpr (std::is_same_v<Node, ir::ExitFunction>) {
            Line(fmt::format("o<fn_{}> return", function_), stmt.loc);
          }
          // Comments, and declarations (only at the top level), emit nothing here.
        },
        stmt.node);
  }

  std::string Variable(std::string_view name) const {
    std::string key = Lower(name);
    return locals_.contains(key) ? fmt::format("#<v_{}>", key) : fmt::format("#<_v_{}>", key);
  }

  // ---------------------------------------------------------------- expressions

  // Sw(n) is read with M66 L0 into a temporary before the block that uses it.
  void ReadSwitches(const ir::Stmt& stmt) {
    ForEachExprOf(stmt, [&](const ir::Expr& expr) { ReadSwitch(expr, stmt.loc); });
  }
  void ReadSwitchesIn(const ir::Expr* expr, SourceLoc loc) {
    ir::ForEachExpr(expr, [&](const ir::Expr& e) { ReadSwitch(e, loc); });
  }
  void ReadSwitch(const ir::Expr& expr, SourceLoc loc) {
    const auto* sw = std::get_if<ir::SwitchRead>(&expr.node);
    if (sw == nullptr) return;
    std::string temp = SwitchTemp();
    Line(fmt::format("M66 P{} L0", Expr(*sw->bit)), loc);
    Line(fmt::format("{} = #5399", temp), loc);
    switches_[&expr] = temp;
  }

  GExpr Expr(const ir::Expr& expr) {
    // Constants as one number: `LimZ -1.0` is Z-1, not Z[0 - 1].
    if (std::optional<sema::Constant> constant = sema::FoldConstant(&expr)) return Num(constant->value);
    return std::visit(
        [&](const auto& node) -> GExpr {
          using Node = std::decay_t<decltype(node)>;
          if constexpr (std::is_same_v<Node, ir::NumberLit>) {
            return Num(node.value);
          } else if constexpr (std::is_same_v<Node, ir::VariableRef>) {
            return Variable(node.name);
          } else if constexpr (std::is_same_v<Node, ir::OnOffLit>) {
            return node.on ? "1" : "0";
          } else if constexpr (std::is_same_v<Node, ir::SwitchRead>) {
            auto it = switches_.find(&expr);
            SMTCAL_CHECK(it != switches_.end(), "every Sw() is read before the block that uses it");
            return it->second;
          } else if constexpr (std::is_same_v<Node, ir::UnaryExpr>) {
            GExpr operand = Expr(*node.operand);
            switch (node.op) {
              case ir::UnaryOp::Negate: return fmt::format("[0 - {}]", operand);
              case ir::UnaryOp::Plus: return operand;
              case ir::UnaryOp::Not: return fmt::format("[{} EQ 0]", operand);
            }
            return operand;
          } else {
            return Binary(node);
          }
        },
        expr.node);
  }

  GExpr Binary(const ir::BinaryExpr& node) {
    GExpr a = Expr(*node.lhs), b = Expr(*node.rhs);
    switch (node.op) {
      case ir::BinaryOp::Add: return fmt::format("[{} + {}]", a, b);
      case ir::BinaryOp::Sub: return fmt::format("[{} - {}]", a, b);
      case ir::BinaryOp::Mul: return fmt::format("[{} * {}]", a, b);
      case ir::BinaryOp::Div: return fmt::format("[{} / {}]", a, b);
      // fmod: the sign of the dividend (rs274's MOD is never negative).
      case ir::BinaryOp::Mod: return fmt::format("[[ABS[{0}] MOD ABS[{1}]] * [[[{0} GE 0] * 2] - 1]]", a, b);
      // Exact, as the compile-time run compares (rs274's EQ/NE allow 1e-4).
      case ir::BinaryOp::Eq: return fmt::format("[[{0} LE {1}] AND [{0} GE {1}]]", a, b);
      case ir::BinaryOp::Ne: return fmt::format("[[{0} LT {1}] OR [{0} GT {1}]]", a, b);
      case ir::BinaryOp::Lt: return fmt::format("[{} LT {}]", a, b);
      case ir::BinaryOp::Gt: return fmt::format("[{} GT {}]", a, b);
      case ir::BinaryOp::Le: return fmt::format("[{} LE {}]", a, b);
      case ir::BinaryOp::Ge: return fmt::format("[{} GE {}]", a, b);
      case ir::BinaryOp::And: return fmt::format("[{} AND {}]", a, b);
      case ir::BinaryOp::Or: return fmt::format("[{} OR {}]", a, b);
      case ir::BinaryOp::Xor: return fmt::format("[{} XOR {}]", a, b);
    }
    return a;
  }

  // ---------------------------------------------------------------- control

  void EmitWaitSwitch(const ir::Stmt& stmt, const ir::WaitSwitch& wait) {
    ReadSwitches(stmt);
    int o = NextOWord();
    Line(fmt::format("o{} do", o), stmt.loc);
    ++indent_;
    Line(fmt::format("M66 P{} L{} Q{}", Expr(*wait.bit), wait.on ? 3 : 4, Num(kWaitSliceS)), stmt.loc);
    --indent_;
    Line(fmt::format("o{} while [#5399 LT 0]", o), stmt.loc);
  }

  // for (v = from; step > 0 ? v <= to : v >= to; v += step) { var = v; body }
  void EmitFor(const ir::Stmt& stmt, const ir::For& loop) {
    ReadSwitches(stmt);
    int o = NextOWord();
    std::string v = fmt::format("#<t_for{}_v>", o), to = fmt::format("#<t_for{}_to>", o),
                step = fmt::format("#<t_for{}_step>", o);
    Line(fmt::format("{} = {}", v, Expr(*loop.from)), stmt.loc);
    Line(fmt::format("{} = {}", to, Expr(*loop.to)), stmt.loc);
    std::optional<sema::Constant> constant_step =
        loop.step ? sema::FoldConstant(loop.step.get()) : sema::Constant{1, true};
    std::string condition;
    if (constant_step && constant_step->value != 0) {
      condition = fmt::format("[{} {} {}]", v, constant_step->value > 0 ? "LE" : "GE", to);
      step = Num(constant_step->value);
    } else {
      Line(fmt::format("{} = {}", step, Expr(*loop.step)), stmt.loc);
      int check = NextOWord();
      Line(fmt::format("o{} if [{} EQ 0]", check, step), stmt.loc);
      ++indent_;
      Abort(fmt::format("the Step of For {} is 0", Quoted(loop.var)), stmt.loc);
      --indent_;
      Line(fmt::format("o{} endif", check), stmt.loc);
      condition = fmt::format("[[[{1} GT 0] AND [{0} LE {2}]] OR [[{1} LT 0] AND [{0} GE {2}]]]", v, step, to);
    }
    Line(fmt::format("o{} while {}", o, condition), stmt.loc);
    ++indent_;
    Line(fmt::format("{} = {}", Variable(loop.var), v), stmt.loc);
    EmitBlock(loop.body);
    SourceLoc next = loop.end.loc.known() ? loop.end.loc : stmt.loc;
    Line(fmt::format("{} = [{} + {}]", v, v, step), next);
    --indent_;
    Line(fmt::format("o{} endwhile", o), next);
  }

  // If/ElseIf/Else as o-if/elseif/else. An ElseIf whose condition reads an
  // input opens a nested If in the Else, so the input is read when the
  // condition is evaluated, as in the language.
  void EmitIf(const ir::Stmt& stmt, const ir::If& branch) {
    EmitBranches(stmt, branch, 0);
  }

  static bool ReadsSwitch(const ir::Expr* expr) {
    bool found = false;
    ir::ForEachExpr(expr, [&](const ir::Expr& e) { found = found || std::holds_alternative<ir::SwitchRead>(e.node); });
    return found;
  }

  void EmitBranches(const ir::Stmt& stmt, const ir::If& branch, std::size_t first) {
    const std::vector<ir::IfBranch>& branches = branch.branches;
    SourceLoc end = branch.end.loc.known() ? branch.end.loc : stmt.loc;
    int o = NextOWord();
    ReadSwitchesIn(branches[first].condition.get(), branches[first].loc);
    Line(fmt::format("o{} if {}", o, Condition(*branches[first].condition)), branches[first].loc);
    ++indent_;
    EmitBlock(branches[first].body);
    --indent_;
    for (std::size_t b = first + 1; b < branches.size(); ++b) {
      const ir::IfBranch& next = branches[b];
      if (next.condition == nullptr) {
        Line(fmt::format("o{} else", o), next.loc);
        ++indent_;
        EmitBlock(next.body);
        --indent_;
        break;
      }
      if (ReadsSwitch(next.condition.get())) {
        Line(fmt::format("o{} else", o), next.loc);
        ++indent_;
        EmitBranches(stmt, branch, b);
        --indent_;
        break;
      }
      Line(fmt::format("o{} elseif {}", o, Condition(*next.condition)), next.loc);
      ++indent_;
      EmitBlock(next.body);
      --indent_;
    }
    Line(fmt::format("o{} endif", o), end);
  }

  // rs274 wants a bracketed condition after if/elseif/while.
  GExpr Condition(const ir::Expr& expr) {
    GExpr text = Expr(expr);
    return text.starts_with('[') ? text : fmt::format("[{}]", text);
  }

  // ---------------------------------------------------------------- motion

  // A target's position in its root frame, as four expressions.
  struct Position {
    std::array<GExpr, 4> xyzu;
  };

  // Literal XY(...) targets are used as they are; everything else is
  // computed into temporaries: the point (or pallet slot) in its root
  // frame, plus the offsets turned by the point's Local frames.
  Position PositionOf(const ir::PointExpr& point, SourceLoc loc) {
    Position position;
    std::string frame;
    if (const auto* coords = std::get_if<ir::Coords>(&point.base)) {
      for (int a = 0; a < 4; ++a) position.xyzu[a] = Num(coords->values[a]);
    } else if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
      for (int a = 0; a < 4; ++a) position.xyzu[a] = PointParam(named->name, kAxes[a]);
      const sema::Symbol* symbol = symbols_.Find(named->name);
      SMTCAL_CHECK(symbol != nullptr && symbol->kind == sema::SymbolKind::Point, "a checked target names a point");
      const auto& decl = std::get<ir::PointDecl>(symbol->decl->node);
      if (!decl.taught) frame = decl.frame;
    } else {
      position = PalletSlot(std::get<ir::PalletPoint>(point.base), loc, frame);
    }
    if (point.offsets.empty()) return position;
    // Offsets are along the axes of the frame the point is given in.
    double angle = Radians(ResolveFrame(symbols_, frame, Pose4{}).pose[3]);
    double c = RoundForProgramText(std::cos(angle)), s = RoundForProgramText(std::sin(angle));
    std::array<std::string, 4> temps;
    for (int a = 0; a < 4; ++a) {
      temps[a] = Temp(std::array<const char*, 4>{"x", "y", "z", "u"}[a]);
      if (position.xyzu[a] != temps[a]) Line(fmt::format("{} = {}", temps[a], position.xyzu[a]), loc);
    }
    for (const ir::PointOffset& offset : point.offsets) {
      GExpr amount = Expr(*offset.amount);
      const char* sign = offset.negative ? "-" : "+";
      auto add = [&](int axis, double factor) {
        if (factor == 0) return;
        GExpr term = factor == 1 ? amount : fmt::format("[{} * {}]", Num(factor), amount);
        Line(fmt::format("{0} = [{0} {1} {2}]", temps[axis], sign, term), offset.loc);
      };
      switch (offset.axis) {
        case ir::Axis::X: add(0, c); add(1, s); break;
        case ir::Axis::Y: add(0, -s); add(1, c); break;
        case ir::Axis::Z: add(2, 1); break;
        case ir::Axis::U: add(3, 1); break;
      }
    }
    for (int a = 0; a < 4; ++a) position.xyzu[a] = temps[a];
    return position;
  }

  // Pallet(n, i, j) / Pallet(n, k) as the language defines it, in the
  // corners' root frame (linear interpolation commutes with the frames).
  Position PalletSlot(const ir::PalletPoint& pallet, SourceLoc loc, std::string& frame) {
    std::optional<int> number = sema::FoldInteger(pallet.number.get());
    SMTCAL_CHECK(number.has_value(), "CheckProgram refused run-time pallet numbers");
    const sema::SymbolTable::PalletEntry* entry = symbols_.FindPallet(*number);
    SMTCAL_CHECK(entry != nullptr, "a checked program uses declared pallets");
    const ir::PalletDecl& decl = *entry->pallet;
    const sema::Symbol* first = symbols_.Find(decl.corners[0]);
    const auto& corner = std::get<ir::PointDecl>(first->decl->node);
    if (!corner.taught) frame = corner.frame;
    GExpr column, row = "1";
    if (pallet.j) {
      column = Expr(*pallet.i);
      row = Expr(*pallet.j);
    } else {  // k counts along the first row, then the next
      std::string k = Temp("k");
      Line(fmt::format("{} = [{} - 1]", k, Expr(*pallet.i)), loc);
      column = fmt::format("[[[ABS[{0}] MOD {1}] * [[[{0} GE 0] * 2] - 1]] + 1]", k, decl.columns);
      row = fmt::format("[FIX[{} / {}] + 1]", k, decl.columns);
    }
    std::string s = Temp("s"), t = Temp("t");
    Line(fmt::format("{} = {}", s, decl.columns > 1 ? fmt::format("[[{} - 1] / {}]", column, decl.columns - 1)
                                                     : std::string("0")), loc);
    Line(fmt::format("{} = {}", t, decl.rows > 1 ? fmt::format("[[{} - 1] / {}]", row, decl.rows - 1)
                                                  : std::string("0")), loc);
    Position position;
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    for (int a = 0; a < 4; ++a) {
      std::string p1 = PointParam(decl.corners[0], kAxes[a]), p2 = PointParam(decl.corners[1], kAxes[a]),
                  p3 = PointParam(decl.corners[2], kAxes[a]);
      std::string temp = Temp(std::string(1, kAxes[a]));
      Line(fmt::format("{} = [{} + [{} * [{} - {}]] + [{} * [{} - {}]]]", temp, p1, s, p2, p1, t, p3, p1), loc);
      position.xyzu[a] = temp;
    }
    return position;
  }

  // Where the robot is commanded: the position itself, or the runtime's
  // correction of it (then x, y, and for a fixture the added angle, come
  // from the runtime's globals).
  Position Commanded(const ir::Stmt& stmt, const ir::PointExpr& point) {
    Command command = CommandOf(stmt, point);
    Position position = PositionOf(point, stmt.loc);
    if (command == Command::kAsWritten) return position;
    int fixture = command == Command::kFixture ? FixtureIndexOf(point) : -1;
    Line(fmt::format("o<smtcal_correct> call [{}] [{}] [{}]", fixture, position.xyzu[0], position.xyzu[1]), stmt.loc);
    position.xyzu[0] = "#<_smtcal_x>";
    position.xyzu[1] = "#<_smtcal_y>";
    if (command == Command::kFixture) position.xyzu[3] = fmt::format("[{} + #<_smtcal_angle>]", position.xyzu[3]);
    return position;
  }

  std::string Axes(const Position& p, bool with_z) const {
    std::string text = fmt::format("X{} Y{}", p.xyzu[0], p.xyzu[1]);
    if (with_z) text += fmt::format(" Z{}", p.xyzu[2]);
    return text + fmt::format(" {}{}", linuxcnc_->rotation_axis, p.xyzu[3]);
  }

  void EmitJump(const ir::Stmt& stmt, const Position& target, const ir::Expr* limz) {
    GExpr z = limz != nullptr ? Expr(*limz) : Num(cell_.robot.safe_limz_mm);
    Line(fmt::format("G0 Z{}", z), stmt.loc);
    Line(fmt::format("G0 {}", Axes(target, false)), stmt.loc);
    Line(fmt::format("G0 Z{}", target.xyzu[2]), stmt.loc);
  }

  void EmitMotion(const ir::Stmt& stmt, const ir::Motion& motion) {
    ReadSwitches(stmt);
    Position target = Commanded(stmt, motion.target);
    switch (motion.kind) {
      case ir::MotionKind::Jump: EmitJump(stmt, target, motion.limz.get()); break;
      case ir::MotionKind::Go: Line(fmt::format("G0 {}", Axes(target, true)), stmt.loc); break;
      case ir::MotionKind::Move:
        Line(fmt::format("G1 {} F{}", Axes(target, true), Num(cell_.robot.xy_speed_mm_s * 60)), stmt.loc);
        break;
    }
  }

  // Jump there, switch the vacuum, and wait for the sensor to agree; a
  // timeout aborts naming the statement.
  void EmitPickPlace(const ir::Stmt& stmt, const ir::PickPlace& pick) {
    ReadSwitches(stmt);
    Position target = Commanded(stmt, pick.target);
    EmitJump(stmt, target, pick.limz.get());
    bool picking = pick.kind == ir::PickPlaceKind::Pick;
    GExpr vacuum = pick.vacuum ? Expr(*pick.vacuum) : Num(DefaultVacuum());
    Line(fmt::format("{} P{}", picking ? "M64" : "M65", vacuum), stmt.loc);
    Line(fmt::format("M66 P{} L{} Q{}", linuxcnc_->vacuum_sensor_input, picking ? 3 : 4,
                     Num(linuxcnc_->vacuum_timeout_s)), stmt.loc);
    int o = NextOWord();
    Line(fmt::format("o{} if [#5399 LT 0]", o), stmt.loc);
    ++indent_;
    Abort(fmt::format("{} of {}: vacuum sensor input {} did not report {} within {} s", picking ? "Pick" : "Place",
                      Quoted(TargetText(stmt, pick.target)), linuxcnc_->vacuum_sensor_input,
                      picking ? "the part held" : "the part released", Num(linuxcnc_->vacuum_timeout_s)),
          stmt.loc);
    --indent_;
    Line(fmt::format("o{} endif", o), stmt.loc);
  }

  // The target as the source wrote it (static targets' IR holds the nominal XY).
  std::string TargetText(const ir::Stmt& stmt, const ir::PointExpr& point) const {
    auto it = target_text_.find(&stmt);
    return it != target_text_.end() ? it->second : PrintPointText(point);
  }

  double DefaultVacuum() const {
    SMTCAL_CHECK(default_vacuum_.has_value(), "a checked Pick/Place without Vacuum has the program's Vacuum");
    return *default_vacuum_;
  }

  const ir::Program& program_;
  const CompileState& state_;
  const cell::Cell& cell_;
  const cell::LinuxCnc* linuxcnc_ = nullptr;
  sema::SymbolTable symbols_;
  std::string source_name_;
  Diagnostics& diags_;
  std::map<const ir::Stmt*, bool> as_written_;
  std::map<const ir::Stmt*, std::string> target_text_;  // the first target's text
  std::optional<int> default_vacuum_;                   // the program's `Vacuum n`
  std::map<const ir::Expr*, std::string> switches_;
  std::set<std::string> locals_;  // the current function's, lowercase
  std::string function_;          // the current function, lowercase
  std::string out_;
  int indent_ = 0;
  int next_oword_ = kFirstOWord;
  int next_switch_ = 1;
};

// ------------------------------------------------------------------ the directory

std::string FirstLine(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::getline(in, line);
  return line;
}

// Why `dir` is not an earlier smtcal output, or "" when it is.
std::string NotOurOutput(const fs::path& dir) {
  if (!fs::is_directory(dir)) return fmt::format("'{}' exists and is not a directory", dir.string());
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    const fs::path& path = entry.path();
    if (entry.is_directory() && (path.filename() == "subroutines" || path.filename() == kLinuxCncDryRunFolder)) {
      for (const fs::directory_entry& sub : fs::directory_iterator(path)) {
        std::string name = sub.path().filename().string();
        if (!sub.is_regular_file() || !name.starts_with("smtcal_") || sub.path().extension() != ".ngc") {
          return fmt::format("'{}' holds '{}', which smtcal did not write", path.string(), name);
        }
      }
      continue;
    }
    if (entry.is_regular_file() && path.extension() == ".ngc" && FirstLine(path).starts_with(kHeaderMark)) continue;
    return fmt::format("'{}' holds '{}', which smtcal did not write", dir.string(), path.filename().string());
  }
  return "";
}

Status WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.flush();
  if (!out) return Error{fmt::format("cannot write '{}': {}", path.string(), std::strerror(errno))};
  return Ok{};
}

Status WriteTree(const fs::path& dir, const LinuxCncOutput& output) {
  std::error_code error;
  fs::create_directories(dir / "subroutines", error);
  if (error) return Error{fmt::format("cannot create '{}': {}", dir.string(), error.message())};
  if (Status written = WriteText(dir / output.main_name, output.main_text); !written) return written;
  for (const EmbeddedFile& file : output.subroutines) {
    if (Status written = WriteText(dir / "subroutines" / file.name, file.text); !written) return written;
  }
  if (!output.dry_run.empty()) fs::create_directories(dir / kLinuxCncDryRunFolder, error);
  for (const EmbeddedFile& file : output.dry_run) {
    if (Status written = WriteText(dir / kLinuxCncDryRunFolder / file.name, file.text); !written) return written;
  }
  return Ok{};
}

}  // namespace

std::string LinuxCncMainName(const std::string& program_path) {
  if (program_path == "-") return "program.ngc";
  std::string stem = fs::path(program_path).stem().string();
  std::string name;
  for (char c : stem) name += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' ? c : '_';
  return (name.empty() ? std::string("program") : name) + ".ngc";
}

std::optional<LinuxCncOutput> EmitLinuxCnc(const ir::Program& program, const CompileState& state,
                                           const std::string& program_path, Diagnostics& diags) {
  SMTCAL_CHECK(state.cell != nullptr, "the linuxcnc target needs a compiled program");
  const cell::Cell& cell = *state.cell;
  if (std::optional<std::string> problem = LinuxCncDataProblem(cell)) {
    // At the fixture whose scan is too long when one is, else at the cell.
    SourceRange where(SourceLoc{cell.file, 1, 1});
    for (const cell::Fixture& fixture : cell.fixtures) {
      if (!FitsCRuntime(fixture)) {
        where = fixture.name_range;
        break;
      }
    }
    diags.Report(DiagKind::LinuxCncDataDoesNotFit, where, *problem);
    return std::nullopt;
  }
  std::string source_name = program_path == "-" ? "stdin" : fs::path(program_path).filename().string();
  std::optional<std::string> main = Emitter(program, state, source_name, diags).Run();
  if (!main) return std::nullopt;
  LinuxCncOutput output;
  output.main_name = LinuxCncMainName(program_path);
  output.main_text = std::move(*main);
  output.subroutines = LinuxCncRuntimeFiles();
  output.subroutines.push_back({"smtcal_data.ngc", EmitLinuxCncData(cell)});
  output.subroutines.push_back({"smtcal_scan_abort.ngc", EmitLinuxCncScanAbort(cell)});
  std::sort(output.subroutines.begin(), output.subroutines.end(),
            [](const EmbeddedFile& a, const EmbeddedFile& b) { return a.name < b.name; });
  return output;
}

std::string LinuxCncReviewText(const LinuxCncOutput& output) {
  std::string text = fmt::format("(smtcal file: {})\n{}", output.main_name, output.main_text);
  for (const EmbeddedFile& file : output.subroutines) {
    if (file.name == "smtcal_data.ngc" || file.name == "smtcal_scan_abort.ngc") {
      text += fmt::format("(smtcal file: subroutines/{})\n{}", file.name, file.text);
    }
  }
  for (const EmbeddedFile& file : output.dry_run) {
    text += fmt::format("(smtcal file: {}/{})\n{}", kLinuxCncDryRunFolder, file.name, file.text);
  }
  return text;
}

Status WriteLinuxCncDirectory(const fs::path& outdir, const LinuxCncOutput& output) {
  fs::path target = outdir.has_filename() ? outdir : outdir.parent_path();
  std::error_code error;
  bool exists = fs::exists(fs::symlink_status(target, error));
  if (exists) {
    if (std::string why = NotOurOutput(target); !why.empty()) {
      return Error{fmt::format("will not replace '{}': {}; choose another -o directory or remove it",
                               target.string(), why)};
    }
  }
  fs::path temp = target;
  temp += fmt::format(".tmp.{}", ::getpid());
  fs::remove_all(temp, error);
  if (Status written = WriteTree(temp, output); !written) {
    fs::remove_all(temp, error);
    return written;
  }
  if (!exists) {
    if (std::rename(temp.c_str(), target.c_str()) != 0) {
      int saved = errno;
      fs::remove_all(temp, error);
      return Error{fmt::format("cannot write '{}': {}", target.string(), std::strerror(saved))};
    }
    return Ok{};
  }
  // Swap the finished directory in atomically; the old one leaves under the
  // temporary's name and is removed.
  if (::renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) != 0) {
    int saved = errno;
    fs::remove_all(temp, error);
    return Error{fmt::format("cannot replace '{}': {}", target.string(), std::strerror(saved))};
  }
  fs::remove_all(temp, error);
  return Ok{};
}

}  // namespace smtcal
