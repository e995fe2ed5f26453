// The front half of a compile, shared by every user that needs a program
// corrected for a cell (the compile, verify, simulate and diff commands, the
// benchmarks, the tests): parse, the semantic checks, the cell, the
// correction passes. The emitters (backend/) take it from there.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"
#include "calibration/cell.h"
#include "ir/ir.h"

namespace smtcal {

// The program after the passes and the cell its CompileState points into
// (keep them together: program.compile->cell is &*cell).
struct CompiledProgram {
  ir::Program program;
  std::optional<cell::Cell> cell;
  // Set before CompileForCell: CompileState::report_budget_findings.
  bool report_budget_findings = true;
};

// Parses and checks the program in `program_file` (loaded into `sources`),
// loads the cell (even when the program has errors, so both sets of mistakes
// are reported at once) and runs the correction passes. Returns an Error when
// the cell file cannot be read; false when errors in the program or the cell
// kept the correction passes from running; true when they ran. The cell's
// table warnings (cell::ReportTableWarnings) come before the passes'
// findings. Every
// diagnostic, the passes' own included, is left in `diags`.
// `verify_each` runs the IR verifier after every pass.
Result<bool> CompileForCell(std::uint32_t program_file, const std::string& cell_path, bool verify_each,
                            SourceManager& sources, Diagnostics& diags, CompiledProgram& out);

}  // namespace smtcal
