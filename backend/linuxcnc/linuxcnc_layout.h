// The layout of the LinuxCNC runtime's data in its numbered parameters
// (runtime/linuxcnc/README.md, "Parameter layout"), and how a main program
// tells the runtime to command a position: written by linuxcnc_data.h into
// smtcal_data.ngc and by linuxcnc_emit.h into the main program, read back by
// linuxcnc_output.h for `smtcal diff`.
#pragma once

#include <string_view>

namespace smtcal {

// The parameter layout shared with runtime/linuxcnc/*.ngc (README.md there).
namespace linuxcnc_layout {
inline constexpr int kFirst = 31;    // the runtime's numbered parameters
inline constexpr int kLast = 4999;
inline constexpr int kScratch = 4700;  // #4700..#4963: the estimators' scratch arrays, then the cycle record; data ends below
inline constexpr int kVersion = 31;  // 1 once smtcal_data ran
inline constexpr int kRegionCount = 32;
inline constexpr int kFixtureCount = 33;
inline constexpr int kRegionDirectory = 34;   // holds the address of the region directory
inline constexpr int kFixtureDirectory = 35;  // holds the address of the fixture directory
inline constexpr int kSafeZ = 36;             // the robot's safe_limz_mm
inline constexpr int kReportOnly = 37;        // 1: a failed check is recorded, not aborted (tests)
inline constexpr int kDataStart = 40;         // directories, records, tables from here
inline constexpr int kLayoutVersion = 1;
// The named parameter smtcal_data.ngc sets to the runtime's identity (the
// main program checks it before its first move; not part of the cell).
inline constexpr std::string_view kRuntimeIdParameter = "#<_smtcal_runtime_id>";
// The first argument of o<pick_place> and o<smtcal_correct> besides a
// fixture's index in the data (0, 1, ...: a point in that fixture's frame,
// through FIX and the tables): a base position the runtime corrects through
// the error tables, or a position commanded as given.
inline constexpr int kCommandBase = -1;
inline constexpr int kCommandAsWritten = -2;

// Fixture record offsets.
inline constexpr int kFxEstimator = 0, kFxOriginX = 1, kFxOriginY = 2, kFxCos = 3, kFxSin = 4, kFxL1 = 5,
                     kFxL2 = 6, kFxEdgeNormal = 7, kFxEdgeOffset = 15, kFxTripCount = 19, kFxTripWindow = 20,
                     kFxMaxShift = 21, kFxMaxRotation = 22, kFxLengthTolerance = 23, kFxSquareness = 24,
                     kFxMaxLineResidual = 25, kFxScanZ = 26, kFxScanFeed = 27, kFxTripEdgeAt = 28,
                     kFxTripNominalAt = 29, kFxTripsAt = 30, kFxTrippedAt = 31, kFxCalibratedAt = 32,
                     kFxScanPathsAt = 33, kFxHasFix = 34, kFxFix = 35, kFxStatus = 41, kFxFailedTrip = 42,
                     kFxCheckValue = 43 /* + code 1..11 */, kFxCheckEvaluated = 55 /* + code */, kFxS = 67,
                     kFxScale = 73, kFxLatchFeed = 74, kFxRecordCycles = 75, kFxRecordSize = 80;
// Predicted search (runtime/linuxcnc/smtcal_probe_predicted.ngc): the
// fixture's predicted_window_mm (0: none) and the traverse feed (mm/min)
// between trips, data; the last scan's paths latched where predicted and
// those searched in full after a prediction failed, set by each scan.
inline constexpr int kFxPredictedWindow = 76, kFxPredictedPaths = 77, kFxFallbackPaths = 78,
                     kFxTraverseFeed = 79;
// The cycle record (backend/linuxcnc/linuxcnc_record.h): the line buffer the
// LOG comments print, above the estimators' scratch (#4700..#4963); and the
// counters that bound the log files, kept across runs in the machine's
// parameter file.
inline constexpr int kRecordBuffer = 4969;   // #4969..#4993: fixture, cycle, status, trip, time, S1..S3, checks, trip
inline constexpr int kRecordSegment = 4996;  // the log's segment: one more at every change of file
inline constexpr int kRecordFile = 4997;     // 0: record_file, 1: record_file.1
inline constexpr int kRecordCount = 4998;    // scans recorded in that file
inline constexpr int kRecordKept = 4999;     // 1 when the parameter file keeps #4996..#4999
// Region record offsets.
inline constexpr int kRgXLo = 0, kRgXHi = 1, kRgYLo = 2, kRgYHi = 3, kRgDomain = 4, kRgContraction = 8,
                     kRgIterationBound = 9, kRgOutside = 10, kRgDxAt = 11, kRgDyAt = 12, kRgRecordSize = 13;
}  // namespace linuxcnc_layout

}  // namespace smtcal
