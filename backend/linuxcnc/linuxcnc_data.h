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

#include "calibration/cell.h"

namespace smtcal {

// The parameter layout shared with runtime/linuxcnc/*.ngc (README.md there).
namespace linuxcnc_layout {
inline constexpr int kFirst = 31;    // the runtime's numbered parameters
inline constexpr int kLast = 4999;
inline constexpr int kScratch = 4700;  // #4700..#4999: the estimators' scratch arrays; data ends below
inline constexpr int kVersion = 31;  // 1 once smtcal_data ran
inline constexpr int kRegionCount = 32;
inline constexpr int kFixtureCount = 33;
inline constexpr int kRegionDirectory = 34;   // holds the address of the region directory
inline constexpr int kFixtureDirectory = 35;  // holds the address of the fixture directory
inline constexpr int kSafeZ = 36;             // the robot's safe_limz_mm
inline constexpr int kReportOnly = 37;        // 1: a failed check is recorded, not aborted (tests)
inline constexpr int kDataStart = 40;         // directories, records, tables from here
inline constexpr int kLayoutVersion = 1;

// Fixture record offsets.
inline constexpr int kFxEstimator = 0, kFxOriginX = 1, kFxOriginY = 2, kFxCos = 3, kFxSin = 4, kFxL1 = 5,
                     kFxL2 = 6, kFxEdgeNormal = 7, kFxEdgeOffset = 15, kFxTripCount = 19, kFxTripWindow = 20,
                     kFxMaxShift = 21, kFxMaxRotation = 22, kFxLengthTolerance = 23, kFxSquareness = 24,
                     kFxMaxLineResidual = 25, kFxScanZ = 26, kFxScanFeed = 27, kFxTripEdgeAt = 28,
                     kFxTripNominalAt = 29, kFxTripsAt = 30, kFxTrippedAt = 31, kFxCalibratedAt = 32,
                     kFxScanPathsAt = 33, kFxHasFix = 34, kFxFix = 35, kFxStatus = 41, kFxFailedTrip = 42,
                     kFxCheckValue = 43 /* + code 1..11 */, kFxCheckEvaluated = 55 /* + code */, kFxS = 67,
                     kFxScale = 73, kFxLatchFeed = 74, kFxRecordSize = 80;
// Region record offsets.
inline constexpr int kRgXLo = 0, kRgXHi = 1, kRgYLo = 2, kRgYHi = 3, kRgDomain = 4, kRgContraction = 8,
                     kRgIterationBound = 9, kRgOutside = 10, kRgDxAt = 11, kRgDyAt = 12, kRgRecordSize = 13;
}  // namespace linuxcnc_layout

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
