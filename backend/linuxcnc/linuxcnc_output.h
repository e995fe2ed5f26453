// Reading back smtcal's own LinuxCNC output (`smtcal compile --target
// linuxcnc`, docs/linuxcnc.md) for `smtcal diff` (docs/diff.md, "LinuxCNC
// outputs"): the main program as the compiled .place program it lowers, and
// the runtime's folder (OUTDIR/subroutines) as the cell its runtime corrects
// with. Everything the controller runs is read or checked:
//   - the runtime's own files must be this smtcal's (runtime/linuxcnc/*.ngc);
//   - smtcal_data.ngc is decoded with the parameter layout the runtime reads
//     (linuxcnc_layout.h) into regions and fixtures, and must be what the
//     emitter writes for them, line by line (a hand-edited line is an error
//     at its line) and as a whole (its text must give the runtime id it
//     records, so no byte of it changed since smtcal wrote it);
//   - the files written for the cell (smtcal_scan_abort.ngc, the cycle
//     record's smtcal_record.ngc and smtcal_record_open.ngc) must be what the
//     emitter writes for that cell;
//   - the main program: every form the emitter writes, the o<pick_place>
//     subroutine as the emitter writes it for the cell's wiring, its runtime
//     check naming that runtime id, and each motion's correction argument,
//     which CheckLinuxCncCommands holds against the traced program.
// Anything else is an error naming the file and line (LinuxCncOutputUnreadable).
#pragma once

#include <climits>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"
#include "calibration/cell.h"
#include "ir/ir.h"
#include "passes/machine_targets.h"

namespace smtcal {

// A line of the .place text that commands no position.
inline constexpr int kNoLinuxCncCommand = INT_MIN;

struct LinuxCncOutputRead {
  // The main program written back as the compiled .place program it lowers
  // (a SourceManager file named as the .ngc), for the caller to parse and
  // check, and for each of its lines the .ngc line it stands for.
  std::uint32_t place_file = 0;
  std::vector<std::uint32_t> line_map;  // [place line - 1] -> .ngc line
  // [place line - 1] -> how the runtime is told to command the position of
  // that line's motion: a fixture's index in the data, or
  // linuxcnc_layout::kCommandBase / kCommandAsWritten; kNoLinuxCncCommand
  // for a line without a motion.
  std::vector<int> commands;
  std::uint32_t main_file = 0;  // the .ngc file itself
  // What the runtime's files hold: the regions and fixtures of
  // smtcal_data.ngc, the robot's safe z, and what the main program and the
  // record files give of the robot (xy speed of Move, final approach) and of
  // [linuxcnc] (rotation axis, vacuum sensor, the cycle record).
  cell::Cell cell;
  std::string main_path;  // OUTDIR/NAME.ngc
  std::string data_path;  // OUTDIR/subroutines/smtcal_data.ngc
};

// A directory, or a file whose name ends in .ngc: what `smtcal diff` reads
// as a LinuxCNC output.
bool LooksLikeLinuxCncOutput(const std::string& path);

// `path` is the output directory or its main .ngc file. An Error when a
// file cannot be read (a runtime file missing among them); nullopt, with
// diagnostics, when what it holds is not what smtcal writes.
Result<std::optional<LinuxCncOutputRead>> ReadLinuxCncOutput(const std::string& path, SourceManager& sources,
                                                             Diagnostics& diags);

// The same from texts already in `sources`: the main program and the runtime
// folder's files by name (what ReadLinuxCncOutput does once it has loaded
// them; the round-trip test gives the emitter's texts). A runtime file
// missing from `subroutines` is an Error.
struct LinuxCncFolderFiles {
  std::uint32_t main = 0;
  std::string subroutines_dir;                                 // for messages and data_path
  std::vector<std::pair<std::string, std::uint32_t>> subroutines;  // (file name, SourceManager id)
};
Result<std::optional<LinuxCncOutputRead>> ReadLinuxCncFolder(const LinuxCncFolderFiles& folder, SourceManager& sources,
                                                             Diagnostics& diags);

// Once the program read back is parsed, checked and traced
// (CompiledProgramTargets): every motion statement's call must tell the
// runtime to command its positions the way the program's text does (a point
// on a fixture with that fixture's index; a base position the compile-time
// run knows as given; any other base position through the tables). A call
// that says otherwise is an error at its .ngc line: the reader never lets a
// position be evaluated other than the controller would command it.
void CheckLinuxCncCommands(const ir::Program& program, const MachineTargets& targets, const LinuxCncOutputRead& read,
                           Diagnostics& diags);

}  // namespace smtcal
