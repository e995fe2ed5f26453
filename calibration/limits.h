// Limits: what a .place program must respect (hard bounds of the language
// and the controller, SPEL+ conventions, checked by
// passes/checks/check_ranges.cpp), the documented range of every number a
// user gives (command-line options and the keys of the cell, truth and
// feeders files, all checked by base/number_range.h), and the bounds on work
// whose size comes from the input. Measurement tolerances live in
// tolerances.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "base/number_range.h"
#include "calibration/tolerances.h"

namespace smtcal::limits {

// --- the language and the controller --------------------------------------------

// I/O bits addressed by On/Off/Sw/Wait Sw: the controller's standard and
// expansion I/O, numbered from 0.
inline constexpr int kIoBitMin = 0;
inline constexpr int kIoBitMax = 511;

// Vacuum outputs (Vacuum n, Pick/Place ... Vacuum n) are ordinary output bits.
inline constexpr int kVacuumOutputMin = kIoBitMin;
inline constexpr int kVacuumOutputMax = kIoBitMax;

// SPEL+ pallets are numbered 0..15.
inline constexpr int kPalletNumberMin = 0;
inline constexpr int kPalletNumberMax = 15;

// A pallet has at least one column and one row; pallet indices are 1-based.
inline constexpr int kPalletMinColumns = 1;
inline constexpr int kPalletMinRows = 1;
inline constexpr int kPalletFirstIndex = 1;

// The rotation u of a point, in degrees: within one turn either way.
inline constexpr double kMaxAbsAngleDeg = 360.0;

// --- ranges of the numbers a user gives ---------------------------------------------
// Each is written, as RangeText words it, into the --help of its option and
// the docs (docs/cell.md, docs/simulate.md, ...). A range is generous: it
// refuses what no real cell has (a unit mistake, a NaN, an overflow), never a
// real value.

// A position, a coordinate or a z: within +-100 m of the robot's origin, the
// bound of every length in a table, point or CAD file (kMaxLengthMm).
inline constexpr NumberRange kPositionMm = Closed(-kMaxLengthMm, kMaxLengthMm, "mm");
// A length that must be positive (L1, L2 of a fixture).
inline constexpr NumberRange kLengthMm = AboveZero(kMaxLengthMm, "mm");
// An angle of a point or a pose, and the robot's u range: within one turn.
inline constexpr NumberRange kAngleDeg = Closed(-kMaxAbsAngleDeg, kMaxAbsAngleDeg, "deg");
// An accuracy, a repeatability, a tolerance: a real cell's are micrometres to
// a fraction of a millimetre; 10 mm is a unit mistake.
inline constexpr NumberRange kAccuracyMm = AboveZero(10, "mm");
// How far the robot's uncalibrated error changes by its own size (robot
// uncalibrated_correlation_mm, truth [robot]): from 0.1 mm (a grid of the
// true field finer than any table) to 10 m.
inline constexpr NumberRange kCorrelationMm = Closed(0.1, 1e4, "mm");
// The controller's servo period (probe latch): up to a second.
inline constexpr NumberRange kServoPeriodS = AboveZero(1, "s");
// What a probe move costs the controller besides the move (robot
// probe_turnaround_s): 0 (none) up to a second; LinuxCNC's is 0.025 s.
inline constexpr NumberRange kProbeTurnaroundS = Closed(0, 1, "s");
// Motion for the cycle-time estimate: up to 100 m/s and 10 000 m/s² (1000 g).
inline constexpr NumberRange kSpeedMmS = AboveZero(1e5, "mm/s");
inline constexpr NumberRange kAccelerationMmS2 = AboveZero(1e7, "mm/s²");
inline constexpr NumberRange kSpeedDegS = AboveZero(1e5, "deg/s");
inline constexpr NumberRange kAccelerationDegS2 = AboveZero(1e7, "deg/s²");
// A dwell or a timeout: up to an hour.
inline constexpr NumberRange kDwellS = Closed(0, 3600, "s");
inline constexpr NumberRange kTimeoutS = AboveZero(3600, "s");
// A fixture's trip window and its check limits.
inline constexpr NumberRange kTripWindowMm = AboveZero(100, "mm");
inline constexpr NumberRange kPredictedWindowMm = Closed(0, 100, "mm");  // 0: no predicted search
// A fixture's pocket (pocket_x_mm, pocket_y_mm): bounds in the fixture frame.
inline constexpr NumberRange kPocketMm = Closed(-2000, 2000, "mm");
inline constexpr NumberRange kFixtureLimitMm = AboveZero(100, "mm");
inline constexpr NumberRange kFixtureRotationDeg = AboveZero(180, "deg");
inline constexpr NumberRange kSquarenessDeg = AboveZero(45, "deg");
// The difficulty level L_D: the number of task axes.
inline constexpr NumberRange kDifficultyLevel = Whole(1, 4);
// An input or output bit of the robot controller; a LinuxCNC digital input.
inline constexpr NumberRange kIoBit = Whole(kIoBitMin, kIoBitMax);
inline constexpr NumberRange kLinuxCncInput = Whole(0, 63);  // [EMCMOT] num_dio: 64 (cell::kLinuxCncMaxDio)
// [linuxcnc] record_max_cycles: scans per log file; at most what `smtcal
// monitor` reads in one file (256 MiB) for a fixture of 32 trips.
inline constexpr NumberRange kRecordMaxCycles = Whole(1, 100'000);
// [measure]: the dwell before a reading; a transducer's slope (its size also
// at least 0.1, checked by the reader) and its grooves; the external system's
// first analog output (the set and repetition go on the next two).
inline constexpr NumberRange kMeasureDwellS = Closed(0, 60, "s");
inline constexpr NumberRange kTransducerSlope = Closed(-10, 10, "");
inline constexpr NumberRange kTransducerGrooves = Whole(2, 10'000);
inline constexpr NumberRange kExternalNodeOutput = Whole(0, 61);
// [measure]: how far off and turned the artefact may be put down; its
// certificate's pitch error and that error's uncertainty; the probe's
// holes per direction; the diameters' standard uncertainties.
inline constexpr NumberRange kPlacementMm = Closed(0, 10, "mm");
inline constexpr NumberRange kPlacementDeg = Closed(0, 5, "deg");
inline constexpr NumberRange kArtefactPitchPpm = Closed(-1000, 1000, "ppm");
inline constexpr NumberRange kArtefactPitchUPpm = Closed(0, 1000, "ppm");
inline constexpr NumberRange kProbeHoles = Whole(2, 10'000);
inline constexpr NumberRange kDiameterUMm = Closed(0, 1, "mm");
// smtcal measure: the grid pitch, sets x repetitions per node, the visit a
// program resumes at.
inline constexpr NumberRange kMeasurePitchMm = Closed(0.1, 1000, "mm");
inline constexpr NumberRange kMeasureSets = Whole(1, 100);
inline constexpr NumberRange kMeasureRepetitions = Whole(1, 1000);
inline constexpr NumberRange kMeasureStartVisit = Whole(1, 1e9);
// Columns or rows of a pallet (a feeder bank, a tray) or of an imported
// panel: 10 000 at most, so a count of pick points always fits.
inline constexpr NumberRange kPalletCount = Whole(1, 10'000);
// A pick point of a pallet (a lane of a feeders file's [[map]]), 1-based.
inline constexpr NumberRange kPalletPickPoint = Whole(1, 1e8);

// Options.
// diff --threshold: up to a metre; a gate that never fails is --exit-zero.
inline constexpr NumberRange kDiffThresholdUm = Closed(0, 1e6, "µm");
// simulate --cycles (every placed part's error is kept), --seed (any 64-bit
// value), the fault rates (probabilities) and --dirty-marker-mm.
inline constexpr int kSimMaxCycles = 100'000;
inline constexpr NumberRange kSimCycles = Whole(1, kSimMaxCycles);
inline constexpr NumberRange kSimSeed = Whole(0, 18446744073709551615.0);
inline constexpr NumberRange kProbability = Closed(0, 1, "");
inline constexpr NumberRange kDirtyMarkerMm = Closed(0, 10, "mm");
// monitor --baseline: the accepted scans per fixture that set the charts
// (at least spc/cycle_monitor.h's kMinBaseline, docs/monitor.md); and
// --baseline-from: the scan the baseline starts at.
inline constexpr NumberRange kMonitorBaseline = Whole(10, 1'000'000);
inline constexpr NumberRange kMonitorBaselineFrom = Whole(1, 2'000'000'000);
// table inverse --paper-tolerance: the paper solver's stopping tolerance.
inline constexpr NumberRange kPaperToleranceMm = AboveZero(1, "mm");
// import --vacuum: an output bit.
inline constexpr NumberRange kVacuumOutput = Whole(kVacuumOutputMin, kVacuumOutputMax);
// setup-sheet and import --boards: the boards of a lot (a count of parts
// per slot stays exact in a double); --spares: percent of each slot's parts.
inline constexpr NumberRange kLotBoards = Whole(1, 1e9);
inline constexpr NumberRange kSparesPercent = Closed(0, 100, "%");
// import --panel CxR: at most this many boards.
inline constexpr long kMaxPanelBoards = 10'000;

// --- work bounded by what is asked ----------------------------------------------------
// Each is checked before the work starts, with a message that says what to
// change; none is reached by a real cell or program.

// simulate's true error field outside the tables is scaled to its largest
// magnitude over the robot's reach, sampled every correlation length / 8 in
// x and y: at most this many samples (a 400 x 300 mm reach at the default
// 25 mm is 12 000; 3 million took 1.6 s, docs/simulate.md).
inline constexpr double kTrueFieldStepsPerCorrelation = 8;
inline constexpr double kMaxTrueFieldSamples = 4e6;
// simulate: the placements of a run, cycles x placements per cycle (each is
// simulated in six modes): 10 million take about a minute (docs/simulate.md).
inline constexpr long kMaxSimulatedPlacements = 10'000'000;
// import: the placements of a program (parts x boards of the panel), as the
// compile-time run follows (passes/correction/target_trace.h).
inline constexpr long kMaxImportedPlacements = 5'000'000;
// An error table's x and y lines make nx x ny nodes, each with a row: up to
// this many missing nodes are each reported (about the error limit); more
// are one error, before the grid is laid out (n rows on a diagonal would
// make n^2 nodes to lay out and to search).
inline constexpr std::size_t kMaxMissingNodesListed = 50;

}  // namespace smtcal::limits
