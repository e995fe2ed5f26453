// The measuring programs for LinuxCNC (`smtcal measure program`,
// docs/measure.md): one main program per group of visits (a region; for the
// transducer also an axis and a mounting of the plate), each calling the
// measuring runtime (runtime/linuxcnc/measure/) once per visit, and logging
// one line per reading (LOGOPEN; LOGAPPEND when resumed) for `measure read`.
#pragma once

#include <string>
#include <vector>

#include "backend/linuxcnc/embedded_files.h"
#include "calibration/cell.h"
#include "frontend/measurement_input.h"

namespace smtcal {

struct MeasuringPrograms {
  std::vector<EmbeddedFile> programs;     // measure_s<station>[_<axis>].ngc, in plan order
  std::vector<EmbeddedFile> subroutines;  // the measuring runtime
  std::vector<std::string> logs;          // per program: the log file it writes
};

// The programs of `plan` from visit `start` on (1: all; a resumed
// measurement starts at the visit its abort named: the programs before it
// are left out, the one holding it starts there and appends to its log).
// `log_dir`: where the controller writes the logs ("" : LinuxCNC's working
// directory, the configuration's folder). The cell gives the device and its
// wiring, the clear z, the approach. Requires a cell with [measure] and
// robot.final_approach_mm, and 1 <= start <= the visits.
MeasuringPrograms EmitMeasuringPrograms(const measure::LoadedPlan& plan, const cell::Cell& cell, int start,
                                        const std::string& log_dir);

}  // namespace smtcal
