// Running a program at compile time to find its motion targets
// (passes/correction/target_trace.h).
#include "passes/correction/target_trace.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <variant>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "base/check.h"
#include "calibration/limits.h"
#include "ir/ir_ops.h"
#include "ir/ir_text.h"
#include "ir/ir_walk.h"

namespace smtcal {
namespace {

using Value = std::optional<double>;  // nullopt: known only at run time
using Variables = std::map<std::string, Value>;

// What a target's position depends on that is not known before run time.
struct Unknown {
  std::string because;
  bool reported = false;  // an error in the program, reported: no target
};

// The calls that led to the running statement, innermost first: a list
// through the C++ stack (one node per active call), so entering a function
// copies nothing; the text is made once per call, for the first target it reaches.
struct CallPath {
  const CallPath* caller = nullptr;
  std::string_view function;
  mutable std::optional<SharedText> shared = {};  // Text(), once a target needs it
  // "Main > Layer > PlaceOne"; past `max_names` calls the middle is "...".
  std::string Text(std::size_t max_names = SIZE_MAX) const {
    std::vector<std::string_view> names;
    for (const CallPath* at = this; at != nullptr; at = at->caller) names.push_back(at->function);
    std::reverse(names.begin(), names.end());
    if (names.size() > max_names && max_names >= 2) {
      names.erase(names.begin() + static_cast<std::ptrdiff_t>(max_names / 2),
                  names.end() - static_cast<std::ptrdiff_t>(max_names - max_names / 2 - 1));
      names.insert(names.begin() + static_cast<std::ptrdiff_t>(max_names / 2), "...");
    }
    std::string text;
    for (std::string_view name : names) text += (text.empty() ? "" : " > ") + std::string(name);
    return text;
  }
};

class Tracer {
 public:
  Tracer(const sema::SymbolTable& symbols, CompileState& state, Diagnostics& diags)
      : symbols_(symbols), state_(state), diags_(diags) {}

  // Room for `statements` motion statements (so the map of their targets is
  // not rehashed while most statements have one target).
  void Reserve(std::size_t statements) { target_index_.reserve(statements); }

  void Run() {
    for (const sema::Symbol& symbol : symbols_.symbols()) {
      if (symbol.kind == sema::SymbolKind::Variable) globals_[sema::Lowercase(symbol.name)] = 0.0;
    }
    const sema::Symbol* main = symbols_.Find("Main");
    if (main == nullptr || main->kind != sema::SymbolKind::Function) return;
    const CallPath path{nullptr, "Main"};
    Frame frame{&std::get<ir::Function>(main->decl->node), {}, &path};
    RunBlock(frame.function->body, frame);
    state_.trace_complete = !out_of_steps_;  // too deep is an error, reported
  }

 private:
  struct Frame {
    const ir::Function* function;
    Variables locals;
    const CallPath* call_path;
  };
  enum class Flow { kNext, kExitFunction, kStop };

  // ---------------------------------------------------------------- values

  Value* Lookup(const std::string& name, Frame& frame) {
    std::string key = sema::Lowercase(name);
    if (auto it = frame.locals.find(key); it != frame.locals.end()) return &it->second;
    if (auto it = globals_.find(key); it != globals_.end()) return &it->second;
    return nullptr;
  }

  Value Eval(const ir::Expr* expr, Frame& frame) {
    if (expr == nullptr) return std::nullopt;
    return std::visit(
        [&](const auto& node) -> Value {
          using Node = std::decay_t<decltype(node)>;
          if constexpr (std::is_same_v<Node, ir::NumberLit>) {
            return node.value;
          } else if constexpr (std::is_same_v<Node, ir::VariableRef>) {
            Value* value = Lookup(node.name, frame);
            return value == nullptr ? std::nullopt : *value;
          } else if constexpr (std::is_same_v<Node, ir::OnOffLit>) {
            return node.on ? 1.0 : 0.0;
          } else if constexpr (std::is_same_v<Node, ir::SwitchRead>) {
            return std::nullopt;  // an input: known only at run time
          } else if constexpr (std::is_same_v<Node, ir::UnaryExpr>) {
            Value operand = Eval(node.operand.get(), frame);
            if (!operand) return std::nullopt;
            switch (node.op) {
              case ir::UnaryOp::Negate: return -*operand;
              case ir::UnaryOp::Plus: return *operand;
              case ir::UnaryOp::Not: return *operand == 0 ? 1.0 : 0.0;
            }
            return std::nullopt;
          } else {
            return Binary(node, frame);
          }
        },
        expr->node);
  }

  Value Binary(const ir::BinaryExpr& node, Frame& frame) {
    Value lhs = Eval(node.lhs.get(), frame);
    Value rhs = Eval(node.rhs.get(), frame);
    // And/Or decide on one known side alone.
    if (node.op == ir::BinaryOp::And && ((lhs && *lhs == 0) || (rhs && *rhs == 0))) return 0.0;
    if (node.op == ir::BinaryOp::Or && ((lhs && *lhs != 0) || (rhs && *rhs != 0))) return 1.0;
    if (!lhs || !rhs) return std::nullopt;
    double a = *lhs, b = *rhs;
    auto truth = [](bool v) { return v ? 1.0 : 0.0; };
    switch (node.op) {
      case ir::BinaryOp::Add: return a + b;
      case ir::BinaryOp::Sub: return a - b;
      case ir::BinaryOp::Mul: return a * b;
      case ir::BinaryOp::Div: return b == 0 ? std::nullopt : Value(a / b);
      case ir::BinaryOp::Mod: return b == 0 ? std::nullopt : Value(std::fmod(a, b));
      case ir::BinaryOp::Eq: return truth(a == b);
      case ir::BinaryOp::Ne: return truth(a != b);
      case ir::BinaryOp::Lt: return truth(a < b);
      case ir::BinaryOp::Gt: return truth(a > b);
      case ir::BinaryOp::Le: return truth(a <= b);
      case ir::BinaryOp::Ge: return truth(a >= b);
      case ir::BinaryOp::And: return truth(a != 0 && b != 0);
      case ir::BinaryOp::Or: return truth(a != 0 || b != 0);
      case ir::BinaryOp::Xor: return truth((a != 0) != (b != 0));
    }
    return std::nullopt;
  }

  // The first run-time value `expr` reads, for messages.
  std::string FirstUnknown(const ir::Expr* expr, Frame& frame) {
    std::string found;
    ir::ForEachExpr(expr, [&](const ir::Expr& e) {
      if (!found.empty()) return;
      if (const auto* var = std::get_if<ir::VariableRef>(&e.node)) {
        Value* value = Lookup(var->name, frame);
        if (value == nullptr || !*value) found = var->name;
      } else if (std::holds_alternative<ir::SwitchRead>(e.node)) {
        found = PrintExpr(e);
      }
    });
    return found.empty() ? PrintExpr(*expr) : found;
  }

  // ---------------------------------------------------------------- points

  std::variant<RootedPose, Unknown> PointPosition(const ir::PointExpr& target, Frame& frame,
                                                  const ir::Stmt*& taught_decl) {
    RootedPose rooted;
    std::string frame_name;
    Pose4 local{};
    if (const auto* named = std::get_if<ir::NamedPoint>(&target.base)) {
      const sema::Symbol* point = symbols_.Find(*named);
      SMTCAL_CHECK(point != nullptr && point->kind == sema::SymbolKind::Point,
                   "a checked program names only points as targets");
      const auto& decl = std::get<ir::PointDecl>(point->decl->node);
      local = decl.coords.values;
      frame_name = decl.frame;
      if (decl.taught) taught_decl = point->decl;
    } else if (const auto* coords = std::get_if<ir::Coords>(&target.base)) {
      local = coords->values;
    } else {
      const auto& pallet = std::get<ir::PalletPoint>(target.base);
      std::variant<Pose4, Unknown> slot = PalletSlot(pallet, frame, frame_name, taught_decl);
      if (auto* unknown = std::get_if<Unknown>(&slot)) return *unknown;
      local = std::get<Pose4>(slot);
    }
    for (const ir::PointOffset& offset : target.offsets) {
      Value amount = Eval(offset.amount.get(), frame);
      if (!amount) return Unknown{FirstUnknown(offset.amount.get(), frame)};
      local[ir::AxisIndex(offset.axis)] += offset.negative ? -*amount : *amount;
    }
    if (taught_decl != nullptr) {
      // Taught coordinates are robot coordinates; the frame is the fixture.
      const auto& decl = std::get<ir::PointDecl>(taught_decl->node);
      return RootedPose{decl.frame, local};
    }
    return ResolveFrame(symbols_, frame_name, local);
  }

  // Pallet(n, i, j): P1 + (i-1)/(columns-1) (P2-P1) + (j-1)/(rows-1) (P3-P1),
  // in the corners' frame (checks made sure they share one).
  std::variant<Pose4, Unknown> PalletSlot(const ir::PalletPoint& pallet, Frame& frame, std::string& frame_name,
                                          const ir::Stmt*& taught_decl) {
    Value number = Eval(pallet.number.get(), frame);
    if (!number) return Unknown{FirstUnknown(pallet.number.get(), frame)};
    const sema::SymbolTable::PalletEntry* entry = FindPallet(*number);
    if (entry == nullptr) {
      ReportUndeclaredPallet(pallet, *number, frame);
      return Unknown{PrintExpr(*pallet.number), true};
    }
    const ir::PalletDecl& decl = *entry->pallet;
    Value i = Eval(pallet.i.get(), frame);
    if (!i) return Unknown{FirstUnknown(pallet.i.get(), frame)};
    double column = *i, row = 1;
    if (pallet.j) {
      Value j = Eval(pallet.j.get(), frame);
      if (!j) return Unknown{FirstUnknown(pallet.j.get(), frame)};
      row = *j;
    } else {  // k counts along the first row, then the next
      double k = *i - 1;
      column = std::fmod(k, decl.columns) + 1;
      row = std::floor(k / decl.columns) + 1;
    }
    std::array<Pose4, 3> corners;
    for (int c = 0; c < 3; ++c) {
      const sema::Symbol* point = symbols_.Find(decl.corners[c]);
      SMTCAL_CHECK(point != nullptr && point->kind == sema::SymbolKind::Point, "checked pallet corners");
      const auto& corner = std::get<ir::PointDecl>(point->decl->node);
      corners[c] = corner.coords.values;
      frame_name = corner.frame;
      if (corner.taught) taught_decl = point->decl;
    }
    double s = decl.columns > 1 ? (column - 1) / (decl.columns - 1) : 0;
    double t = decl.rows > 1 ? (row - 1) / (decl.rows - 1) : 0;
    Pose4 slot{};
    for (int a = 0; a < 4; ++a) {
      slot[a] = corners[0][a] + s * (corners[1][a] - corners[0][a]) + t * (corners[2][a] - corners[0][a]);
    }
    return slot;
  }

  // The pallet a number computed at compile time names, if it is declared.
  // (The checks saw only the numbers written as constants.)
  const sema::SymbolTable::PalletEntry* FindPallet(double number) const {
    if (!(number >= limits::kPalletNumberMin && number <= limits::kPalletNumberMax) || number != std::floor(number)) {
      return nullptr;
    }
    return symbols_.FindPallet(static_cast<int>(number));
  }

  void ReportUndeclaredPallet(const ir::PalletPoint& pallet, double number, const Frame& frame) {
    if (!reported_pallets_.insert(pallet.number.get()).second) return;
    std::vector<int> declared = symbols_.PalletNumbers();
    std::string why =
        number >= limits::kPalletNumberMin && number <= limits::kPalletNumberMax && number == std::floor(number)
            ? fmt::format("no pallet {} is declared; {}", number,
                          declared.empty() ? std::string("the program declares none")
                                           : fmt::format("the declared pallets are {}", fmt::join(declared, ", ")))
            : fmt::format("pallet numbers are whole numbers from {} to {}", limits::kPalletNumberMin,
                          limits::kPalletNumberMax);
    diags_.Report(DiagKind::TracePalletUndeclared, sema::ExprRange(*pallet.number), PrintExpr(*pallet.number),
                  number, frame.call_path->Text(), why);
  }

  void RecordTarget(const ir::Stmt& stmt, const ir::PointExpr& point, Frame& frame) {
    const ir::Stmt* taught_decl = nullptr;
    std::variant<RootedPose, Unknown> position = PointPosition(point, frame, taught_decl);
    Target target;
    target.stmt = &stmt;
    target.text = PrintPointExpr(point);
    target.taught_decl = taught_decl;
    if (auto* unknown = std::get_if<Unknown>(&position)) {
      if (unknown->reported) return;
      target.known = false;
      target.unknown_because = state_.Share(unknown->because);
      // The frame is still known: the point's declaration decides it.
      target.fixture = state_.FindFixture(FrameRootOf(point, frame));
    } else {
      const RootedPose& rooted = std::get<RootedPose>(position);
      target.fixture = rooted.fixture.empty() ? -1 : state_.FindFixture(rooted.fixture);
      target.in_frame = rooted.pose;
      if (taught_decl != nullptr) {
        const auto& decl = std::get<ir::PointDecl>(taught_decl->node);
        for (int a = 0; a < 4; ++a) target.taught_offset[a] = rooted.pose[a] - decl.coords.values[a];
      }
    }
    // A fixture the cell does not describe is reported by bind; its targets
    // have no frame to be corrected in.
    if (target.fixture < 0 && FixtureNamed(point, frame)) return;
    std::size_t index = FindOrAddTarget(std::move(target), *frame.call_path);
    if (trace_ != nullptr && !exploring_) trace_->push_back({TraceEvent::Kind::kMotion, index, 0});
  }

  // Targets are unique per (statement, known, position), found by a hash
  // of all three: a statement in a loop may reach any number of positions
  // (a pallet's lanes), and each lookup stays constant time. The set holds
  // indices into state_.targets (8 bytes a target, not a copy of its key).
  std::size_t FindOrAddTarget(Target target, const CallPath& call_path) {
    state_.targets.push_back(std::move(target));
    auto [found, inserted] = target_index_.insert(state_.targets.size() - 1);
    if (!inserted) {
      state_.targets.pop_back();
      return *found;
    }
    // Where it was reached first: the text made once per call.
    if (!call_path.shared) call_path.shared = state_.Share(call_path.Text());
    state_.targets.back().call_path = *call_path.shared;
    return state_.targets.size() - 1;
  }

  // Whether the target hangs on a fixture (bound to the cell or not).
  bool FixtureNamed(const ir::PointExpr& point, Frame& frame) { return !FrameRootOf(point, frame).empty(); }

  // The root frame (fixture name or "") of a target whose position is unknown.
  std::string FrameRootOf(const ir::PointExpr& point, Frame& frame) {
    std::string frame_name;
    if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      const sema::Symbol* symbol = symbols_.Find(*named);
      const auto& decl = std::get<ir::PointDecl>(symbol->decl->node);
      if (decl.taught) return decl.frame;
      frame_name = decl.frame;
    } else if (const auto* pallet = std::get_if<ir::PalletPoint>(&point.base)) {
      Value number = Eval(pallet->number.get(), frame);
      if (!number) return "";
      const sema::SymbolTable::PalletEntry* entry = FindPallet(*number);
      if (entry == nullptr) return "";
      const auto& corner = std::get<ir::PointDecl>(symbols_.Find(entry->pallet->corners[0])->decl->node);
      if (corner.taught) return corner.frame;
      frame_name = corner.frame;
    }
    return ResolveFrame(symbols_, frame_name, Pose4{}).fixture;
  }

  // ---------------------------------------------------------------- statements

  bool Step() {
    if (++steps_ > kMaxTraceSteps) out_of_steps_ = true;
    return !out_of_steps_;
  }

  // Every block entered (a body of a function, loop, branch or Cycle) is one
  // level of the C++ stack; past kMaxTraceDepth the run stops, reported.
  Flow RunBlock(const ir::Block& block, Frame& frame) {
    if (depth_ >= kMaxTraceDepth) {
      if (!too_deep_) {
        too_deep_ = true;
        const ir::Stmt* where = block.empty() ? nullptr : block.front().get();
        diags_.Report(DiagKind::TraceTooDeep, where != nullptr ? sema::StmtRange(*where) : SourceRange{},
                      kMaxTraceDepth, frame.call_path->Text(/*max_names=*/6));
      }
      return Flow::kStop;
    }
    ++depth_;
    Flow flow = Flow::kNext;
    for (const ir::StmtPtr& stmt : block) {
      if (!Step()) {
        flow = Flow::kStop;
        break;
      }
      flow = RunStmt(*stmt, frame);
      if (flow != Flow::kNext) break;
    }
    --depth_;
    return flow;
  }

  // Every statement kind is named: a kind added to the IR does not compile
  // here until the trace says what it does (a motion must not vanish).
  Flow RunStmt(const ir::Stmt& stmt, Frame& frame) {
    return std::visit(
        [&](const auto& node) -> Flow {
          using Node = std::decay_t<decltype(node)>;
          if constexpr (std::is_same_v<Node, ir::VarDecl>) {
            for (const std::string& name : node.names) frame.locals[sema::Lowercase(name)] = 0.0;
          } else if constexpr (std::is_same_v<Node, ir::Assign>) {
            Value value = Eval(node.value.get(), frame);
            if (Value* target = Lookup(node.name, frame)) *target = value;
          } else if constexpr (std::is_same_v<Node, ir::Motion> || std::is_same_v<Node, ir::PickPlace>) {
            RecordTarget(stmt, node.target, frame);
          } else if constexpr (std::is_same_v<Node, ir::WaitTime>) {
            Value seconds = Eval(node.seconds.get(), frame);
            if (trace_ != nullptr && !exploring_ && seconds) trace_->push_back({TraceEvent::Kind::kWait, 0, *seconds});
          } else if constexpr (std::is_same_v<Node, ir::For>) {
            return RunFor(node, frame);
          } else if constexpr (std::is_same_v<Node, ir::If>) {
            return RunIf(node, frame);
          } else if constexpr (std::is_same_v<Node, ir::Call>) {
            const sema::Symbol* function = symbols_.Find(node.name);
            if (function == nullptr || function->kind != sema::SymbolKind::Function) return Flow::kNext;
            const CallPath path{frame.call_path, function->name};
            Frame callee{&std::get<ir::Function>(function->decl->node), {}, &path};
            Flow flow = RunBlock(callee.function->body, callee);
            return flow == Flow::kStop ? Flow::kStop : Flow::kNext;
          } else if constexpr (std::is_same_v<Node, ir::Cycle>) {
            return RunCycle(stmt, node, frame);
          } else if constexpr (std::is_same_v<Node, ir::ExitFunction>) {
            return Flow::kExitFunction;
          } else if constexpr (std::is_same_v<Node, ir::Comment> || std::is_same_v<Node, ir::ProgramDecl> ||
                               std::is_same_v<Node, ir::UnitsDecl> || std::is_same_v<Node, ir::FixtureDecl> ||
                               std::is_same_v<Node, ir::LocalDecl> || std::is_same_v<Node, ir::PointDecl> ||
                               std::is_same_v<Node, ir::PalletDecl> || std::is_same_v<Node, ir::VacuumDecl> ||
                               std::is_same_v<Node, ir::Function>) {
            // Declarations: the symbol table holds what they say; a Function
            // runs when it is called.
          } else if constexpr (std::is_same_v<Node, ir::SetOutput> || std::is_same_v<Node, ir::WaitSwitch>) {
            // I/O: no position, and no time the trace can know (a switch is
            // waited for on the controller).
          } else if constexpr (std::is_same_v<Node, ir::Scan>) {
            // A scan moves the robot over the markers, not to a target; its
            // time is the scan plan's (calibration/scan_plan.h).
          } else {
            static_assert(sizeof(Node) == 0, "statement kind the target trace does not handle");
          }
          return Flow::kNext;
        },
        stmt.node);
  }

  Flow RunCycle(const ir::Stmt& stmt, const ir::Cycle& cycle, Frame& frame) {
    std::vector<TraceEvent>* outer = trace_;
    bool first = !state_.cycle_traces.contains(&stmt) && !exploring_;
    if (first) trace_ = &state_.cycle_traces[&stmt];
    Flow flow = RunBlock(cycle.body, frame);
    if (first) trace_ = outer;
    return flow;
  }

  Flow RunFor(const ir::For& loop, Frame& frame) {
    Value from = Eval(loop.from.get(), frame);
    Value to = Eval(loop.to.get(), frame);
    Value step = loop.step ? Eval(loop.step.get(), frame) : Value(1.0);
    Value* var = Lookup(loop.var, frame);
    if (var == nullptr) return Flow::kNext;
    if (!from || !to || !step || *step == 0) {
      *var = std::nullopt;
      Variables before_globals = globals_, before_locals = frame.locals;
      Flow flow = RunBlock(loop.body, frame);
      // After an unknown number of runs, whatever the body changed is unknown.
      ForgetChanged(before_globals, globals_);
      ForgetChanged(before_locals, frame.locals);
      return flow == Flow::kStop || flow == Flow::kExitFunction ? flow : Flow::kNext;
    }
    for (double v = *from; *step > 0 ? v <= *to : v >= *to; v += *step) {
      *Lookup(loop.var, frame) = v;
      Flow flow = RunBlock(loop.body, frame);
      if (flow != Flow::kNext) return flow;
      if (!Step()) return Flow::kStop;
    }
    return Flow::kNext;
  }

  static void ForgetChanged(const Variables& before, Variables& after) {
    for (auto& [name, value] : after) {
      auto it = before.find(name);
      if (it == before.end() || it->second != value) value = std::nullopt;
    }
  }

  Flow RunIf(const ir::If& branch, Frame& frame) {
    std::vector<const ir::IfBranch*> candidates;
    for (const ir::IfBranch& b : branch.branches) {
      if (b.condition == nullptr) {  // Else
        candidates.push_back(&b);
        break;
      }
      Value condition = Eval(b.condition.get(), frame);
      if (condition && *condition != 0) {
        candidates.push_back(&b);
        break;
      }
      if (!condition) candidates.push_back(&b);
    }
    bool has_else = !branch.branches.empty() && branch.branches.back().condition == nullptr;
    bool decided = candidates.size() == 1 && (candidates[0]->condition == nullptr ||
                                               Eval(candidates[0]->condition.get(), frame).has_value());
    if (decided) return RunBlock(candidates[0]->body, frame);
    if (candidates.empty()) return Flow::kNext;
    // Several branches may run: each on a copy; the merge keeps what they agree on.
    // The trace follows the branch taken when every unknown condition is false.
    const ir::IfBranch* traced = nullptr;
    for (const ir::IfBranch* b : candidates) {
      Value condition = b->condition ? Eval(b->condition.get(), frame) : Value(1.0);
      if (condition && *condition != 0) {
        traced = b;
        break;
      }
    }
    Variables globals_in = globals_, locals_in = frame.locals;
    std::vector<std::pair<Variables, Variables>> outcomes;
    bool stopped = false;
    for (const ir::IfBranch* b : candidates) {
      globals_ = globals_in;
      frame.locals = locals_in;
      bool was_exploring = exploring_;
      exploring_ = exploring_ || b != traced;
      Flow flow = RunBlock(b->body, frame);
      exploring_ = was_exploring;
      if (flow == Flow::kStop) stopped = true;
      outcomes.emplace_back(globals_, frame.locals);
    }
    if (!has_else) outcomes.emplace_back(globals_in, locals_in);  // no branch taken
    globals_ = Merge(outcomes, true);
    frame.locals = Merge(outcomes, false);
    return stopped ? Flow::kStop : Flow::kNext;
  }

  static Variables Merge(const std::vector<std::pair<Variables, Variables>>& outcomes, bool globals) {
    Variables merged = globals ? outcomes[0].first : outcomes[0].second;
    for (const auto& outcome : outcomes) {
      const Variables& vars = globals ? outcome.first : outcome.second;
      for (auto& [name, value] : merged) {
        auto it = vars.find(name);
        if (it == vars.end() || it->second != value) value = std::nullopt;
      }
    }
    return merged;
  }

  const sema::SymbolTable& symbols_;
  CompileState& state_;
  Diagnostics& diags_;
  std::set<const ir::Expr*> reported_pallets_;
  int depth_ = 0;  // blocks being run
  bool too_deep_ = false;
  Variables globals_;
  // What makes a target: its statement, whether its position is known, and
  // the position (compared as numbers: -0 is 0).
  struct TargetHash {
    const std::vector<Target>* targets;
    std::size_t operator()(std::size_t index) const {
      const Target& t = (*targets)[index];
      std::size_t hash = std::hash<const ir::Stmt*>()(t.stmt) ^ (t.known ? 0x9e3779b97f4a7c15ull : 0);
      for (double value : t.in_frame) hash = hash * 1099511628211ull ^ std::hash<double>()(value + 0.0);
      return hash;
    }
  };
  struct SameTarget {
    const std::vector<Target>* targets;
    bool operator()(std::size_t a, std::size_t b) const {
      const Target &ta = (*targets)[a], &tb = (*targets)[b];
      return ta.stmt == tb.stmt && ta.known == tb.known && ta.in_frame == tb.in_frame;
    }
  };
  std::unordered_set<std::size_t, TargetHash, SameTarget> target_index_{
      0, TargetHash{&state_.targets}, SameTarget{&state_.targets}};
  std::vector<TraceEvent>* trace_ = nullptr;
  bool exploring_ = false;  // in a branch the cycle trace does not follow
  long steps_ = 0;
  bool out_of_steps_ = false;
};

}  // namespace

RootedPose ResolveFrame(const sema::SymbolTable& symbols, const std::string& frame, const Pose4& local) {
  RootedPose rooted{"", local};
  std::string current = frame;
  for (std::size_t hops = 0; !current.empty() && hops <= symbols.symbols().size(); ++hops) {
    const sema::Symbol* symbol = symbols.Find(current);
    SMTCAL_CHECK(symbol != nullptr, "a checked program's frames are declared");
    if (symbol->kind == sema::SymbolKind::Fixture) {
      rooted.fixture = symbol->name;
      return rooted;
    }
    SMTCAL_CHECK(symbol->kind == sema::SymbolKind::Local, "a checked program's frames are fixtures or Locals");
    const auto& decl = std::get<ir::LocalDecl>(symbol->decl->node);
    const Pose4& origin = decl.origin.values;
    double angle = Radians(origin[3]);
    double c = std::cos(angle), s = std::sin(angle);
    Pose4 parent = rooted.pose;
    parent[0] = origin[0] + c * rooted.pose[0] - s * rooted.pose[1];
    parent[1] = origin[1] + s * rooted.pose[0] + c * rooted.pose[1];
    parent[2] = origin[2] + rooted.pose[2];
    parent[3] = origin[3] + rooted.pose[3];
    rooted.pose = parent;
    current = decl.frame;
  }
  return rooted;
}

void TraceTargets(const ir::Program& program, const sema::SymbolTable& symbols, CompileState& state,
                  Diagnostics& diags) {
  // Room for one target per motion statement: most have one, and growing a
  // vector of a million targets would hold it twice for a moment.
  std::size_t motions = 0;
  ir::ForEachStmt(program.items, [&](const ir::Stmt& stmt) {
    motions += std::holds_alternative<ir::Motion>(stmt.node) || std::holds_alternative<ir::PickPlace>(stmt.node);
  });
  state.targets.reserve(state.targets.size() + motions);
  Tracer tracer(symbols, state, diags);
  tracer.Reserve(motions);
  tracer.Run();
}

}  // namespace smtcal
