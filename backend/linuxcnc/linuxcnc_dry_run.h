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

// rs274's INI for a dry run, beside that file: OUTDIR/dry-run/rs274.ini,
// with the dry-run folder first on SUBROUTINE_PATH, then the runtime
// (absolute paths: rs274 resolves them from wherever it is started), and
// its parameter file rs274.var beside it (the work coordinates all zero).
//   rs274 -i OUTDIR/dry-run/rs274.ini -g OUTDIR/PROGRAM.ngc
inline constexpr const char* kLinuxCncDryRunIni = "rs274.ini";
inline constexpr const char* kLinuxCncDryRunVar = "rs274.var";
std::string EmitLinuxCncDryRunIni(const std::string& dry_run_folder, const std::string& runtime_folder);
std::string LinuxCncZeroOffsets();

}  // namespace smtcal
