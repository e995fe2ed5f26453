// check-fixture-scope: fixture points move with their fixture, so they may be
// used only while that fixture is registered: inside its Cycle.
//
// Assumes: an IR that passes the verifier. Undefined or wrong-kind names are
// check-names' to report and are skipped here; a Cycle of a name that is not
// a declared Fixture gives its body an unknown context (nothing is judged
// there); recursion is check-reachability's to report (the analysis below
// terminates on it all the same).
//
// A point belongs to fixture F when it is `In F`, `In` a chain of Local
// frames that ends in F, or `Taught ... On F`; a pallet belongs to F when its
// corners do. A function's context is where it can run: Main runs outside
// any Cycle; a Call passes on the Cycle around it, or, outside any Cycle in
// the caller, the caller's own context. So a function called only inside
// `Cycle Board` may use Board's points, and a call from anywhere else is
// reported at the use with notes along the offending calls. Functions Main
// never reaches run in an unknown context: only their own Cycles count.
//
// Guarantees when it reports no error: a pallet's three corners are in one
// frame; every Jump/Go/Move/Pick/Place of a fixture point (or a constant
// pallet of a fixture) runs only inside a Cycle of that fixture; no Cycle
// runs inside another, directly or through Calls; no Scan of another
// fixture runs inside a Cycle. Reads the IR, never changes it.
#include <deque>
#include <map>
#include <set>

#include "ir/constant_fold.h"
#include "ir/symbols.h"
#include "passes/checks/checks.h"

namespace smtcal {
namespace {

using sema::Symbol;
using sema::SymbolKind;

// Where code runs.
struct Context {
  enum class Kind { Unknown, NoCycle, Cycle };
  Kind kind = Kind::Unknown;
  std::string fixture;  // Cycle only: the fixture's declared name

  std::string Key() const {
    switch (kind) {
      case Kind::Unknown: return "?";
      case Kind::NoCycle: return "";
      case Kind::Cycle: return sema::Lowercase(fixture);
    }
    return "?";
  }
};

// How a function first came to run in a context: the Call that brought it.
struct Arrival {
  const ir::Stmt* call = nullptr;          // null for Main and unreached functions
  const ir::Function* caller = nullptr;
  bool call_inside_cycle = false;          // the Call sits inside a Cycle of the caller
};

class CheckFixtureScope final : public Pass {
 public:
  std::string_view Name() const override { return "check-fixture-scope"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    diags_ = &diags;
    const sema::SymbolTable& table = sema::SymbolsOf(program);
    table_ = &table;

    std::vector<const ir::Function*> functions;
    for (const ir::StmtPtr& item : program.items) {
      if (const auto* pallet = std::get_if<ir::PalletDecl>(&item->node)) PalletCorners(*pallet);
      if (const auto* function = std::get_if<ir::Function>(&item->node)) functions.push_back(function);
    }

    // Main first, then whatever Main never reaches, each to a fixed point.
    const Symbol* main = table.Find("Main");
    if (main != nullptr && main->kind == SymbolKind::Function) {
      Enqueue(&std::get<ir::Function>(main->decl->node), Context{Context::Kind::NoCycle, {}}, Arrival{});
      Drain();
    }
    for (const ir::Function* function : functions) {
      if (reached_.count(function) == 0) {
        Enqueue(function, Context{}, Arrival{});
        Drain();
      }
    }
  }

 private:
  // ---------------------------------------------------------------- pallets

  // Taught coordinates are commanded robot positions (recorded on a fixture
  // at its teach-time pose), programmed ones are required positions: never
  // the same frame, even when both name the robot base or the same fixture.
  static std::string DescribeFrame(const ir::PointDecl& point) {
    if (point.frame.empty()) return point.taught ? "taught in the robot base" : "in the robot base";
    return point.taught ? fmt::format("taught on '{}'", point.frame) : fmt::format("in '{}'", point.frame);
  }

  void PalletCorners(const ir::PalletDecl& pallet) {
    const Symbol* first = nullptr;
    for (std::size_t i = 0; i < pallet.corners.size(); ++i) {
      const Symbol* corner = table_->Find(pallet.corners[i]);
      if (corner == nullptr || corner->kind != SymbolKind::Point) continue;
      if (first == nullptr) {
        first = corner;
        continue;
      }
      if (sema::SymbolTable::FrameOfPoint(*corner) == sema::SymbolTable::FrameOfPoint(*first)) continue;
      const auto& a = std::get<ir::PointDecl>(first->decl->node);
      const auto& b = std::get<ir::PointDecl>(corner->decl->node);
      Diagnostic* diag = diags_->Report(
          DiagKind::PalletCornersInDifferentFrames,
          sema::NameAt(pallet.corner_locs[i], pallet.corners[i]),
          pallet.number, first->name, DescribeFrame(a), corner->name, DescribeFrame(b));
      Diagnostics::AddNote(diag, corner->range, fmt::format("'{}' is declared here", corner->name));
      return;  // one report per pallet
    }
  }

  // ---------------------------------------------------------------- contexts

  void Enqueue(const ir::Function* function, const Context& context, const Arrival& arrival) {
    auto key = std::make_pair(function, context.Key());
    if (arrivals_.count(key) != 0) return;
    arrivals_.emplace(key, arrival);
    reached_.insert(function);
    queue_.push_back({function, context});
  }

  void Drain() {
    while (!queue_.empty()) {
      auto [function, context] = queue_.front();
      queue_.pop_front();
      function_ = function;
      context_ = context;
      Block(function->body, nullptr);
    }
  }

  static std::string Where(const Context& context) {
    return context.kind == Context::Kind::Cycle ? fmt::format("inside 'Cycle {}'", context.fixture)
                                                : "outside any Cycle";
  }

  // Notes along the Calls that brought `function` into `context`.
  void AddCallChain(Diagnostic* diag, const ir::Function* function, const Context& context) {
    constexpr int kMaxNotes = 8;  // a deep chain says enough after a few calls
    for (int notes = 0; notes < kMaxNotes; ++notes) {
      auto it = arrivals_.find(std::make_pair(function, context.Key()));
      if (it == arrivals_.end() || it->second.call == nullptr) return;
      const Arrival& arrival = it->second;
      const auto& call = std::get<ir::Call>(arrival.call->node);
      const std::string& callee = call.name;
      SourceRange where = sema::NameAt(call.name_loc, call.name);
      if (arrival.call_inside_cycle) {
        Diagnostics::AddNote(diag, where, fmt::format("'{}' is called here, {}", callee, Where(context)));
        return;
      }
      Diagnostics::AddNote(diag, where,
                           context.kind == Context::Kind::Cycle
                               ? fmt::format("'{}' is called here, from code that runs {}", callee, Where(context))
                               : fmt::format("'{}' is called here, {}", callee, Where(context)));
      function = arrival.caller;
    }
  }

  // Why code outside any Cycle of its function runs in the inherited context.
  std::string InheritedReason() const {
    return fmt::format("'{}' is called {}", function_->name, Where(context_));
  }
  bool Inherited() const {
    auto it = arrivals_.find(std::make_pair(function_, context_.Key()));
    return it != arrivals_.end() && it->second.call != nullptr;
  }

  // ---------------------------------------------------------------- walking

  // `cycle` is the innermost Cycle statement around the block in this
  // function, or null.
  void Block(const ir::Block& block, const ir::Stmt* cycle) {
    for (const ir::StmtPtr& stmt : block) Stmt(*stmt, cycle);
  }

  Context Effective(const ir::Stmt* cycle) const {
    if (cycle == nullptr) return context_;
    const Symbol* fixture = table_->Find(std::get<ir::Cycle>(cycle->node).fixture);
    if (fixture == nullptr || fixture->kind != SymbolKind::Fixture) return Context{};
    return Context{Context::Kind::Cycle, fixture->name};
  }

  bool FirstReport(const ir::Stmt& stmt) { return reported_.insert(&stmt).second; }

  void Stmt(const ir::Stmt& stmt, const ir::Stmt* cycle) {
    if (const auto* inner = std::get_if<ir::Cycle>(&stmt.node)) {
      CycleStmt(stmt, *inner, cycle);
      Block(inner->body, &stmt);
    } else if (const auto* scan = std::get_if<ir::Scan>(&stmt.node)) {
      ScanStmt(stmt, *scan, cycle);
    } else if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) {
      Use(stmt, motion->target, cycle);
    } else if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) {
      Use(stmt, pick->target, cycle);
    } else if (const auto* call = std::get_if<ir::Call>(&stmt.node)) {
      const Symbol* callee = table_->Find(call->name);
      if (callee == nullptr || callee->kind != SymbolKind::Function) return;
      Arrival arrival{&stmt, function_, cycle != nullptr};
      Enqueue(&std::get<ir::Function>(callee->decl->node), Effective(cycle), arrival);
    } else if (const auto* loop = std::get_if<ir::For>(&stmt.node)) {
      Block(loop->body, cycle);
    } else if (const auto* branch = std::get_if<ir::If>(&stmt.node)) {
      for (const ir::IfBranch& b : branch->branches) Block(b.body, cycle);
    }
  }

  void CycleStmt(const ir::Stmt& stmt, const ir::Cycle& inner, const ir::Stmt* outer) {
    SourceRange where = sema::NameAt(inner.fixture_loc, inner.fixture);
    if (outer != nullptr) {
      if (!FirstReport(stmt)) return;
      const std::string& outer_name = std::get<ir::Cycle>(outer->node).fixture;
      Diagnostic* diag = diags_->Report(DiagKind::NestedCycle, where, inner.fixture, outer_name, "");
      Diagnostics::AddNote(diag, sema::StmtRange(*outer), "the outer Cycle starts here");
    } else if (context_.kind == Context::Kind::Cycle && FirstReport(stmt)) {
      Diagnostic* diag = diags_->Report(DiagKind::NestedCycle, where, inner.fixture, context_.fixture,
                                        fmt::format(" because '{}' is called inside it", function_->name));
      AddCallChain(diag, function_, context_);
    }
  }

  void ScanStmt(const ir::Stmt& stmt, const ir::Scan& scan, const ir::Stmt* cycle) {
    Context context = Effective(cycle);
    if (context.kind != Context::Kind::Cycle || sema::SameName(context.fixture, scan.fixture)) return;
    const Symbol* scanned = table_->Find(scan.fixture);
    if (scanned == nullptr || scanned->kind != SymbolKind::Fixture || !FirstReport(stmt)) return;
    SourceRange where = sema::NameAt(scan.fixture_loc, scan.fixture);
    if (cycle != nullptr) {
      Diagnostic* diag = diags_->Report(DiagKind::ScanInOtherCycle, where, scan.fixture, context.fixture, "");
      Diagnostics::AddNote(diag, sema::StmtRange(*cycle), "the Cycle starts here");
    } else {
      Diagnostic* diag = diags_->Report(DiagKind::ScanInOtherCycle, where, scan.fixture, context.fixture,
                                        fmt::format(" because '{}' is called inside it", function_->name));
      AddCallChain(diag, function_, context_);
    }
  }

  // The fixture a motion target belongs to, and where the target is named.
  const Symbol* FixtureOf(const ir::PointExpr& point, SourceRange& where) const {
    if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      const Symbol* symbol = table_->Find(*named);
      if (symbol == nullptr || symbol->kind != SymbolKind::Point) return nullptr;
      where = SourceRange(point.loc, named->length);
      return table_->FixtureOfPoint(*symbol);
    }
    if (const auto* pallet = std::get_if<ir::PalletPoint>(&point.base)) {
      std::optional<int> number = sema::FoldInteger(pallet->number.get());
      if (!number) return nullptr;  // chosen at run time: the runtime checks it
      where = SourceRange(point.loc, 6);  // "Pallet"
      return table_->FixtureOfPallet(*number);
    }
    return nullptr;  // XY(...) is in the robot base
  }

  // How a report names the target: "point 'P1'", "pallet 2". Made only for a
  // report: every placement of a program is a use.
  std::string Describe(const ir::PointExpr& point) const {
    if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      return fmt::format("point '{}'", table_->Find(*named)->name);
    }
    const auto& pallet = std::get<ir::PalletPoint>(point.base);
    return fmt::format("pallet {}", *sema::FoldInteger(pallet.number.get()));
  }

  void Use(const ir::Stmt& stmt, const ir::PointExpr& target, const ir::Stmt* cycle) {
    SourceRange where;
    const Symbol* fixture = FixtureOf(target, where);
    if (fixture == nullptr) return;
    Context context = Effective(cycle);
    if (context.kind == Context::Kind::Unknown) return;
    if (context.kind == Context::Kind::Cycle && sema::SameName(context.fixture, fixture->name)) return;
    if (!FirstReport(stmt)) return;
    const std::string what = Describe(target);
    if (cycle != nullptr) {
      Diagnostic* diag = diags_->Report(DiagKind::FixturePointOutsideCycle, where, what, fixture->name,
                                        fixture->name, fmt::format("this use is {}", Where(context)));
      Diagnostics::AddNote(diag, sema::StmtRange(*cycle), "the Cycle starts here");
    } else if (!Inherited()) {
      diags_->Report(DiagKind::FixturePointOutsideCycle, where, what, fixture->name, fixture->name,
                     fmt::format("this use is {}", Where(context)));
    } else {
      Diagnostic* diag = diags_->Report(DiagKind::FixturePointOutsideCycle, where, what, fixture->name,
                                        fixture->name, InheritedReason());
      AddCallChain(diag, function_, context_);
    }
  }

  Diagnostics* diags_ = nullptr;
  const sema::SymbolTable* table_ = nullptr;
  std::map<std::pair<const ir::Function*, std::string>, Arrival> arrivals_;
  std::set<const ir::Function*> reached_;
  std::deque<std::pair<const ir::Function*, Context>> queue_;
  std::set<const ir::Stmt*> reported_;
  const ir::Function* function_ = nullptr;  // being walked
  Context context_;                         // its context in this walk
};

}  // namespace

std::unique_ptr<Pass> CreateCheckFixtureScopePass() { return std::make_unique<CheckFixtureScope>(); }

}  // namespace smtcal
