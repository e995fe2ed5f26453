// scan-injection: every Cycle re-registers its fixture first.
//
// Assumes: a checked program (each Cycle names a declared fixture).
// Guarantees: the first statement of every Cycle's body (comments aside) is
// `Scan FIXTURE` of the Cycle's own fixture; an injected Scan carries the
// location of its Cycle statement and a comment saying it was injected. A
// Cycle that already opens with that Scan is left as it is, so compiling a
// compiled program does not scan twice.
#include <memory>

#include "ir/symbols.h"
#include "passes/correction/correction_passes.h"

namespace smtcal {
namespace {

class ScanInjection final : public Pass {
 public:
  std::string_view Name() const override { return "scan-injection"; }

  void Run(ir::Program& program, Diagnostics& /*diags*/) override { Visit(program.items); }

 private:
  static void Visit(ir::Block& block) {
    for (ir::StmtPtr& stmt : block) {
      if (auto* function = std::get_if<ir::Function>(&stmt->node)) Visit(function->body);
      if (auto* loop = std::get_if<ir::For>(&stmt->node)) Visit(loop->body);
      if (auto* branch = std::get_if<ir::If>(&stmt->node)) {
        for (ir::IfBranch& b : branch->branches) Visit(b.body);
      }
      if (auto* cycle = std::get_if<ir::Cycle>(&stmt->node)) {
        Inject(*stmt, *cycle);
        Visit(cycle->body);
      }
    }
  }

  static bool OpensWithScan(const ir::Cycle& cycle) {
    for (const ir::StmtPtr& stmt : cycle.body) {
      if (std::holds_alternative<ir::Comment>(stmt->node)) continue;
      const auto* scan = std::get_if<ir::Scan>(&stmt->node);
      return scan != nullptr && sema::SameName(scan->fixture, cycle.fixture);
    }
    return false;
  }

  static void Inject(const ir::Stmt& cycle_stmt, ir::Cycle& cycle) {
    if (OpensWithScan(cycle)) return;
    auto scan = std::make_unique<ir::Stmt>();
    scan->loc = cycle_stmt.loc;
    scan->length = cycle_stmt.length;
    scan->trailing_comment = " injected by smtcal: measure " + cycle.fixture + "'s pose FIX_n before placing";
    scan->node = ir::Scan{cycle.fixture, cycle.fixture_loc};
    cycle.body.insert(cycle.body.begin(), std::move(scan));
  }
};

}  // namespace

std::unique_ptr<Pass> CreateScanInjectionPass() { return std::make_unique<ScanInjection>(); }

}  // namespace smtcal
