// A fuzzed .place program through the compile pipeline with the example
// cell (examples/paper-cell), then every target: the corrected program, the
// C data, LinuxCNC, the JSON report and verify's summary.
#include "backend/c/c_data.h"
#include "backend/linuxcnc/linuxcnc_emit.h"
#include "backend/place/place_printer.h"
#include "backend/reports/compile_report.h"
#include "base/json_text.h"
#include "base/text_output.h"
#include "passes/compile_pipeline.h"
#include "passes/correction/compile_state.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(compile) {
  using namespace smtcal;
  static const std::string cell_path = (fuzz::SourceDir() / "examples/paper-cell/paper.cell.toml").string();
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("fuzz.place", std::string(fuzz::AsText(data, size)));
  CompiledProgram compiled;
  Result<bool> ran = CompileForCell(file, cell_path, /*verify_each=*/true, sources, diags, compiled);
  if (!ran) fuzz::Fail("the example cell did not load");
  if (ran.value()) {
    const CompileState& state = *compiled.program.compile;
    ReportCounts counts{static_cast<int>(diags.error_count()), static_cast<int>(diags.warning_count())};
    JsonText(CompileReportJson(compiled.program, state, sources, counts));
    VerifySummaryText(compiled.program, state, sources, counts);
    if (!diags.has_errors()) {
      Diagnostics emit_diags(sources);
      TextOutput main;  // in memory
      EmitLinuxCnc(compiled.program, state, "fuzz.place", main, emit_diags);
      EmitCRuntimeData(*compiled.cell, CRuntimeFixturePoints(state), "fuzz");
      PrintPlace(compiled.program);
      emit_diags.RenderText();
    }
  }
  diags.RenderText();
  return 0;
}
