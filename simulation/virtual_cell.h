// The virtual cell (docs/simulate.md): runs a compiled program's cycles on a
// simulated robot with true errors (simulation/true_field.h) and measures where
// its parts really land, under six ways of correcting them, on the same
// random draws.
//
// Per cycle (each Cycle statement of the program, N times, in order):
//   board: a true pose FIX_true drawn from the truth's distribution
//   scan:  the commanded V legs at the nominal pose; the robot really moves
//          along F_true(leg) + repeatability; a trip where that path crosses
//          the true marker edge, +- the sensor's accuracy, latched up to one
//          servo period late (a uniform draw); none if it does not cross
//   modes: each turns the same trips (periphery modes) and the compiled
//          targets into commands; a failed scan check stops the cycle (in
//          the paper's modes only a missing trip or no pose: the paper's
//          cell had no checks; what the others would have stopped is counted)
//   place: the robot lands at F_true(command) + repeatability; the error is
//          the distance to where the part truly belongs (FIX_true . f)
// The cycle's trace is the compiler's (CompileState::cycle_traces): branches
// on inputs follow the path where every input condition is false.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "calibration/capability.h"
#include "calibration/cycle_record.h"
#include "passes/correction/compile_state.h"
#include "simulation/true_field.h"

namespace smtcal {

enum class SimMode : int {
  kNone = 0,       // commands as written: nominal board pose, no tables
  kMeanOffset,     // the task origin shifted by the region's table means (the paper's first step)
  kTablesOnly,     // F^-1 through the tables at the nominal board pose (no periphery calibration)
  kPeripheryOnly,  // the paper's production cell: the fixture's estimator on raw trips, no checks, no tables
  kPaper,          // the paper: the same scan + tables, taught points by Eq. 9 in commanded space
  kImproved,       // ours: direct-calibrated trips, least squares, Eq. 7 in actual space + tables
};
inline constexpr std::array<SimMode, 6> kSimModes = {SimMode::kNone,          SimMode::kMeanOffset,
                                                     SimMode::kTablesOnly,    SimMode::kPeripheryOnly,
                                                     SimMode::kPaper,         SimMode::kImproved};
std::string_view SimModeName(SimMode mode);         // none, mean-offset, tables, periphery, paper, improved
std::string_view SimModeDescription(SimMode mode);  // one line for reports
bool UsesPeriphery(SimMode mode);
// Whether a mode's cycles stop on every failed scan check of the cell
// (improved, as the compiled program does), or run as the paper's cell did,
// which had no checks (periphery, paper): only a missing trip or trips that
// define no pose (no line to fit, no crossing) stop its cycle; the cell's
// other checks are still evaluated and counted (ModeResult::would_stop).
bool UsesCellChecks(SimMode mode);

struct SimOptions {
  int cycles = 1000;        // executions of each Cycle statement
  std::uint64_t seed = 1;
  // Fault injection: per cycle, the probability of each fault.
  double missed_trip_rate = 0;    // one trip the sensor does not make
  double dirty_marker_rate = 0;   // one trip displaced along its leg by +-dirty_marker_mm
  double dirty_marker_mm = 0.5;
  double board_beyond_rate = 0;   // the board shifted beyond max_shift_mm (by 0.1..1 mm more)
  std::size_t scatter_points = 2000;  // per mode, kept for the picture: every k-th planned placement
  // Keep the record of every scan of the improved mode (the runtime's), as
  // the controller would log it (SimResult::records).
  bool record = false;
};

struct ModeResult {
  SimMode mode = SimMode::kNone;
  int cycles = 0;             // cycles started
  int faults = 0;             // cycles stopped by a failed scan check
  std::map<std::string, int> fault_checks;  // by check name
  // Modes without the cell's checks (UsesCellChecks false): the cycles they
  // ran although the cell's checks would have stopped them, by the first
  // check that fails.
  int would_stop = 0;
  std::map<std::string, int> would_stop_checks;
  long placements = 0;        // parts placed
  long within = 0;            // within their region's tolerance
  int faults_injected = 0;      // stopped cycles among those with an injected fault
  long misplaced_injected = 0;  // out of tolerance in a cycle with an injected fault
  std::vector<double> errors_um;             // every placed part's error, in placing order
  std::vector<Eigen::Vector2d> scatter_um;   // error vectors of every k-th planned placement (at most scatter_points)
  double scan_share = 0;      // the scan's share of the cycle time (0 without periphery)
  // Process figures of the placed parts: per region of the cell (in cell
  // order; regions nothing was placed in stay empty) and overall.
  std::vector<SampleCapability> by_region;
  SampleCapability overall;
};

struct SimResult {
  SimOptions options;
  int cycles = 0;                // cycles run (every Cycle statement, N times)
  long placements_planned = 0;   // parts the cycles would place
  int injected_missed = 0, injected_dirty = 0, injected_beyond = 0;
  int injected_cycles = 0;       // cycles with at least one injected fault
  int unknown_targets = 0;       // placements depending on run-time values: not simulated
  double tolerance_mm = 0;       // the smallest tolerance of a placement's region
  std::string fixture_estimator; // the improved mode's estimator
  std::string paper_estimator;    // the paper's modes': the first fixture's, as the cell declares it
  double uncalibrated_accuracy_mm = 0;  // the true field's size outside the tables
  bool accuracy_assumed = false;        // not declared: kAssumedUncalibratedAccuracyMm
  std::vector<std::string> regions;     // the cell's region names, for by_region
  std::vector<ModeResult> modes; // in kSimModes order
  // With SimOptions::record: the improved mode's scans, in the order they
  // ran, numbered per fixture from 1; the fixture is its index in the cell,
  // the time the cycle-time estimate's clock at the end of the scan.
  std::vector<CycleRecord> records;
};

// The compiled program must have passed the correction passes without error.
SimResult Simulate(const CompileState& state, const TruthSpec& truth, const SimOptions& options);

// The placements a run plans: the known placements of every Cycle's trace,
// every cycle. Each keeps its error in every mode (ModeResult::errors_um),
// and the report sorts a copy of one mode's: kSimBytesPerPlacement bytes of
// memory per planned placement, which a caller can check before running.
long PlannedPlacements(const CompileState& state, const SimOptions& options);
inline constexpr std::size_t kSimBytesPerPlacement = sizeof(double) * (kSimModes.size() + 1);

// Nearest-rank percentile (q in [0, 1]) of sorted values; 0 when empty.
double Percentile(const std::vector<double>& sorted, double q);

}  // namespace smtcal
