// bind: the program's fixtures and frames against the cell.
//
// Assumes: a program that passed the checks; program.compile made by the
// compile driver with its cell set (passes/correction/compile_state.h).
// Guarantees when it reports no error: the program is not smtcal output (its
// static targets would be corrected twice); every program fixture is bound to the
// cell's fixture of that name with its nominal pose; every fixture that
// carries taught points has FIX_0 from its teach-time scan; no pallet has
// taught corners; state.targets holds every motion target the program can
// reach (passes/correction/target_trace.h) with its frame: a fixture or the robot base.
// Reads the IR, never changes it.
#include <memory>
#include <set>

#include <fmt/format.h>

#include "ir/ir_ops.h"
#include "ir/symbols.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"
#include "passes/correction/target_trace.h"

namespace smtcal {
namespace {

class Bind final : public Pass {
 public:
  std::string_view Name() const override { return "bind"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    SMTCAL_CHECK(program.compile != nullptr && program.compile->cell != nullptr,
                 "bind runs only when compiling for a cell");
    CompileState& state = *program.compile;
    const cell::Cell& cell = *state.cell;
    if (const ir::Stmt* header = ir::CorrectedHeader(program)) {
      // Its static targets are already commands: correcting them again
      // would move every one by the table's error a second time.
      diags.Report(DiagKind::ProgramIsCompiledOutput, SourceRange(header->loc));
      return;
    }
    const sema::SymbolTable& symbols = sema::SymbolsOf(program);

    for (const ir::StmtPtr& item : program.items) {
      if (const auto* fixture = std::get_if<ir::FixtureDecl>(&item->node)) BindFixture(*item, *fixture, cell, state, diags);
    }
    std::set<int> reported_scans;
    for (const ir::StmtPtr& item : program.items) {
      if (const auto* point = std::get_if<ir::PointDecl>(&item->node); point != nullptr && point->taught) {
        CheckTaughtPoint(*point, cell, state, reported_scans, diags);
      }
      if (const auto* pallet = std::get_if<ir::PalletDecl>(&item->node)) CheckPalletCorners(*item, *pallet, symbols, diags);
    }
    TraceTargets(program, symbols, state, diags);
    if (!state.trace_complete) {
      const sema::Symbol* main = symbols.Find("Main");
      diags.Report(DiagKind::TraceIncomplete, main != nullptr ? main->range : SourceRange{}, kMaxTraceSteps);
    }
  }

 private:
  static void BindFixture(const ir::Stmt& stmt, const ir::FixtureDecl& decl, const cell::Cell& cell,
                          CompileState& state, Diagnostics& diags) {
    const cell::Fixture* fixture = cell.FindFixture(decl.name);
    if (fixture == nullptr) {
      std::vector<std::string> names;
      for (const cell::Fixture& f : cell.fixtures) names.push_back(f.name);
      std::string closest = ClosestName(decl.name, names);
      std::string hint = !closest.empty()        ? fmt::format(" (did you mean '{}'?)", closest)
                         : names.empty()         ? std::string(" (it describes no fixture)")
                                                 : fmt::format(" (it describes {})", fmt::join(names, ", "));
      diags.Report(DiagKind::FixtureNotInCell, sema::NameAt(decl.name_loc, decl.name), decl.name, cell.path, hint);
      return;
    }
    FixtureBinding binding = NominalBinding(stmt, decl, *fixture);
    if (!fixture->teach_trips_mm.empty()) {
      TeachPose pose = EstimateTeachPose(*fixture, cell);
      if (pose.fix) binding.fix0 = *pose.fix;
      binding.teach_fault = pose.fault;
    }
    state.fixtures.push_back(std::move(binding));
  }

  static void CheckTaughtPoint(const ir::PointDecl& point, const cell::Cell& cell, const CompileState& state,
                               std::set<int>& reported_scans, Diagnostics& diags) {
    int index = state.FindFixture(point.frame);
    if (index < 0) return;  // an unbound fixture is reported once, at its declaration
    const FixtureBinding& binding = state.fixtures[index];
    SourceRange where = sema::NameAt(point.name_loc, point.name);
    if (binding.cell_fixture->teach_trips_mm.empty()) {
      diags.Report(DiagKind::TaughtPointWithoutTeachScan, where, point.name, binding.name, cell.path, binding.name);
    } else if (!binding.fix0 && reported_scans.insert(index).second) {
      Diagnostic* diag = diags.Report(DiagKind::TeachScanHasNoPose, binding.cell_fixture->teach_range,
                                      binding.cell_fixture->name, binding.teach_fault);
      Diagnostics::AddNote(diag, where, fmt::format("'{}' is taught on it here", point.name));
    }
  }

  static void CheckPalletCorners(const ir::Stmt& stmt, const ir::PalletDecl& pallet, const sema::SymbolTable& symbols,
                                 Diagnostics& diags) {
    for (std::size_t c = 0; c < pallet.corners.size(); ++c) {
      const sema::Symbol* corner = symbols.Find(pallet.corners[c]);
      if (corner == nullptr || corner->kind != sema::SymbolKind::Point) continue;
      const auto& decl = std::get<ir::PointDecl>(corner->decl->node);
      if (!decl.taught) continue;
      Diagnostic* diag = diags.Report(DiagKind::TaughtPalletCorner, sema::StmtRange(stmt), pallet.number, decl.frame,
                                      decl.frame);
      Diagnostics::AddNote(diag, corner->range, fmt::format("'{}' is taught here", decl.name));
      return;
    }
  }
};

}  // namespace

std::unique_ptr<Pass> CreateBindPass() { return std::make_unique<Bind>(); }

}  // namespace smtcal
