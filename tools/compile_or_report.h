// The front half of `smtcal compile` for the commands that need a program
// corrected for a cell (compile, verify, simulate, scan report, cell plot,
// setup-sheet): passes/compile_pipeline.h's CompileForCell with the driver's
// printing and exit codes, as LoadCellOrReport is the cell loader's.
#pragma once

#include <string>

#include "base/diagnostics.h"
#include "base/source.h"
#include "passes/compile_pipeline.h"
#include "tools/commands.h"

namespace smtcal::tools {

// Loads the program file and runs CompileForCell. Returns false, with
// everything printed and options.exit_code set, when the passes could not
// run; true otherwise — the passes' own diagnostics are still in `diags`,
// unprinted.
bool CompileForCellOrReport(const std::string& program_path, const std::string& cell_path, bool verify_each,
                    SourceManager& sources, Diagnostics& diags, CompiledProgram& out, GlobalOptions& options);

}  // namespace smtcal::tools
