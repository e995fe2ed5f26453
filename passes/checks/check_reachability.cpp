// check-reachability: code that never runs, functions never called, and
// recursion.
//
// Assumes: an IR that passes the verifier. Calls to undefined names or to
// non-functions are check-names' to report and are ignored here.
// Guarantees:
// - warns at the first statement after a statement that always leaves the
//   function (`Exit Function`, or an If with an Else whose every branch
//   leaves), with a note at what leaves; when nothing follows it in the
//   function's own body, the warning is at the unreachable Fend;
// - warns at every function other than Main that no other function calls;
// - when it reports no error, the call graph has no cycle (the controller's
//   call stack is small and the backends need a static call graph): each
//   cycle is reported once, at its first call, with notes at the others.
// Reads the IR, never changes it.
#include <algorithm>
#include <map>
#include <optional>
#include <set>

#include "ir/ir_walk.h"
#include "ir/symbols.h"
#include "passes/checks/checks.h"

namespace smtcal {
namespace {

using sema::Symbol;
using sema::SymbolKind;

// A statement that always leaves the function, and how to point at it.
struct Leave {
  SourceRange range;
  std::string note;
};

struct CallEdge {
  const ir::Stmt* call;
  const ir::Function* callee;
};

class CheckReachability final : public Pass {
 public:
  std::string_view Name() const override { return "check-reachability"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    diags_ = &diags;
    const sema::SymbolTable& table = sema::SymbolsOf(program);
    table_ = &table;
    std::vector<const ir::Stmt*> functions;
    for (const ir::StmtPtr& item : program.items) {
      if (const auto* function = std::get_if<ir::Function>(&item->node)) {
        functions.push_back(item.get());
        FunctionBody(*function);
        CollectCalls(*function);
      }
    }
    Unused(functions);
    Recursion(functions);
  }

 private:
  // ---------------------------------------------------------------- unreachable code

  void FunctionBody(const ir::Function& function) {
    std::optional<Leave> leave = Block(function.body);
    if (leave && !warned_after_) {
      Diagnostic* diag = diags_->Report(DiagKind::UnreachableCode, SourceRange(function.end.loc, 4), "Fend",
                                        "an 'Exit Function' just before Fend is not needed");
      Diagnostics::AddNote(diag, leave->range, leave->note);
    }
  }

  // Whether the block always leaves the function; warns at the first
  // statement after a statement that does. warned_after_ tells the caller
  // whether this block's own tail was warned about.
  std::optional<Leave> Block(const ir::Block& block) {
    std::optional<Leave> leave;
    bool warned = false;
    for (const ir::StmtPtr& stmt : block) {
      if (std::holds_alternative<ir::Comment>(stmt->node)) continue;
      if (leave) {
        Diagnostic* diag = diags_->Report(DiagKind::UnreachableCode, sema::StmtRange(*stmt), "this statement",
                                          "remove it, or make the Exit conditional");
        Diagnostics::AddNote(diag, leave->range, leave->note);
        warned = true;
        break;
      }
      leave = Stmt(*stmt);
    }
    warned_after_ = warned;
    return leave;
  }

  std::optional<Leave> Stmt(const ir::Stmt& stmt) {
    if (std::holds_alternative<ir::ExitFunction>(stmt.node)) {
      return Leave{sema::StmtRange(stmt), "'Exit Function' leaves the function here"};
    }
    if (const auto* loop = std::get_if<ir::For>(&stmt.node)) {
      Block(loop->body);  // a loop may run zero times: it never always leaves
      return std::nullopt;
    }
    if (const auto* cycle = std::get_if<ir::Cycle>(&stmt.node)) {
      return Block(cycle->body);  // a Cycle's body always runs
    }
    if (const auto* branch = std::get_if<ir::If>(&stmt.node)) {
      bool has_else = !branch->branches.empty() && branch->branches.back().condition == nullptr;
      bool all_leave = has_else;
      for (const ir::IfBranch& b : branch->branches) {
        if (!Block(b.body)) all_leave = false;
      }
      if (all_leave) return Leave{sema::StmtRange(stmt), "every branch of this If leaves the function"};
    }
    return std::nullopt;
  }

  // ---------------------------------------------------------------- calls

  void CollectCalls(const ir::Function& caller) {
    ir::ForEachStmt(caller.body, [&](const ir::Stmt& stmt) {
      const auto* call = std::get_if<ir::Call>(&stmt.node);
      if (call == nullptr) return;
      const Symbol* callee = table_->Find(call->name);
      if (callee != nullptr && callee->kind == SymbolKind::Function) {
        calls_[&caller].push_back({&stmt, &std::get<ir::Function>(callee->decl->node)});
      }
    });
  }

  void Unused(const std::vector<const ir::Stmt*>& functions) {
    std::set<const ir::Function*> called;
    for (const auto& [caller, edges] : calls_) {
      for (const CallEdge& edge : edges) {
        if (edge.callee != caller) called.insert(edge.callee);
      }
    }
    for (const ir::Stmt* stmt : functions) {
      const auto& function = std::get<ir::Function>(stmt->node);
      if (sema::SameName(function.name, "Main") || called.count(&function) != 0) continue;
      diags_->Report(DiagKind::UnusedFunction, sema::NameAt(function.name_loc, function.name), function.name);
    }
  }

  // Depth-first search in source order; a call to a function still on the
  // stack closes a cycle. Every function of a reported cycle is marked so
  // the same cycle is not reported again from another entry. The stack is
  // our own, not the machine's: a chain of 200 000 calls is a valid program.
  void Recursion(const std::vector<const ir::Stmt*>& functions) {
    for (const ir::Stmt* stmt : functions) {
      const auto* function = &std::get<ir::Function>(stmt->node);
      if (done_.count(function) == 0) Visit(function);
    }
  }

  void Visit(const ir::Function* root) {
    Enter(root);
    while (!stack_.empty()) {
      Frame& top = stack_.back();
      const std::vector<CallEdge>& edges = calls_[top.function];
      if (top.next_edge == edges.size()) {
        on_stack_.erase(top.function);
        done_.insert(top.function);
        stack_.pop_back();
        continue;
      }
      const CallEdge& edge = edges[top.next_edge++];
      top.call = edge.call;
      if (auto on_stack = on_stack_.find(edge.callee); on_stack != on_stack_.end()) {
        ReportCycle(on_stack->second);
      } else if (done_.count(edge.callee) == 0) {
        Enter(edge.callee);  // `top` is not used after this
      }
    }
  }

  void Enter(const ir::Function* function) {
    on_stack_.emplace(function, stack_.size());
    stack_.push_back({function, nullptr, 0});
  }

  // The stack from position `first` (the called function) to the top, each
  // with the call it made next.
  void ReportCycle(std::size_t first) {
    const ir::Function* target = stack_[first].function;
    for (std::size_t i = first; i < stack_.size(); ++i) {
      if (in_reported_cycle_.count(stack_[i].function) != 0) return;
    }
    std::vector<Frame> cycle(stack_.begin() + static_cast<std::ptrdiff_t>(first), stack_.end());
    std::string path;
    for (const Frame& frame : cycle) path += fmt::format("'{}' -> ", frame.function->name);
    path += fmt::format("'{}'", target->name);
    auto call_range = [](const Frame& frame) {
      const auto& call = std::get<ir::Call>(frame.call->node);
      return sema::NameAt(call.name_loc, call.name);
    };
    Diagnostic* diag = diags_->Report(DiagKind::RecursiveCall, call_range(cycle.front()), path);
    for (std::size_t i = 1; i < cycle.size(); ++i) {
      Diagnostics::AddNote(diag, call_range(cycle[i]),
                           fmt::format("'{}' calls '{}' here", cycle[i].function->name,
                                       std::get<ir::Call>(cycle[i].call->node).name));
    }
    for (const Frame& frame : cycle) in_reported_cycle_.insert(frame.function);
  }

  struct Frame {
    const ir::Function* function;
    const ir::Stmt* call;       // the call being followed
    std::size_t next_edge = 0;  // index into calls_[function]
  };

  Diagnostics* diags_ = nullptr;
  const sema::SymbolTable* table_ = nullptr;
  bool warned_after_ = false;
  std::map<const ir::Function*, std::vector<CallEdge>> calls_;
  std::vector<Frame> stack_;
  std::map<const ir::Function*, std::size_t> on_stack_;  // its index in stack_
  std::set<const ir::Function*> done_;
  std::set<const ir::Function*> in_reported_cycle_;
};

}  // namespace

std::unique_ptr<Pass> CreateCheckReachabilityPass() { return std::make_unique<CheckReachability>(); }

}  // namespace smtcal
