// The front half of a compile (passes/compile_pipeline.h).
#include "passes/compile_pipeline.h"

#include <memory>
#include <vector>

#include "frontend/cell_toml.h"
#include "frontend/parse.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"
#include "passes/pass_manager.h"

namespace smtcal {

Result<bool> CompileForCell(std::uint32_t program_file, const std::string& cell_path, bool verify_each,
                            SourceManager& sources, Diagnostics& diags, CompiledProgram& out) {
  out.program = ParseProgram(program_file, diags);
  if (!diags.has_errors()) {
    std::vector<const PassInfo*> checks;
    for (const PassInfo& info : PassRegistry()) checks.push_back(&info);
    RunPasses(out.program, diags, checks, verify_each);
  }
  Result<std::optional<cell::Cell>> cell = cell::LoadCell(cell_path, sources, diags);
  if (!cell) return cell.error();
  out.cell = std::move(cell).value();
  if (diags.has_errors() || !out.cell) return false;
  // The tables' warnings (sign changes, large errors), once per table and
  // before the findings of the passes: they bear on them, and a long list of
  // budget findings could otherwise reach the error limit first.
  cell::ReportTableWarnings(*out.cell, diags);
  out.program.compile = std::make_shared<CompileState>();
  out.program.compile->cell = &*out.cell;
  out.program.compile->report_budget_findings = out.report_budget_findings;
  std::vector<const PassInfo*> corrections;
  for (const PassInfo& info : CorrectionPassRegistry()) corrections.push_back(&info);
  RunPasses(out.program, diags, corrections, verify_each);
  return true;
}

}  // namespace smtcal
