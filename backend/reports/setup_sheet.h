// The feeder set-up sheet: which part goes in which feeder, lane or tray
// pocket, for the operator who loads the cell. `smtcal import --setup-sheet`
// makes it from the placement list (frontend/cad/cad_to_program.h fills
// it); `smtcal setup-sheet` makes it from any program compiled for the cell
// (ProgramSetupSheet, below). Both print as a text table, as CSV and as a
// printable SVG page (docs/import.md and docs/compile.md describe them).
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
// `feeders` are the cell's and a feeders file's. What a slot holds: the
// program's comments first (a Place's or its point's, in the form `smtcal
// import` writes: "DESIGNATOR VALUE PACKAGE"), then the feeders file's
// [[lane]], then the feeder's own package and value; its location, part
// number and tape from the feeders file (DescribeSlot); which way its parts
// lie in the tape from the pick's u and the feeder's rotation_offset_deg,
// and how far the nozzle turns them from the targets' u.
SetupSheet ProgramSetupSheet(const ir::Program& program, const CompileState& state, const cad::FeederTable& feeders,
                             Diagnostics& diags);

// One row per slot: text for the operator; CSV for a spreadsheet (columns
// feeder, kind, slot_kind, slot, location, count, lot_quantity, spares,
// value, package, part_number, tape_width_mm, tape_pitch_mm, in_tape_deg,
// turns_deg, parts, pick_x_mm, pick_y_mm, pick_z_mm, pick_u_deg, note; lists
// inside a field separated by " / " (values, packages, part numbers), ", "
// (parts) or " " (angles); lot_quantity and spares empty without a lot); a
// printable SVG page (A4 landscape wide) with a tick box per slot and each
// part's direction in its tape drawn.
std::string SetupSheetText(const SetupSheet& sheet);
std::string SetupSheetCsv(const SetupSheet& sheet);
std::string SetupSheetSvg(const SetupSheet& sheet);

}  // namespace smtcal
