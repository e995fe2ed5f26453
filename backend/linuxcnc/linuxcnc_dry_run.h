// The dry-run probe file of the LinuxCNC target (`smtcal compile --target
// linuxcnc --dry-run-probe`): OUTDIR/dry-run/smtcal_probe_trips.ngc, a
// replacement of the runtime's probe moves that fills every fixture's trips
// with the trips the controller would latch on a board at its nominal pose
// (exactly where the cell file puts it): the commands that reach the nominal
// trips through the cell's tables, so the estimate gives the nominal FIX. LinuxCNC's standalone interpreter `rs274` has no
// probe input, so with the real file the first scan aborts (missing_trip);
// with this folder first on the subroutine path the whole program runs to
// its end in rs274 (examples/linuxcnc/README.md).
//
// It must never reach a machine: it says so in its comments and in a
// message each time it runs, and it aborts when the interpreter is LinuxCNC's
// task (#<_task> = 1) instead of a standalone or preview interpreter.
#pragma once

#include <string>

#include "calibration/cell.h"

namespace smtcal {

// The folder inside the output directory and the file it holds.
inline constexpr const char* kLinuxCncDryRunFolder = "dry-run";
inline constexpr const char* kLinuxCncDryRunFile = "smtcal_probe_trips.ngc";

// The text of the dry-run smtcal_probe_trips.ngc for the cell (deterministic).
std::string EmitLinuxCncDryRunProbe(const cell::Cell& cell);

}  // namespace smtcal
