// The LinuxCNC machine's configuration derived from the cell and the program
// (docs/linuxcnc.md, "The machine's configuration"): what the INI and the
// HAL files must say so that the controller does what smtcal computed with.
//
// - the robot's limits, speeds and accelerations: [AXIS_x] and [JOINT_n]
//   MIN_LIMIT, MAX_LIMIT, MAX_VELOCITY, MAX_ACCELERATION per axis, [TRAJ]
//   MAX_LINEAR_VELOCITY and MAX_LINEAR_ACCELERATION (x and y move together,
//   the slower decides: the cell's motion model), trivkins with the axes
//   X Y Z and the rotation axis, mm and degrees;
// - the servo period ([EMCMOT]SERVO_PERIOD: the trips' latency) and the
//   task's cycle ([TASK]CYCLE_TIME, at most a third of the cell's
//   probe_turnaround_s: each probe move of the scan costs LinuxCNC's task
//   about three cycles);
// - the signals: the marker sensor on motion.probe-input, the vacuum switch
//   on motion.digital-in-NN ([linuxcnc] vacuum_sensor_input), and every
//   digital output and input the program uses (its Vacuum, On/Off, Sw(n)),
//   each on a net, num_dio large enough;
// - the work coordinates: the robot base frame (G54 and G92 offsets 0 in
//   the parameter file);
// - [RS274NGC]SUBROUTINE_PATH: where the runtime lives (LinuxCncRuntimeFolder).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "base/result.h"
#include "calibration/cell.h"
#include "frontend/linuxcnc_config.h"

namespace smtcal {

// A digital input or output the program or the cell uses.
struct LinuxCncIoUse {
  bool output = false;
  int bit = 0;
  std::string what;   // "vacuum output", "output bit", "input bit", "the vacuum switch"
  SourceRange range;  // where the program (or the cell) names it
};

// Checks the machine's INI and HAL files against the cell and the program's
// I/O. Every disagreement is an error at the INI or HAL value, naming both
// values.
void CheckLinuxCncMachine(const cell::Cell& cell, const std::vector<LinuxCncIoUse>& io, const IniFile& ini,
                          const HalConfig& hal, SourceManager& sources, Diagnostics& diags);

// The folder the INI's SUBROUTINE_PATH names first, from the INI's folder
// (where LinuxCNC runs): where the runtime goes. An error when the INI has
// no SUBROUTINE_PATH.
Result<std::filesystem::path> LinuxCncRuntimeFolder(const IniFile& ini);

// A complete machine for the cell and the program, everything above filled
// in: `stem`.ini, `stem`.hal, `stem`.tbl and `stem`.var, the program
// `stem`.ngc opened at start and the runtime in `subroutines/` beside them.
// The joints are looped back (a simulator); the real cell's drives replace
// that part of the HAL file.
struct LinuxCncMachineFile {
  std::string name;
  std::string text;
};
std::vector<LinuxCncMachineFile> EmitLinuxCncMachine(const cell::Cell& cell, const std::vector<LinuxCncIoUse>& io,
                                                     const std::string& stem);

}  // namespace smtcal
