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
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include <fmt/format.h>

#include "backend/c/c_data.h"
#include "backend/linuxcnc/linuxcnc_data.h"
#include "backend/linuxcnc/linuxcnc_dry_run.h"
#include "backend/linuxcnc/linuxcnc_record.h"
#include "backend/linuxcnc/linuxcnc_scan_abort.h"
#include "ir/constant_fold.h"
#include "ir/ir_ops.h"
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
// o<pick_place>'s first argument besides a fixture's index (linuxcnc_layout.h).
constexpr int kPickPlaceBase = linuxcnc_layout::kCommandBase;
constexpr int kPickPlaceAsWritten = linuxcnc_layout::kCommandAsWritten;

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

// Text for an (abort, ...) message: a comment's text in which rs274 would
// substitute nothing (it substitutes parameters, #..., with formats, %...).
std::string SanitizeMessage(std::string_view text) {
  std::string out = Sanitize(text);
  std::replace_if(out.begin(), out.end(), [](char c) { return c == '#' || c == '%'; }, '?');
  return out;
}

// Source text for a comment, cut so the line stays within kMaxLineChars.
std::string Quoted(std::string_view text) {
  if (text.size() <= kMaxQuotedChars) return std::string(text);
  return std::string(text.substr(0, kMaxQuotedChars - 3)) + "...";
}
void AppendQuoted(std::string& out, std::string_view text) {
  if (text.size() <= kMaxQuotedChars) {
    out += text;
  } else {
    out += text.substr(0, kMaxQuotedChars - 3);
    out += "...";
  }
}

std::string Lower(std::string_view name) { return sema::Lowercase(name); }

std::string Num(double value) { return LinuxCncNumber(value); }

// The expression text rs274 evaluates: a number, a parameter or [ ... ].
using GExpr = std::string;

class Emitter {
 public:
  Emitter(const ir::Program& program, const CompileState& state, std::string source_name, TextOutput& out,
          Diagnostics& diags)
      : program_(program),
        state_(state),
        cell_(*state.cell),
        symbols_(sema::SymbolsOf(program)),
        source_name_(std::move(source_name)),
        diags_(diags),
        out_(out) {}

  // False when the program cannot be lowered (reported); the text is then
  // incomplete.
  bool Run() {
    if (!cell_.linuxcnc) {
      diags_.Report(DiagKind::LinuxCncNoCellTable, SourceRange(SourceLoc{cell_.file, 1, 1}));
      return false;
    }
    linuxcnc_ = &*cell_.linuxcnc;
    CheckProgram();
    if (diags_.has_errors()) return false;
    ClassifyTargets();
    EmitHeader();
    EmitPoints();
    EmitGlobals();
    EmitPickPlaceSubroutine();
    for (const ir::StmtPtr& item : program_.items) {
      if (const auto* function = std::get_if<ir::Function>(&item->node)) EmitFunction(*item, *function);
    }
    Line("o<fn_main> call", MainLoc());
    Line("M2", MainLoc());
    return true;
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
        } else {
          io_.push_back({true, decl->output, "vacuum output", SourceRange(decl->output_loc)});
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
    if (value && *value >= 0 && *value < cell::kLinuxCncMaxDio) {
      io_.push_back({direction == "output", *value, std::string(what), sema::ExprRange(*bit)});
    }
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
  // Also remembers the program's Vacuum default, so emitting stays linear in
  // the program's size.
  void ClassifyTargets() {
    for (const Target& target : state_.targets) {
      // A statement whose point is in a fixture is commanded through it
      // (CommandOf answers before it asks this map).
      const ir::PointExpr* point = ir::MotionTarget(*target.stmt);
      if (point != nullptr && FixtureIndexOf(*point) >= 0) continue;
      bool as_written = target.kind == CorrectionKind::kStatic || target.kind == CorrectionKind::kUncorrected;
      auto [it, inserted] = as_written_.emplace(target.stmt, as_written);
      if (!inserted) it->second = it->second && as_written;
    }
    for (const ir::StmtPtr& item : program_.items) {
      if (const auto* decl = std::get_if<ir::VacuumDecl>(&item->node)) default_vacuum_ = decl->output;
    }
  }

  // The cell's index of the fixture a point expression hangs on, or -1.
  int FixtureIndexOf(const ir::PointExpr& point) {
    const sema::Symbol* fixture = nullptr;
    if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      if (const sema::Symbol* symbol = symbols_.Find(*named)) fixture = symbols_.FixtureOfPoint(*symbol);
    } else if (const auto* pallet = std::get_if<ir::PalletPoint>(&point.base)) {
      if (std::optional<int> number = sema::FoldInteger(pallet->number.get())) {
        fixture = symbols_.FixtureOfPallet(*number);
      }
    }
    if (fixture == nullptr) return -1;
    auto [it, inserted] = cell_fixture_of_.emplace(fixture, 0);
    if (inserted) it->second = CellFixtureIndex(fixture->name);
    return it->second;
  }

  int CellFixtureIndex(std::string_view name) const {
    const cell::Fixture* fixture = cell_.FindFixture(name);
    SMTCAL_CHECK(fixture != nullptr, "bind made sure every program fixture is in the cell");
    return static_cast<int>(fixture - cell_.fixtures.data());
  }

  Command CommandOf(const ir::Stmt& stmt, const ir::PointExpr& point, int* fixture = nullptr) {
    int index = FixtureIndexOf(point);
    if (fixture != nullptr) *fixture = index;
    if (index >= 0) return Command::kFixture;
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
    std::string& out = Begin();
    const std::size_t begin = out.size();
    out += text;
    out += Suffix(loc);
    Ended(begin, loc);
  }
  // " (layers.place:57)\n", the end of every block of source line 57: made
  // once per source line, as a statement's blocks come one after another.
  const std::string& Suffix(SourceLoc loc) {
    if (!suffix_made_ || loc.line != suffix_line_) {
      suffix_.assign(" (");
      AppendWhere(suffix_, loc);
      suffix_ += ")\n";
      suffix_line_ = loc.line;
      suffix_made_ = true;
    }
    return suffix_;
  }
  // "layers.place:57", as Sanitize(Where(loc)) gives it (a line number
  // needs no sanitizing).
  void AppendWhere(std::string& out, SourceLoc loc) {
    if (source_where_.empty()) source_where_ = Sanitize(Quoted(source_name_)) + ":";
    out += source_where_;
    char digits[16];
    out.append(digits, std::to_chars(digits, digits + sizeof digits, loc.line).ptr);
  }
  // The output with the indentation of a new line appended.
  std::string& Begin() {
    std::string& out = out_.buffer();
    out.append(static_cast<std::size_t>(indent_) * 2, ' ');
    return out;
  }
  // The line that started at `begin` is complete (with its newline). One
  // rs274 cannot read is an error of the statement it came from (once per
  // statement), never output.
  void Ended(std::size_t begin, SourceLoc loc) {
    const std::size_t length = out_.buffer().size() - begin - 1 + static_cast<std::size_t>(indent_) * 2;
    if (length > kMaxLineChars) {
      SMTCAL_CHECK(loc.known(), "only blocks from statements can grow long; comments are cut");
      if (too_long_.insert({loc.line, loc.column}).second) {
        diags_.Report(DiagKind::LinuxCncLineTooLong, SourceRange(loc), length, kMaxLineChars);
      }
    }
    out_.Produced();
  }
  // A comment line is cut to fit: it only informs.
  void Comment(std::string_view text) {
    std::string body = Sanitize(text);
    std::size_t room = kMaxLineChars - static_cast<std::size_t>(indent_) * 2 - 2;
    if (body.size() > room) body = body.substr(0, room - 3) + "...";
    std::string& out = Begin();
    out += '(';
    out += body;
    out += ")\n";
    out_.Produced();
  }
  void Comment(std::string_view text, SourceLoc loc) { Comment(fmt::format("{} {}", text, Where(loc))); }
  std::set<std::pair<std::uint32_t, std::uint32_t>> too_long_;  // statements reported
  void Abort(std::string_view message, SourceLoc loc) {
    // The abort's own text is the message; the location is inside it.
    std::string& out = Begin();
    const std::size_t begin = out.size();
    fmt::format_to(std::back_inserter(out), "(abort,smtcal: {} at {})\n", SanitizeMessage(message),
                   SanitizeMessage(Where(loc)));
    Ended(begin, loc);
  }
  int NextOWord() { return next_oword_++; }
  // Temporaries live for one statement, so their names repeat; only the
  // inputs one statement reads are numbered.
  static std::string Temp(std::string_view what) { return fmt::format("#<t_{}>", what); }
  std::string SwitchTemp() { return fmt::format("#<t_sw{}>", next_switch_++); }

  void EmitHeader() {
    out_.Append(fmt::format("{}{})\n", kHeaderMark,
                            Sanitize(fmt::format("{}: {} for LinuxCNC and cell {}. Do not edit: compile the source again.",
                                                 SMTCAL_VERSION, Quoted(source_name_), Quoted(cell_.name)))));
    out_.Append("(Needs smtcal's runtime for this cell on [RS274NGC]SUBROUTINE_PATH; docs/linuxcnc.md.)\n");
    out_.Append(fmt::format("(mm and degrees; u on the {} axis; vacuum sensor on motion.digital-in-{:02}.)\n",
                            linuxcnc_->rotation_axis, linuxcnc_->vacuum_sensor_input));
    SourceLoc loc = ProgramLoc();
    // G61, exact path: every move ends where it is commanded before the next
    // starts, as the cycle-time model assumes (and a Jump must: a blended
    // corner cuts towards the part); LinuxCNC also gives a blended move only
    // half the axes' acceleration.
    Line("G21 G90 G17 G94 G61", loc);
    Line("o<smtcal_data> call", loc);
    // The runtime the path finds must be the one compiled with this program:
    // the same cell data and the same smtcal (LinuxCncRuntimeId).
    const std::string id = fmt::format("{}", LinuxCncRuntimeId(cell_));
    const std::string message =
        "the runtime on SUBROUTINE_PATH is not the one this program was compiled with [another cell or its "
        "tables; or another smtcal]: compile it again with --ini";
    const int known = NextOWord(), same = NextOWord();
    Line(fmt::format("o{} if [EXISTS[{}] EQ 0]", known, linuxcnc_layout::kRuntimeIdParameter), loc);
    Abort(message, loc);
    Line(fmt::format("o{} endif", known), loc);
    Line(fmt::format("o{} if [{} NE {}]", same, linuxcnc_layout::kRuntimeIdParameter, id), loc);
    Abort(message, loc);
    Line(fmt::format("o{} endif", same), loc);
  }

  SourceLoc ProgramLoc() const {
    for (const ir::StmtPtr& item : program_.items) {
      if (std::holds_alternative<ir::ProgramDecl>(item->node)) return item->loc;
    }
    return SourceLoc{};
  }

  // Points: their coordinates in the root frame (a fixture's or the base's),
  // the four parameters on one line with the declaration in its comment; a
  // line too long for rs274 (long names) is split into one line per axis.
  void EmitPoints() {
    static constexpr std::array<char, 4> kAxes = {'x', 'y', 'z', 'u'};
    for (const ir::StmtPtr& item : program_.items) {
      const auto* decl = std::get_if<ir::PointDecl>(&item->node);
      if (decl == nullptr) continue;
      const RootedPose rooted = RootOf(*decl);
      const std::string name = Lower(decl->name);
      std::string& out = out_.buffer();
      const std::size_t begin = out.size();
      for (int a = 0; a < 4; ++a) {
        out += a > 0 ? " #<_p_" : "#<_p_";
        out += name;
        out += '_';
        out += kAxes[a];
        out += "> = ";
        AppendLinuxCncNumber(out, RoundForProgramText(rooted.pose[a]));
      }
      out += " (";
      AppendWhere(out, item->loc);
      out += ' ';
      AppendPointComment(out, *decl, rooted);
      out += ")\n";
      if (out.size() - begin - 1 <= kMaxLineChars) {
        out_.Produced();
        continue;
      }
      out.resize(begin);  // too long for rs274 (long names): one line per axis
      std::string what;
      AppendPointComment(what, *decl, rooted);
      Comment(what, item->loc);
      for (int a = 0; a < 4; ++a) {
        Line(fmt::format("#<_p_{}_{}> = {}", name, kAxes[a], Num(RoundForProgramText(rooted.pose[a]))), item->loc);
      }
    }
  }

  // "Point P In Layer1 -> fixture Board frame": the declaration and where its
  // parameters are. Names are identifiers: nothing in them needs sanitizing.
  static void AppendPointComment(std::string& out, const ir::PointDecl& decl, const RootedPose& rooted) {
    out += decl.taught ? "Taught Point " : "Point ";
    AppendQuoted(out, decl.name);
    if (!decl.frame.empty()) {
      out += decl.taught ? " On " : " In ";
      AppendQuoted(out, decl.frame);
    }
    if (rooted.fixture.empty()) {
      out += " -> robot base frame";
    } else {
      out += " -> fixture ";
      AppendQuoted(out, rooted.fixture);
      out += " frame";
    }
  }

  RootedPose RootOf(const ir::PointDecl& decl) const {
    if (decl.taught && !decl.frame.empty()) return RootedPose{decl.frame, decl.coords.values};
    return ResolveFrame(symbols_, decl.frame, decl.coords.values);
  }

  static std::string PointParam(std::string_view name, char axis) {
    return fmt::format("#<_p_{}_{}>", Lower(name), axis);
  }
  // The four parameters of a point: #<_p_NAME_x>, ..._y>, ..._z>, ..._u>.
  static std::array<std::string, 4> PointParams(std::string_view name) {
    std::string prefix = "#<_p_" + Lower(name) + "_";
    return {prefix + "x>", prefix + "y>", prefix + "z>", prefix + "u>"};
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
      position.xyzu = PointParams(named->name);
      if (!point.offsets.empty()) {  // the frame is needed for the offsets only
        const sema::Symbol* symbol = symbols_.Find(*named);
        SMTCAL_CHECK(symbol != nullptr && symbol->kind == sema::SymbolKind::Point, "a checked target names a point");
        const auto& decl = std::get<ir::PointDecl>(symbol->decl->node);
        if (!decl.taught) frame = decl.frame;
      }
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
    if (const auto& approach = cell_.robot.final_approach_mm) {
      // The final approach (docs/measure.md, "Backlash"): every target is
      // reached by the same last move as every node of the measurement.
      Position from = target;
      from.xyzu[0] = fmt::format("[{} - {}]", target.xyzu[0], Num(approach->x()));
      from.xyzu[1] = fmt::format("[{} - {}]", target.xyzu[1], Num(approach->y()));
      Line(fmt::format("G0 {}", Axes(from, false)), stmt.loc);
      Line(fmt::format("G0 X{} Y{}", target.xyzu[0], target.xyzu[1]), stmt.loc);
    } else {
      Line(fmt::format("G0 {}", Axes(target, false)), stmt.loc);
    }
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

  // One call of o<pick_place> (EmitPickPlaceSubroutine): the position as
  // written (static and uncorrected targets: the IR's nominal XY) or as
  // computed at run time, and how the subroutine corrects it.
  void EmitPickPlace(const ir::Stmt& stmt, const ir::PickPlace& pick) {
    ReadSwitches(stmt);
    int fixture = -1;
    Command command = CommandOf(stmt, pick.target, &fixture);
    if (command != Command::kFixture) fixture = command == Command::kRunTimeBase ? kPickPlaceBase : kPickPlaceAsWritten;
    // A point or an XY(...) without offsets is written straight into the
    // call; anything else is computed into temporaries first.
    const bool direct = pick.target.offsets.empty() && !std::holds_alternative<ir::PalletPoint>(pick.target.base);
    Position target;
    if (!direct) target = PositionOf(pick.target, stmt.loc);
    if (safe_limz_.empty()) safe_limz_ = Num(cell_.robot.safe_limz_mm);
    GExpr limz = pick.limz ? Expr(*pick.limz) : safe_limz_;
    GExpr vacuum = pick.vacuum ? Expr(*pick.vacuum) : DefaultVacuum();
    std::string& out = Begin();
    const std::size_t begin = out.size();
    auto argument = [&](std::string_view text) {
      out += " [";
      out += text;
      out += ']';
    };
    char digits[16];
    out += "o<pick_place> call";
    argument(std::string_view(digits, std::to_chars(digits, digits + sizeof digits, fixture).ptr));
    if (!direct) {
      for (const GExpr& axis : target.xyzu) argument(axis);
    } else if (const auto* coords = std::get_if<ir::Coords>(&pick.target.base)) {
      for (double value : coords->values) {
        out += " [";
        AppendLinuxCncNumber(out, value);
        out += ']';
      }
    } else {
      const std::string name = Lower(std::get<ir::NamedPoint>(pick.target.base).name);
      for (char axis : {'x', 'y', 'z', 'u'}) {
        out += " [#<_p_";
        out += name;
        out += '_';
        out += axis;
        out += ">]";
      }
    }
    argument(limz);
    argument(vacuum);
    argument(pick.kind == ir::PickPlaceKind::Pick ? "1" : "0");
    argument(std::string_view(digits, std::to_chars(digits, digits + sizeof digits, stmt.loc.line).ptr));
    out += Suffix(stmt.loc);
    Ended(begin, stmt.loc);
  }

  // o<pick_place> call [fixture] [x] [y] [z] [u] [LimZ] [vacuum] [1: Pick, 0: Place] [source line]:
  // the target corrected on the controller (fixture: the cell's index of the
  // fixture it is in, or kPickPlaceBase: a base position, through the error
  // tables; kPickPlaceAsWritten: commanded as given), the Jump there, the
  // vacuum switched, and the sensor waited for; a timeout aborts naming the
  // source line. One subroutine in the main program, so each Pick and Place
  // is one line of it, as a controller reads it.
  void EmitPickPlaceSubroutine() {
    bool used = false;
    ir::ForEachStmt(program_.items, [&](const ir::Stmt& stmt) {
      used = used || std::holds_alternative<ir::PickPlace>(stmt.node);
    });
    if (!used) return;
    out_.Append(LinuxCncPickPlaceSubroutine(cell_, source_name_));
  }

  // The program's `Vacuum n`, as written (made once).
  const std::string& DefaultVacuum() {
    SMTCAL_CHECK(default_vacuum_.has_value(), "a checked Pick/Place without Vacuum has the program's Vacuum");
    if (default_vacuum_text_.empty()) default_vacuum_text_ = Num(*default_vacuum_);
    return default_vacuum_text_;
  }

  const ir::Program& program_;
  const CompileState& state_;
  const cell::Cell& cell_;
  const cell::LinuxCnc* linuxcnc_ = nullptr;
  const sema::SymbolTable& symbols_;
  std::string source_name_;
  Diagnostics& diags_;
  std::unordered_map<const ir::Stmt*, bool> as_written_;
  std::unordered_map<const sema::Symbol*, int> cell_fixture_of_;  // FixtureIndexOf's answers
  std::string safe_limz_;  // the robot's safe_limz_mm, as written
  std::string default_vacuum_text_;  // the program's `Vacuum n`, as written
  std::optional<int> default_vacuum_;                   // the program's `Vacuum n`
  std::map<const ir::Expr*, std::string> switches_;
  std::set<std::string> locals_;  // the current function's, lowercase
  std::string function_;          // the current function, lowercase
  TextOutput& out_;
  std::string suffix_;            // Suffix() of source line suffix_line_
  std::string source_where_;      // "layers.place:", sanitized
  std::uint32_t suffix_line_ = 0;
  bool suffix_made_ = false;
  int indent_ = 0;
  int next_oword_ = kFirstOWord;
 public:
  std::vector<LinuxCncIoUse> io_;  // the digital inputs and outputs the program uses (constant bits)
 private:
  int next_switch_ = 1;
};

// ------------------------------------------------------------------ the directory

std::string FirstLine(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::getline(in, line);
  return line;
}

// Why `dir` is not a folder of smtcal's runtime files (only smtcal_*.ngc,
// and in dry-run/ also rs274's INI and parameter file), or "".
std::string NotOurRuntime(const fs::path& dir) {
  if (!fs::is_directory(dir)) return fmt::format("'{}' exists and is not a directory", dir.string());
  for (const fs::directory_entry& sub : fs::directory_iterator(dir)) {
    const std::string name = sub.path().filename().string();
    const bool rs274 = dir.filename() == kLinuxCncDryRunFolder &&
                       (name == kLinuxCncDryRunIni || name == kLinuxCncDryRunVar);
    if (sub.is_regular_file() && (rs274 || (name.starts_with("smtcal_") && sub.path().extension() == ".ngc"))) {
      continue;
    }
    return fmt::format("'{}' holds '{}', which smtcal did not write", dir.string(), name);
  }
  return "";
}

// The folder holding `path`, for RemoveStaleTemporaries.
std::string ParentOf(const fs::path& path) { return path.has_parent_path() ? path.parent_path().string() : "."; }

// Why `dir` is not an earlier smtcal output, or "" when it is.
std::string NotOurOutput(const fs::path& dir) {
  if (!fs::is_directory(dir)) return fmt::format("'{}' exists and is not a directory", dir.string());
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    const fs::path& path = entry.path();
    if (entry.is_directory() && (path.filename() == "subroutines" || path.filename() == kLinuxCncDryRunFolder)) {
      if (std::string why = NotOurRuntime(path); !why.empty()) return why;
      continue;
    }
    const fs::path extension = path.extension();
    if (entry.is_regular_file() && extension == ".ngc" && FirstLine(path).starts_with(kHeaderMark)) continue;
    // The machine files: smtcal's INI and HAL, LinuxCNC's tool table and
    // parameter file (LinuxCNC rewrites them).
    if (entry.is_regular_file() && (extension == ".ini" || extension == ".hal") &&
        FirstLine(path).find("written by smtcal") != std::string::npos) {
      continue;
    }
    if (entry.is_regular_file() && (extension == ".tbl" || extension == ".var")) continue;
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

}  // namespace

// The o<pick_place> subroutine (linuxcnc_emit.h): written by the emitter into
// every main program with a Pick or Place, and compared by the reader of an
// output (linuxcnc_output.h).
std::string LinuxCncPickPlaceSubroutine(const cell::Cell& cell, std::string_view source_name) {
  SMTCAL_CHECK(cell.linuxcnc.has_value(), "the LinuxCNC target has the cell's [linuxcnc] table");
  const std::string timeout = Num(cell.linuxcnc->vacuum_timeout_s);
  const int sensor = cell.linuxcnc->vacuum_sensor_input;
  const std::string where = SanitizeMessage(Quoted(source_name));
  const char axis = cell.linuxcnc->rotation_axis;
  std::string text;
  int indent = 0;
  auto block = [&](std::string_view line) {
    text += std::string(static_cast<std::size_t>(indent) * 2, ' ');
    text += line;
    text += '\n';
  };
  // A comment line cut to fit, as Emitter::Comment cuts it.
  auto comment = [&](std::string_view line) {
    std::string body = Sanitize(line);
    if (body.size() > kMaxLineChars - 2) body = body.substr(0, kMaxLineChars - 5) + "...";
    text += '(' + body + ")\n";
  };
  comment(fmt::format("Pick and Place: o<pick_place> call [fixture] [x] [y] [z] [u] [LimZ] [vacuum] [1 Pick or 0 Place] [source line]"));
  comment(fmt::format("fixture: the cell's index of the fixture - {}: a base position corrected through the tables - {}: as given",
                      kPickPlaceBase, kPickPlaceAsWritten));
  block("o<pick_place> sub");
  ++indent;
  block(fmt::format("o<pick_place_correct> if [#1 GT {}]", kPickPlaceAsWritten));
  ++indent;
  block("o<smtcal_correct> call [#1] [#2] [#3]");
  block("#2 = #<_smtcal_x>");
  block("#3 = #<_smtcal_y>");
  block("#5 = [#5 + #<_smtcal_angle>]");
  --indent;
  block("o<pick_place_correct> endif");
  block("G0 Z#6");
  if (const auto& approach = cell.robot.final_approach_mm) {
    // The final approach: the last x-y move is robot.final_approach_mm, as
    // at every node the tables were measured at (backlash taken up alike).
    block(fmt::format("G0 X[#2 - {}] Y[#3 - {}] {}#5", Num(approach->x()), Num(approach->y()), axis));
    block("G0 X#2 Y#3");
  } else {
    block(fmt::format("G0 X#2 Y#3 {}#5", axis));
  }
  block("G0 Z#4");
  block("o<pick_place_vacuum> if [#8 EQ 1]");
  ++indent;
  block("M64 P#7");
  block(fmt::format("M66 P{} L3 Q{}", sensor, timeout));
  --indent;
  block("o<pick_place_vacuum> else");
  ++indent;
  block("M65 P#7");
  block(fmt::format("M66 P{} L4 Q{}", sensor, timeout));
  --indent;
  block("o<pick_place_vacuum> endif");
  block("o<pick_place_agreed> if [#5399 LT 0]");
  ++indent;
  block("o<pick_place_held> if [#8 EQ 1]");
  ++indent;
  block(fmt::format("(abort,smtcal: Pick at {}:%d#9: vacuum sensor input {} did not report the part held within {} s)",
                    where, sensor, timeout));
  --indent;
  block("o<pick_place_held> endif");
  block(fmt::format("(abort,smtcal: Place at {}:%d#9: vacuum sensor input {} did not report the part released within {} s)",
                    where, sensor, timeout));
  --indent;
  block("o<pick_place_agreed> endif");
  --indent;
  block("o<pick_place> endsub");
  return text;
}

namespace {
}  // namespace

std::string LinuxCncMainName(const std::string& program_path) {
  if (program_path == "-") return "program.ngc";
  std::string stem = fs::path(program_path).stem().string();
  std::string name;
  for (char c : stem) name += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' ? c : '_';
  return (name.empty() ? std::string("program") : name) + ".ngc";
}

std::optional<LinuxCncOutput> EmitLinuxCnc(const ir::Program& program, const CompileState& state,
                                           const std::string& program_path, TextOutput& main, Diagnostics& diags) {
  SMTCAL_CHECK(state.cell != nullptr, "the linuxcnc target needs a compiled program");
  const cell::Cell& cell = *state.cell;
  std::optional<std::string> problem = LinuxCncDataProblem(cell);
  if (!problem) problem = LinuxCncRecordProblem(cell);
  if (problem) {
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
  Emitter emitter(program, state, source_name, main, diags);
  if (!emitter.Run()) return std::nullopt;
  LinuxCncOutput output;
  output.io = std::move(emitter.io_);
  if (cell.linuxcnc) {
    output.io.push_back({false, cell.linuxcnc->vacuum_sensor_input, "vacuum_sensor_input",
                         cell.linuxcnc->range});
  }
  output.main_name = LinuxCncMainName(program_path);
  output.subroutines = LinuxCncRuntimeFiles();
  output.subroutines.push_back({"smtcal_data.ngc", EmitLinuxCncData(cell)});
  output.subroutines.push_back({"smtcal_scan_abort.ngc", EmitLinuxCncScanAbort(cell)});
  output.subroutines.push_back({"smtcal_record.ngc", EmitLinuxCncRecord(cell)});
  output.subroutines.push_back({"smtcal_record_open.ngc", EmitLinuxCncRecordOpen(cell)});
  std::sort(output.subroutines.begin(), output.subroutines.end(),
            [](const EmbeddedFile& a, const EmbeddedFile& b) { return a.name < b.name; });
  return output;
}

std::string LinuxCncReviewText(const LinuxCncOutput& output, std::string_view main_text) {
  std::string text = fmt::format("(smtcal file: {})\n{}", output.main_name, main_text);
  for (const EmbeddedFile& file : output.subroutines) {
    if (file.name == "smtcal_data.ngc" || file.name == "smtcal_scan_abort.ngc" || file.name == "smtcal_record.ngc" ||
        file.name == "smtcal_record_open.ngc") {
      text += fmt::format("(smtcal file: subroutines/{})\n{}", file.name, file.text);
    }
  }
  for (const EmbeddedFile& file : output.dry_run) {
    text += fmt::format("(smtcal file: {}/{})\n{}", kLinuxCncDryRunFolder, file.name, file.text);
  }
  return text;
}

Result<std::unique_ptr<LinuxCncDirectory>> LinuxCncDirectory::Open(const fs::path& outdir,
                                                                   const std::string& main_name,
                                                                   const fs::path& runtime) {
  auto directory = std::unique_ptr<LinuxCncDirectory>(new LinuxCncDirectory());
  LinuxCncDirectory& d = *directory;
  d.target_ = outdir.has_filename() ? outdir : outdir.parent_path();
  std::error_code error;
  d.replaces_ = fs::exists(fs::symlink_status(d.target_, error));
  if (d.replaces_) {
    if (std::string why = NotOurOutput(d.target_); !why.empty()) {
      return Error{fmt::format("will not replace '{}': {}; choose another -o directory or remove it",
                               d.target_.string(), why)};
    }
  }
  // The temporaries of killed runs go first, as a file output's do: a
  // folder "OUTDIR.tmp.PID" of a process that no longer runs, holding the
  // subroutines/ folder Open() makes first (or, with --ini, only smtcal's
  // files), and "RUNTIME.tmp.PID" holding only the runtime's files.
  RemoveStaleTemporaries(ParentOf(d.target_), d.target_.filename().string() + ".tmp.", [](const std::string& stale) {
    std::error_code ignored;
    if (fs::is_directory(fs::symlink_status(stale, ignored)) &&
        (fs::is_directory(fs::path(stale) / "subroutines", ignored) || NotOurOutput(stale).empty())) {
      fs::remove_all(stale, ignored);
    }
  });
  if (!runtime.empty()) {
    d.runtime_ = runtime.has_filename() ? runtime : runtime.parent_path();
    d.runtime_replaces_ = fs::exists(fs::symlink_status(d.runtime_, error));
    if (d.runtime_replaces_) {
      if (std::string why = NotOurRuntime(d.runtime_); !why.empty()) {
        return Error{fmt::format("will not replace the runtime folder '{}' that the machine's SUBROUTINE_PATH "
                                 "names: {}; name a folder of its own there",
                                 d.runtime_.string(), why)};
      }
    }
    RemoveStaleTemporaries(ParentOf(d.runtime_), d.runtime_.filename().string() + ".tmp.", [](const std::string& stale) {
      std::error_code ignored;
      if (fs::is_directory(fs::symlink_status(stale, ignored)) && NotOurRuntime(stale).empty()) {
        fs::remove_all(stale, ignored);
      }
    });
    d.runtime_temp_ = d.runtime_;
    d.runtime_temp_ += fmt::format(".tmp.{}", ::getpid());
    fs::remove_all(d.runtime_temp_, error);
    fs::create_directories(d.runtime_temp_, error);
    if (error) return Error{fmt::format("cannot create '{}': {}", d.runtime_temp_.string(), error.message())};
  }
  d.temp_ = d.target_;
  d.temp_ += fmt::format(".tmp.{}", ::getpid());
  fs::remove_all(d.temp_, error);
  fs::create_directories(d.runtime_.empty() ? d.temp_ / "subroutines" : d.temp_, error);
  if (error) return Error{fmt::format("cannot create '{}': {}", d.temp_.string(), error.message())};
  Result<std::unique_ptr<TextOutput>> main = TextOutput::Open((d.temp_ / main_name).string());
  if (!main) return main.error();
  d.main_ = std::move(main).value();
  return directory;
}

LinuxCncDirectory::~LinuxCncDirectory() {
  main_.reset();  // closes and removes an unfinished main program first
  std::error_code error;
  if (!committed_) fs::remove_all(temp_, error);
  if (!runtime_temp_.empty() && !runtime_committed_) fs::remove_all(runtime_temp_, error);
}

namespace {

// Puts the finished `temp` in place of `target`: a rename, or an atomic swap
// when `target` exists (the old one leaves under the temporary's name and is
// removed).
Status SwapIn(const fs::path& temp, const fs::path& target, bool replaces) {
  if (!replaces) {
    if (std::rename(temp.c_str(), target.c_str()) != 0) {
      return Error{fmt::format("cannot write '{}': {}", target.string(), std::strerror(errno))};
    }
    return Ok{};
  }
  if (::renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) != 0) {
    return Error{fmt::format("cannot replace '{}': {}", target.string(), std::strerror(errno))};
  }
  std::error_code error;
  fs::remove_all(temp, error);
  return Ok{};
}

}  // namespace

Status LinuxCncDirectory::Commit(const LinuxCncOutput& output, const std::vector<LinuxCncMachineFile>& machine) {
  std::error_code error;
  Status written = main_->Commit();
  const fs::path subroutines = runtime_.empty() ? temp_ / "subroutines" : runtime_temp_;
  for (const EmbeddedFile& file : output.more_mains) {
    if (!written) break;
    written = WriteText(temp_ / file.name, file.text);
  }
  for (const EmbeddedFile& file : output.subroutines) {
    if (!written) break;
    written = WriteText(subroutines / file.name, file.text);
  }
  for (const LinuxCncMachineFile& file : machine) {
    if (!written) break;
    written = WriteText(temp_ / file.name, file.text);
  }
  if (written && !output.dry_run.empty()) {
    fs::create_directories(temp_ / kLinuxCncDryRunFolder, error);
    if (error) written = Error{fmt::format("cannot create '{}': {}", (temp_ / kLinuxCncDryRunFolder).string(), error.message())};
  }
  for (const EmbeddedFile& file : output.dry_run) {
    if (!written) break;
    written = WriteText(temp_ / kLinuxCncDryRunFolder / file.name, file.text);
  }
  if (written && !output.dry_run.empty()) {
    // rs274's INI names the folders where they will be, absolute.
    const fs::path dry_run = fs::absolute(target_ / kLinuxCncDryRunFolder, error).lexically_normal();
    const fs::path runtime = fs::absolute(runtime_.empty() ? target_ / "subroutines" : runtime_, error).lexically_normal();
    written = WriteText(temp_ / kLinuxCncDryRunFolder / kLinuxCncDryRunIni,
                        EmitLinuxCncDryRunIni(dry_run.string(), runtime.string()));
    if (written) written = WriteText(temp_ / kLinuxCncDryRunFolder / kLinuxCncDryRunVar, LinuxCncZeroOffsets());
  }
  if (!written) return written;
  if (!runtime_.empty()) {
    Status swapped = SwapIn(runtime_temp_, runtime_, runtime_replaces_);
    if (!swapped) return swapped;
    runtime_committed_ = true;
  }
  Status swapped = SwapIn(temp_, target_, replaces_);
  if (!swapped) return swapped;
  committed_ = true;
  return Ok{};
}

}  // namespace smtcal
