// check-names: every name is defined once and used as what it is.
//
// Assumes: an IR that passes the verifier; top-level declarations in any
// order (they are order-independent); a function's locals are visible from
// their declaration to Fend, whatever block declares them (SPEL+).
// Guarantees when it reports no error: fixtures, Local frames, points,
// global variables and functions share one case-insensitive namespace with
// no duplicates; pallet numbers are unique; a function's locals are unique
// and never reuse a global name; every use resolves to a symbol of the right
// kind (In -> Fixture or Local, a taught point's On -> Fixture, pallet
// corners -> points, motion targets -> points, Cycle/Scan -> Fixture, Call
// -> Function, assignments, For and expressions -> variables declared
// before the use); a constant pallet number names a declared pallet; no
// chain of Local frames loops. Reads the IR, never changes it.
#include <map>
#include <set>

#include "calibration/limits.h"
#include "ir/constant_fold.h"
#include "ir/ir_ops.h"
#include "ir/ir_walk.h"
#include "ir/symbols.h"
#include "passes/checks/checks.h"

namespace smtcal {
namespace {

using sema::Symbol;
using sema::SymbolKind;

enum class Want { Point, Frame, Fixture, Variable, Function };

struct WantInfo {
  const char* noun;         // "undefined <noun> 'X'"
  const char* with_article; // "<user> needs <with_article>"
};

WantInfo Describe(Want want) {
  switch (want) {
    case Want::Point: return {"point", "a point"};
    case Want::Frame: return {"frame", "a frame (a Fixture or a Local)"};
    case Want::Fixture: return {"fixture", "a fixture"};
    case Want::Variable: return {"variable", "a variable"};
    case Want::Function: return {"function", "a function"};
  }
  return {"name", "a name"};
}

bool Fits(Want want, SymbolKind kind) {
  switch (want) {
    case Want::Point: return kind == SymbolKind::Point;
    case Want::Frame: return kind == SymbolKind::Fixture || kind == SymbolKind::Local;
    case Want::Fixture: return kind == SymbolKind::Fixture;
    case Want::Variable: return kind == SymbolKind::Variable;
    case Want::Function: return kind == SymbolKind::Function;
  }
  return false;
}

class CheckNames final : public Pass {
 public:
  std::string_view Name() const override { return "check-names"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    diags_ = &diags;
    const sema::SymbolTable& table = sema::SymbolsOf(program);
    table_ = &table;
    for (const ir::StmtPtr& item : program.items) TopLevel(*item);
  }

 private:
  // ---------------------------------------------------------------- top level

  void TopLevel(const ir::Stmt& stmt) {
    if (const auto* fixture = std::get_if<ir::FixtureDecl>(&stmt.node)) {
      Definition(stmt, fixture->name, fixture->name_loc);
    } else if (const auto* local = std::get_if<ir::LocalDecl>(&stmt.node)) {
      Definition(stmt, local->name, local->name_loc);
      if (!local->frame.empty()) {
        GlobalUse(local->frame, sema::NameAt(local->frame_loc, local->frame), Want::Frame, "'In'");
        LocalLoop(stmt, *local);
      }
    } else if (const auto* point = std::get_if<ir::PointDecl>(&stmt.node)) {
      Definition(stmt, point->name, point->name_loc);
      if (!point->frame.empty()) {
        SourceRange where = sema::NameAt(point->frame_loc, point->frame);
        if (point->taught) {
          GlobalUse(point->frame, where, Want::Fixture, "a taught point's 'On'");
        } else {
          GlobalUse(point->frame, where, Want::Frame, "'In'");
        }
      }
    } else if (const auto* pallet = std::get_if<ir::PalletDecl>(&stmt.node)) {
      const sema::SymbolTable::PalletEntry* first = table_->FindPallet(pallet->number);
      if (first != nullptr && first->stmt != &stmt) {
        Diagnostic* diag = diags_->Report(DiagKind::DuplicatePallet, sema::StmtRange(stmt), pallet->number);
        Diagnostics::AddNote(diag, sema::StmtRange(*first->stmt),
                             fmt::format("pallet {} was first defined here", pallet->number));
      }
      for (std::size_t i = 0; i < pallet->corners.size(); ++i) {
        GlobalUse(pallet->corners[i], sema::NameAt(pallet->corner_locs[i], pallet->corners[i]), Want::Point,
                  "a pallet corner");
      }
    } else if (std::holds_alternative<ir::VarDecl>(stmt.node)) {
      for (const Symbol& variable : sema::VariablesDeclaredBy(stmt, /*global=*/true)) {
        Definition(variable);
      }
    } else if (const auto* function = std::get_if<ir::Function>(&stmt.node)) {
      Definition(stmt, function->name, function->name_loc);
      FunctionBody(*function);
    }
  }

  void Definition(const ir::Stmt& stmt, const std::string& name, SourceLoc name_loc) {
    Symbol mine;
    mine.name = name;
    mine.range = sema::NameAt(name_loc, name);
    mine.decl = &stmt;
    Definition(mine);
  }

  // Reports `mine` if the table's first definition of the name is another one.
  void Definition(const Symbol& mine) {
    if (table_->duplicates().empty()) return;  // the usual case: no name is defined twice
    const Symbol* first = table_->Find(mine.name);
    if (first == nullptr || (first->decl == mine.decl && first->range.begin == mine.range.begin)) return;
    Duplicate(mine, *first);
  }

  void Duplicate(const Symbol& mine, const Symbol& first) {
    Diagnostic* diag =
        diags_->Report(DiagKind::DuplicateName, mine.range, mine.name, sema::DescribeKind(first));
    Diagnostics::AddNote(diag, first.range, fmt::format("'{}' was first defined here", first.name));
  }

  // A chain of Local frames that comes back to where it started. Reported
  // once, at the loop's first Local in source order, with notes at the rest.
  void LocalLoop(const ir::Stmt& stmt, const ir::LocalDecl& local) {
    const Symbol* self = table_->Find(local.name);
    if (self == nullptr || self->decl != &stmt || reported_loops_.count(self) != 0) return;
    std::vector<const Symbol*> chain = {self};
    const Symbol* current = self;
    while (true) {
      const auto& decl = std::get<ir::LocalDecl>(current->decl->node);
      if (decl.frame.empty()) return;
      const Symbol* next = table_->Find(decl.frame);
      if (next == nullptr || next->kind != SymbolKind::Local) return;
      if (next == self) break;
      if (std::find(chain.begin(), chain.end(), next) != chain.end()) return;  // a loop not through self
      chain.push_back(next);
      current = next;
    }
    std::string text;
    for (const Symbol* frame : chain) text += fmt::format("{} In ", frame->name);
    text += self->name;
    Diagnostic* diag = diags_->Report(DiagKind::LocalFrameLoop, self->range, self->name, text);
    for (std::size_t i = 0; i < chain.size(); ++i) {
      reported_loops_.insert(chain[i]);
      if (i == 0) continue;
      const auto& decl = std::get<ir::LocalDecl>(chain[i]->decl->node);
      Diagnostics::AddNote(diag, sema::NameAt(decl.frame_loc, decl.frame),
                           fmt::format("'{}' is given In '{}' here", chain[i]->name, decl.frame));
    }
  }

  // ---------------------------------------------------------------- uses

  // Checks a resolved (or unresolved) use of `name`. `found` is what the
  // name resolves to; `candidates` lists suggestions for a misspelling (only
  // called then: listing names for every use would be quadratic).
  template <typename Candidates>
  void Use(const Symbol* found, const std::string& name, SourceRange where, Want want,
           std::string_view user, Candidates candidates, const Symbol* declared_later = nullptr) {
    WantInfo info = Describe(want);
    if (found != nullptr) {
      if (!Fits(want, found->kind)) {
        Diagnostic* diag = diags_->Report(DiagKind::WrongKindOfName, where, user, info.with_article, name,
                                          sema::DescribeKind(*found));
        Diagnostics::AddNote(diag, found->range,
                             fmt::format("'{}' is defined as {} here", found->name, sema::DescribeKind(*found)));
      }
      return;
    }
    std::string suggestion = ClosestName(name, candidates());
    Diagnostic* diag = diags_->Report(DiagKind::UndefinedName, where, info.noun, name,
                                      suggestion.empty() ? "" : fmt::format("; did you mean '{}'?", suggestion));
    if (declared_later != nullptr) {
      Diagnostics::AddNote(diag, declared_later->range,
                           fmt::format("'{}' is declared later, here; declare it before its first use",
                                       declared_later->name));
    }
  }

  std::vector<std::string> Candidates(Want want) const {
    switch (want) {
      case Want::Point: return table_->NamesOf({SymbolKind::Point});
      case Want::Frame: return table_->NamesOf({SymbolKind::Fixture, SymbolKind::Local});
      case Want::Fixture: return table_->NamesOf({SymbolKind::Fixture});
      case Want::Variable: return table_->NamesOf({SymbolKind::Variable});
      case Want::Function: return table_->NamesOf({SymbolKind::Function});
    }
    return {};
  }

  void GlobalUse(const std::string& name, SourceRange where, Want want, std::string_view user) {
    Use(table_->Find(name), name, where, want, user, [&] { return Candidates(want); });
  }

  void ScopedUse(const std::string& name, SourceRange where, Want want, std::string_view user) {
    ScopedUse(name, want != Want::Variable ? table_->Find(name) : nullptr, where, want, user);
  }

  // `global`: what the global table has for the name (not needed for a variable).
  void ScopedUse(const std::string& name, const Symbol* global, SourceRange where, Want want,
                 std::string_view user) {
    if (want != Want::Variable) {
      // Locals are variables; a local that took the name of a global was
      // reported at its declaration, so the global still answers here.
      Use(global != nullptr && Fits(want, global->kind) ? global : scope_->Find(name), name, where, want, user,
          [&] { return Candidates(want); });
      return;
    }
    const Symbol* found = scope_->Find(name);
    const Symbol* later = nullptr;
    if (found == nullptr) {
      auto it = all_locals_.find(sema::Lowercase(name));
      if (it != all_locals_.end()) later = &it->second;
    }
    Use(found, name, where, want, user, [&] { return scope_->VariableNames(); }, later);
  }

  // ---------------------------------------------------------------- functions

  void FunctionBody(const ir::Function& function) {
    sema::LocalScope scope(*table_);
    scope_ = &scope;
    // Every local the function declares anywhere, for "declared later" notes.
    all_locals_.clear();
    ir::ForEachStmt(function.body, [&](const ir::Stmt& stmt) {
      for (Symbol& local : sema::VariablesDeclaredBy(stmt, /*global=*/false)) {
        all_locals_.emplace(sema::Lowercase(local.name), std::move(local));
      }
    });
    Block(function.body);
    scope_ = nullptr;
  }

  void Block(const ir::Block& block) {
    for (const ir::StmtPtr& stmt : block) Stmt(*stmt);
  }

  void Stmt(const ir::Stmt& stmt) {
    if (std::holds_alternative<ir::VarDecl>(stmt.node)) {
      for (Symbol& local : sema::VariablesDeclaredBy(stmt, /*global=*/false)) {
        Symbol copy = local;
        const Symbol* clash = scope_->Declare(std::move(local));
        if (clash == nullptr) continue;
        if (clash->kind == SymbolKind::Variable && clash->global) {
          Diagnostic* diag = diags_->Report(DiagKind::LocalShadowsGlobal, copy.range, copy.name);
          Diagnostics::AddNote(diag, clash->range,
                               fmt::format("the global variable '{}' is declared here", clash->name));
        } else {
          Duplicate(copy, *clash);
        }
      }
    } else if (const auto* assign = std::get_if<ir::Assign>(&stmt.node)) {
      ScopedUse(assign->name, sema::NameAt(stmt.loc, assign->name), Want::Variable, "an assignment");
      Expr(assign->value.get());
    } else if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) {
      Point(motion->target, ir::MotionSpelling(motion->kind));
      Expr(motion->limz.get());
    } else if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) {
      Point(pick->target, ir::PickPlaceSpelling(pick->kind));
      Expr(pick->vacuum.get());
      Expr(pick->limz.get());
    } else if (const auto* output = std::get_if<ir::SetOutput>(&stmt.node)) {
      Expr(output->bit.get());
    } else if (const auto* wait = std::get_if<ir::WaitTime>(&stmt.node)) {
      Expr(wait->seconds.get());
    } else if (const auto* wait_sw = std::get_if<ir::WaitSwitch>(&stmt.node)) {
      Expr(wait_sw->bit.get());
    } else if (const auto* loop = std::get_if<ir::For>(&stmt.node)) {
      ScopedUse(loop->var, sema::NameAt(loop->var_loc, loop->var), Want::Variable, "For");
      Expr(loop->from.get());
      Expr(loop->to.get());
      Expr(loop->step.get());
      Block(loop->body);
    } else if (const auto* branch = std::get_if<ir::If>(&stmt.node)) {
      for (const ir::IfBranch& b : branch->branches) {
        Expr(b.condition.get());
        Block(b.body);
      }
    } else if (const auto* call = std::get_if<ir::Call>(&stmt.node)) {
      ScopedUse(call->name, sema::NameAt(call->name_loc, call->name), Want::Function, "Call");
    } else if (const auto* cycle = std::get_if<ir::Cycle>(&stmt.node)) {
      ScopedUse(cycle->fixture, sema::NameAt(cycle->fixture_loc, cycle->fixture), Want::Fixture, "Cycle");
      Block(cycle->body);
    } else if (const auto* scan = std::get_if<ir::Scan>(&stmt.node)) {
      ScopedUse(scan->fixture, sema::NameAt(scan->fixture_loc, scan->fixture), Want::Fixture, "Scan");
    }
  }

  void Point(const ir::PointExpr& point, std::string_view user) {
    if (const auto* named = std::get_if<ir::NamedPoint>(&point.base)) {
      ScopedUse(named->name, table_->Find(*named), SourceRange(point.loc, named->length), Want::Point, user);
    } else if (const auto* pallet = std::get_if<ir::PalletPoint>(&point.base)) {
      Expr(pallet->number.get());
      Expr(pallet->i.get());
      Expr(pallet->j.get());
      std::optional<int> number = sema::FoldInteger(pallet->number.get());
      // Out-of-range numbers are check-ranges' to report.
      if (number && *number >= limits::kPalletNumberMin && *number <= limits::kPalletNumberMax &&
          table_->FindPallet(*number) == nullptr) {
        std::vector<int> defined = table_->PalletNumbers();
        std::string hint = defined.empty()
                               ? fmt::format("; declare it with 'Pallet {}, P1, P2, P3, columns, rows'", *number)
                               : fmt::format("; the defined pallets are {}", fmt::join(defined, ", "));
        diags_->Report(DiagKind::UndefinedPallet, sema::ExprRange(*pallet->number), *number, hint);
      }
    }
    for (const ir::PointOffset& offset : point.offsets) Expr(offset.amount.get());
  }

  void Expr(const ir::Expr* expr) {
    ir::ForEachExpr(expr, [&](const ir::Expr& node) {
      if (const auto* variable = std::get_if<ir::VariableRef>(&node.node)) {
        ScopedUse(variable->name, sema::ExprRange(node), Want::Variable, "an expression");
      }
    });
  }

  Diagnostics* diags_ = nullptr;
  const sema::SymbolTable* table_ = nullptr;
  sema::LocalScope* scope_ = nullptr;
  std::map<std::string, Symbol> all_locals_;
  std::set<const Symbol*> reported_loops_;
};

}  // namespace

std::unique_ptr<Pass> CreateCheckNamesPass() { return std::make_unique<CheckNames>(); }

}  // namespace smtcal
