// smtcal_scan_abort.ngc: the abort messages of a failed marker scan, one set
// per fixture of the cell, so a message names the fixture by its name
// ("smtcal: marker scan of fixture Board failed check trip_window: ...").
// An rs274 message is fixed text with parameters substituted (no strings),
// so the names have to be written into the file: smtcal writes it beside
// smtcal_data.ngc for the cell it compiles for. The runtime's
// smtcal_scan_failed.ngc calls it (runtime/linuxcnc/README.md, "Aborts").
#pragma once

#include <string>
#include <string_view>

#include "calibration/cell.h"

namespace smtcal {

// The text of smtcal_scan_abort.ngc for the cell (deterministic).
std::string EmitLinuxCncScanAbort(const cell::Cell& cell);

// A name as text of an rs274 message: rs274 would end the comment at ')',
// substitute after '#' and '%', and take ',' after a command word; anything
// but letters, digits, '_', '-' and '.' is written as '_'.
std::string LinuxCncMessageName(std::string_view name);

}  // namespace smtcal
