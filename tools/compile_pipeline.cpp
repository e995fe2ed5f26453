// The front half of `smtcal compile` (tools/compile_pipeline.h).
#include "tools/compile_pipeline.h"

#include <memory>
#include <vector>

#include "frontend/parse.h"
#include "passes/compile_state.h"
#include "passes/correction_passes.h"
#include "passes/pass_manager.h"

namespace smtcal::tools {

bool CompileForCell(const std::string& program_path, const std::string& cell_path, bool verify_each,
                    SourceManager& sources, Diagnostics& diags, CompiledProgram& out, GlobalOptions& options) {
  Result<std::uint32_t> file = sources.Load(program_path);
  if (!file) {
    options.exit_code = ReportIoError(file.error());
    return false;
  }
  out.program = ParseProgram(file.value(), diags);
  if (!diags.has_errors()) {
    std::vector<const PassInfo*> checks;
    for (const PassInfo& info : PassRegistry()) checks.push_back(&info);
    RunPasses(out.program, diags, checks, verify_each);
  }
  Result<std::optional<cell::Cell>> cell = cell::LoadCell(cell_path, sources, diags);
  if (!cell) {
    PrintDiagnostics(diags, options);
    options.exit_code = ReportIoError(cell.error());
    return false;
  }
  out.cell = std::move(cell).value();
  if (diags.has_errors() || !out.cell) {
    options.exit_code = PrintDiagnostics(diags, options);
    return false;
  }
  out.program.compile = std::make_shared<CompileState>();
  out.program.compile->cell = &*out.cell;
  std::vector<const PassInfo*> corrections;
  for (const PassInfo& info : CorrectionPassRegistry()) corrections.push_back(&info);
  RunPasses(out.program, diags, corrections, verify_each);
  return true;
}

}  // namespace smtcal::tools
