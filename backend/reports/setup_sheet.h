// The feeder set-up sheet: which part goes in which feeder, lane or tray
// pocket, for the operator who loads the cell. `smtcal import --setup-sheet`
// makes it from the placement list (frontend/cad/cad_to_program.h fills
// it); `smtcal setup-sheet` makes it from any program compiled for the cell
// (ProgramSetupSheet, below). Both print as a text table and as CSV
// (docs/import.md and docs/compile.md describe them).
#pragma once

#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "frontend/cad/cad_to_program.h"
#include "frontend/feeders_toml.h"
#include "ir/ir.h"
#include "passes/correction/compile_state.h"

namespace smtcal {

// The set-up sheet of a program after the correction passes: every Pick of
// the first run of each Cycle, in the order the compile trace
// (passes/correction/target_trace.h) follows it — loops unrolled, calls
// followed, an If whose condition is an input taken the way it goes when
// the input is off — counted at the feeder pick point it reaches, with the
// Place that follows it. A pick point reached only on another branch of
// such an If (a spare lane) is listed with count 0 and a note. A Pick whose
// position is known only at run time, or that is at no pick point of the
// cell's feeders, is listed under feeder "?" with a warning at the Pick.
// `feeders` are the cell's and a feeders file's (cad::FeederTable); what a
// lane holds (package, value) is what its feeder says.
SetupSheet ProgramSetupSheet(const ir::Program& program, const CompileState& state,
                             const std::vector<cad::FeederSpec>& feeders, Diagnostics& diags);

// One row per slot, text for the operator, CSV for a spreadsheet (columns
// feeder, kind, slot_kind, slot, count, value, package, parts, pick_x_mm,
// pick_y_mm, pick_z_mm, pick_u_deg, note; lists inside a field separated by
// ", ").
std::string SetupSheetText(const SetupSheet& sheet);
std::string SetupSheetCsv(const SetupSheet& sheet);

}  // namespace smtcal
