// Reading back smtcal's own LinuxCNC output (`smtcal compile --target
// linuxcnc`, docs/linuxcnc.md) for `smtcal diff` (docs/diff.md, "LinuxCNC
// outputs"): the main program as the compiled .place program it lowers,
// and the runtime's data (subroutines/smtcal_data.ngc) as the cell its
// runtime corrects with. Only what the emitter writes is read; anything
// else is an error naming the file and line.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"
#include "calibration/cell.h"

namespace smtcal {

struct LinuxCncOutputRead {
  // The main program written back as the compiled .place program it lowers
  // (a SourceManager file named as the .ngc), for the caller to parse and
  // check, and for each of its lines the .ngc line it stands for.
  std::uint32_t place_file = 0;
  std::vector<std::uint32_t> line_map;  // [place line - 1] -> .ngc line
  std::uint32_t main_file = 0;          // the .ngc file itself
  cell::Cell cell;        // the regions and fixtures of smtcal_data.ngc
  std::string main_path;  // OUTDIR/NAME.ngc
  std::string data_path;  // OUTDIR/subroutines/smtcal_data.ngc
};

// A directory, or a file whose name ends in .ngc: what `smtcal diff` reads
// as a LinuxCNC output.
bool LooksLikeLinuxCncOutput(const std::string& path);

// `path` is the output directory or its main .ngc file. An Error when a
// file cannot be read; nullopt, with diagnostics, when what it holds is not
// what smtcal writes.
Result<std::optional<LinuxCncOutputRead>> ReadLinuxCncOutput(const std::string& path, SourceManager& sources,
                                                             Diagnostics& diags);

}  // namespace smtcal
