// The data of the LinuxCNC runtime (runtime/linuxcnc/): smtcal_data.ngc,
// one O-word subroutine that stores a cell's regions (bounds, error tables,
// contraction, iteration bound, outside policy) and fixtures (nominal pose,
// marker edge lines, expected trips, limits, the scan paths in the base
// frame) in the numbered parameters #31..#4699, laid out as
// runtime/linuxcnc/README.md describes. The numbers are the C runtime's
// (CRuntimeData in backend/c/c_data.h), written as plain decimals that read
// back exactly (rs274 reads no exponents).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "calibration/cell.h"
#include "backend/linuxcnc/linuxcnc_layout.h"

namespace smtcal {

// Why the cell's data does not fit the LinuxCNC runtime (parameter space,
// trip count, ...), or nullopt.
std::optional<std::string> LinuxCncDataProblem(const cell::Cell& cell);

// The text of smtcal_data.ngc for the cell (deterministic; the cell must fit:
// checked).
std::string EmitLinuxCncData(const cell::Cell& cell);

// What identifies the runtime of a compile: smtcal's version, its runtime
// files, the cell's data and abort messages (FNV-1a, 31 bits: an integer
// rs274 holds exactly). smtcal_data.ngc sets #<_smtcal_runtime_id> to it;
// the main program refuses to run with another.
long LinuxCncRuntimeId(const cell::Cell& cell);
// The same from the texts: the smtcal version that wrote them, this smtcal's
// runtime files, smtcal_data.ngc without its runtime-id line, and the files
// written for the cell (smtcal_scan_abort.ngc, smtcal_record.ngc,
// smtcal_record_open.ngc): what the reader of an output recomputes from the
// files it finds (linuxcnc_output.h).
long LinuxCncRuntimeIdOf(std::string_view version, std::string_view data_without_id, std::string_view scan_abort,
                         std::string_view record, std::string_view record_open);

// A number as rs274 reads it back exactly: a plain decimal (no exponent) with
// the fewest decimals that round-trip, correctly rounded; "0" for zero.
std::string LinuxCncNumber(double value);
// The same appended to `out` (no temporary string).
void AppendLinuxCncNumber(std::string& out, double value);
// More decimals than any double needs to read back (the smallest subnormal
// needs 324), and the longest text: 309 digits before the point, the point,
// the decimals, a sign.
inline constexpr int kMaxLinuxCncDecimals = 400;
inline constexpr std::size_t kMaxLinuxCncNumberChars = 309 + 1 + kMaxLinuxCncDecimals + 1;

}  // namespace smtcal
