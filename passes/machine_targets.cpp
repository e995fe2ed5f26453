// A program's machine targets (passes/machine_targets.h).
#include "passes/machine_targets.h"

#include <algorithm>

#include "base/check.h"
#include "ir/symbols.h"
#include "passes/correction/correction_passes.h"
#include "passes/correction/target_trace.h"
#include "passes/pass_manager.h"

namespace smtcal {

std::span<const MachineTarget> MachineTargets::Of(const ir::Stmt* stmt) const {
  auto it = std::lower_bound(index_.begin(), index_.end(), stmt,
                             [](const auto& entry, const ir::Stmt* s) { return std::less<>()(entry.first, s); });
  if (it == index_.end() || it->first != stmt) return {};
  const std::uint32_t end = std::next(it) == index_.end() ? static_cast<std::uint32_t>(targets_.size()) : std::next(it)->second;
  return std::span<const MachineTarget>(targets_.data() + it->second, end - it->second);
}

MachineTargets MachineTargets::FromState(const CompileState& state, bool compiled) {
  MachineTargets out;
  out.complete_ = state.trace_complete;
  out.reasons_.emplace_back();
  std::unordered_map<const ir::Stmt*, bool> as_written;
  if (compiled) as_written = BaseStatementsCommandedAsWritten(state.targets);
  // The targets grouped by statement, each group in the order the run reached them.
  std::vector<std::pair<const ir::Stmt*, std::uint32_t>> order;
  order.reserve(state.targets.size());
  for (std::size_t i = 0; i < state.targets.size(); ++i) {
    order.emplace_back(state.targets[i].stmt, static_cast<std::uint32_t>(i));
  }
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? std::less<>()(a.first, b.first) : a.second < b.second;
  });
  out.targets_.reserve(order.size());
  for (const auto& [stmt, index] : order) {
    const Target& target = state.targets[index];
    if (out.index_.empty() || out.index_.back().first != stmt) {
      out.index_.emplace_back(stmt, static_cast<std::uint32_t>(out.targets_.size()));
    }
    MachineTarget machine;
    machine.known = target.known;
    if (!target.known) {
      machine.unknown_because = static_cast<std::uint32_t>(out.reasons_.size());
      out.reasons_.push_back(target.unknown_because.str());
    }
    if (target.fixture >= 0) {
      const cell::Fixture* fixture = state.fixtures[static_cast<std::size_t>(target.fixture)].cell_fixture;
      machine.kind = MachineTarget::Kind::kFixture;
      machine.fixture = static_cast<int>(fixture - state.cell->fixtures.data());
      machine.position = target.in_frame;
    } else if (compiled) {
      // The program's numbers are what the controller gets, or what it corrects.
      machine.kind = as_written.at(stmt) ? MachineTarget::Kind::kAsWritten : MachineTarget::Kind::kRunTime;
      machine.position = target.in_frame;
    } else {
      switch (target.kind) {
        case CorrectionKind::kStatic:
          machine.kind = MachineTarget::Kind::kAsWritten;
          machine.position = target.nominal;
          break;
        case CorrectionKind::kUncorrected:
          machine.kind = MachineTarget::Kind::kAsWritten;
          machine.position = target.required;
          break;
        case CorrectionKind::kRunTimeBase:
        case CorrectionKind::kFixture:  // a base-frame target is never kFixture
          machine.kind = MachineTarget::Kind::kRunTime;
          machine.position = target.required;
          break;
      }
    }
    out.targets_.push_back(machine);
  }
  return out;
}

MachineTargets CompiledProgramTargets(const ir::Program& program, const cell::Cell& cell, Diagnostics& diags) {
  CompileState state;
  state.cell = &cell;
  for (const ir::StmtPtr& item : program.items) {
    const auto* decl = std::get_if<ir::FixtureDecl>(&item->node);
    if (decl == nullptr) continue;
    const cell::Fixture* fixture = cell.FindFixture(decl->name);
    SMTCAL_CHECK(fixture != nullptr, "the caller made sure every fixture of the program is in its cell");
    state.fixtures.push_back(NominalBinding(*item, *decl, *fixture));
  }
  TraceTargets(program, sema::SymbolsOf(program), state, diags);
  return MachineTargets::FromState(state, /*compiled=*/true);
}

MachineTargets SourceProgramTargets(ir::Program& program, const cell::Cell& cell, Diagnostics& diags) {
  program.compile = std::make_shared<CompileState>();
  program.compile->cell = &cell;
  // Scan injection and verify add nothing to what is commanded.
  std::vector<const PassInfo*> passes;
  for (const PassInfo& info : CorrectionPassRegistry()) {
    if (info.name == "scan-injection") break;
    passes.push_back(&info);
  }
  RunPasses(program, diags, passes, /*verify_each=*/false);
  MachineTargets targets;
  if (!diags.has_errors()) targets = MachineTargets::FromState(*program.compile, /*compiled=*/false);
  program.compile.reset();  // the targets' full records are no longer needed
  return targets;
}

}  // namespace smtcal
