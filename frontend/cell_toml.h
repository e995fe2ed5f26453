// Loading a cell file (`*.cell.toml`, docs/cell.md) into a cell::Cell
// (calibration/cell.h).
#pragma once

#include <array>
#include <optional>
#include <string>

#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"
#include "calibration/cell.h"

namespace smtcal::cell {

// Loads and validates a cell file, its error tables included (paths relative
// to the cell file; read with ReadErrorTable, validated with
// ValidateErrorTable, their diagnostics located in the table files). The cell
// file failing to open is an Error; everything wrong inside it (or a table
// file that cannot be opened, located at its key) is a diagnostic, and then the
// value is nullopt. `sources` must be the SourceManager `diags` renders with.
Result<std::optional<Cell>> LoadCell(const std::string& path, SourceManager& sources, Diagnostics& diags);

// How a cell is loaded for planning its measurement (`smtcal measure plan`):
// a region's table file that does not exist yet is no error (the region gets
// has_table = false and must give its bounds x_mm and y_mm); a table that
// exists is read and validated as always (it is the previous measurement).
struct CellLoadOptions {
  bool tables_may_be_missing = false;
  // For a picture of a cell with mistakes (`smtcal cell plot`): the cell is
  // returned even when errors were reported, with every region, fixture and
  // feeder that was read cleanly, and those whose only errors are points
  // outside the robot's travel (so they are drawn where they are). Nothing
  // but a picture may use such a cell.
  bool keep_drawable = false;
};
Result<std::optional<Cell>> LoadCell(const std::string& path, SourceManager& sources, Diagnostics& diags,
                                     const CellLoadOptions& options);


// Warnings on a loaded cell's marker scans (`smtcal cell check`): every trip
// whose window lies outside every region's table (CellTripUncalibrated: the
// robot's own error there moves every placement on the board), and a probe
// latch later than a quarter of the fixture's max_line_residual_mm
// (CellTripLatency). verify covers both in its budgets.
void CheckScanCalibration(const Cell& cell, Diagnostics& diags);

// The corners of a fixture's pocket (it must have one) in the robot base
// frame at the fixture's nominal pose: lower left, lower right, upper right,
// upper left of the fixture frame.
std::array<Point2, 4> PocketCornersInBase(const Fixture& fixture);

// A pocket that is larger than its region or sticks out of it
// (CellPocketOverRegion, calibration/region_fit.h), at its pocket_x_mm key:
// a board that fills it has parts no table corrects. Nothing for a cell
// without calibrated regions. For `smtcal cell check`.
void CheckPockets(const Cell& cell, Diagnostics& diags);

// The warnings of the cell's error tables (sign changes, errors over half the
// pitch: what `smtcal table check` shows in full), summarised once per table
// at the first region that uses it (CellTableWarnings): for the commands
// that decide (cell check, verify, compile).
void ReportTableWarnings(const Cell& cell, Diagnostics& diags);

// The grid advice of every region whose interpolation estimate is more than
// kInterpolationShareOfTolerance of its tolerance (InterpolationCoarse, at
// its table key): for `smtcal cell check`.
void ReportGridAdvice(const Cell& cell, Diagnostics& diags);

}  // namespace smtcal::cell
