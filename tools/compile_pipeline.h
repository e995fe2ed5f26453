// The front half of `smtcal compile`, shared by the commands that need a
// program corrected for a cell (compile, verify, simulate): parse, the
// checks, the cell, the correction passes.
#pragma once

#include <optional>
#include <string>

#include "frontend/cell.h"
#include "frontend/diagnostics.h"
#include "frontend/source.h"
#include "passes/ir.h"
#include "tools/commands.h"

namespace smtcal::tools {

// The program after the passes and the cell its CompileState points into
// (keep them together: program.compile->cell is &*cell).
struct CompiledProgram {
  ir::Program program;
  std::optional<cell::Cell> cell;
};

// Parses and checks the program, loads the cell (even when the program has
// errors, so both sets of mistakes are reported at once) and runs the
// correction passes. Returns false, with everything printed and
// options.exit_code set, when the passes could not run; true otherwise —
// the passes' own diagnostics are still in `diags`, unprinted.
// `verify_each` runs the IR verifier after every pass.
bool CompileForCell(const std::string& program_path, const std::string& cell_path, bool verify_each,
                    SourceManager& sources, Diagnostics& diags, CompiledProgram& out, GlobalOptions& options);

}  // namespace smtcal::tools
