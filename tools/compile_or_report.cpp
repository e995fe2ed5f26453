// The front half of `smtcal compile` (tools/compile_or_report.h).
#include "tools/compile_or_report.h"

namespace smtcal::tools {

bool CompileForCellOrReport(const std::string& program_path, const std::string& cell_path, bool verify_each,
                    SourceManager& sources, Diagnostics& diags, CompiledProgram& out, GlobalOptions& options) {
  Result<std::uint32_t> file = sources.Load(program_path);
  if (!file) {
    options.exit_code = ReportIoError(file.error());
    return false;
  }
  Result<bool> ran = smtcal::CompileForCell(file.value(), cell_path, verify_each, sources, diags, out);
  if (!ran) {
    PrintDiagnostics(diags, options);
    options.exit_code = ReportIoError(ran.error());
    return false;
  }
  if (!ran.value()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return false;
  }
  return true;
}

}  // namespace smtcal::tools
