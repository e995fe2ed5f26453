// What the cycle records of a cell say about it (`smtcal monitor`,
// docs/monitor.md): per fixture, control charts of what every accepted scan
// measured — the board's pose, the distance between the markers, the sensor's
// threshold and the trips' residuals — and of the refusals, per check and
// all together; what a drift means (the robot's scale changing, the sensor,
// the fixture moving, tables that no longer describe the robot), in order of
// cause, how soon it reaches a limit, and the process figures of what the
// scans saw.
//
// Phase I and Phase II: the charts judge against a baseline — a window of
// the logs' accepted scans (estimated robustly, spc/baseline.h: outliers
// left out and said, a drifting window refused with the scans to exclude),
// or one stored before (`--baseline-out`, `--baseline-in`).
//
// Every scan is also recomputed from its recorded trips with the cell
// (ScanFixture): a record whose pose or verdict differs from the cell's
// was written with other tables or fixture data.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/cell.h"
#include "calibration/cycle_record.h"
#include "spc/baseline.h"
#include "spc/bernoulli_cusum.h"
#include "spc/control_chart.h"

namespace smtcal {

// One record of the logs, with its fixture's name as the log gives it.
struct MonitoredCycle {
  std::string fixture;
  CycleRecord record;
  bool restart = false;  // the first record after a program start: the runtime had no previous pose
  std::size_t run = 0;   // the log's run (begin line) it belongs to, counted over the logs
  SourceRange where;     // its cycle line
};

// What each accepted scan measured, charted.
enum class Quantity : int {
  kPoseX = 0,        // the board origin's x minus the nominal, µm
  kPoseY,            // ... y, µm
  kPoseAngle,        // the board's angle minus the nominal, millidegrees
  kMarkerScale,      // the distance between the markers against L1, L2: (scale - 1), ppm
  kSensorThreshold,  // how much smaller the markers appear than drawn (trips inside their edges), µm
  kResidualRms,      // the rms distance of the trips from their edge lines as the runtime's pose places them, µm
  kResidualMax,      // the largest (check 7, line_residual), µm
};
inline constexpr std::size_t kQuantities = 7;
std::string_view QuantityName(Quantity quantity);   // pose_x, pose_y, pose_angle, marker_scale, ...
std::string_view QuantityTitle(Quantity quantity);  // "board pose x", ...
std::string_view QuantityUnit(Quantity quantity);   // "µm", "mdeg", "ppm"
bool QuantityGates(Quantity quantity);              // its alarm puts the cell out of control (all but the largest residual)
std::optional<Quantity> QuantityNamed(std::string_view name);

// The fewest accepted scans a baseline may have (docs/monitor.md): below it
// the guarded sigma's bound grows past 1.65 times the estimate and the
// centre's uncertainty past 0.52 sigma, and the chart no longer sees a step
// of 1.7 sigma (a baseline of 50 sees 0.9 sigma).
inline constexpr std::size_t kMinBaseline = 10;

struct MonitorOptions {
  std::size_t baseline = 50;  // accepted scans per fixture in the baseline window
  long baseline_from = 1;     // the window's first scan (per fixture, in the order of the logs)
  double cusum_k = 0.5;       // sigmas
  double cusum_h = 10;        // sigmas
  double cusum_clip = 4;      // sigmas
  // In-control alarms per chart with sigma and the centre known, measured
  // (docs/monitor.md, "Run lengths"): the CUSUM about once in 70 000 scans,
  // the EWMA once in 59 000; the guarded estimates of a baseline make each
  // rarer.
  double ewma_lambda = 0.05;
  double ewma_l = 4.1;        // its sigmas
  double confidence = 0.95;   // of the process figures' intervals
};

// The reference a fixture's charts judge against: Phase I's result (what
// `--baseline-out` writes) or a stored one (`--baseline-in`).
struct FixtureBaseline {
  std::string fixture;
  long first_scan = 0, last_scan = 0;     // the window, in the scans of the logs it came from
  std::string first_record, last_record;  // where they are: "LOG:LINE"
  std::array<std::optional<ChartReference>, kQuantities> charts{};
  long scans = 0;                                  // records in the window (the refusal rates)
  std::array<long, kScanChecks.size()> refused{};  // per check
  long refused_any = 0;
};
struct BaselineFile {
  std::string path, sha256;  // a file of the cell (the cell file, its tables)
};
struct MonitorBaseline {
  std::string cell;                 // its name
  std::vector<BaselineFile> files;  // the cell file and its tables, with their SHA-256
  std::vector<std::string> logs;    // the logs it came from, as given
  std::vector<FixtureBaseline> fixtures;
};

struct SeriesResult {
  Quantity quantity = Quantity::kPoseX;
  bool gates = true;           // its CUSUM alarm puts the cell out of control
  std::vector<double> scan;    // the fixture's scan number (1, 2, ... in log order) of each value
  std::vector<double> values;  // in QuantityUnit
  bool charted = false;        // it has a reference and values to judge
  ChartResult chart;
  std::optional<Trend> trend;  // per scan, from the change point on, when the chart alarmed
  // For a chart of a location (the pose, the marker distance, the
  // threshold): the CUSUM's alarm is a verdict only when the mean since the
  // change point differs from the centre line by more than kShiftConfirmed
  // of its standard errors; values that only spread more (a dirty sensor
  // scatters the whole scan) make a CUSUM alarm too, which is not a shift.
  bool shift_confirmed = true;
  std::vector<long> outliers;  // Phase I: scans of the window left out of its reference
};
inline constexpr double kShiftConfirmed = 3;

struct RefusalResult {
  std::optional<ScanCheck> check;  // none: every refusal together
  long count = 0;                  // scans it refused
  long baseline_count = 0;         // ... in the baseline's window (or the stored baseline's)
  long baseline_scans = 0;         // the window's scans
  BernoulliCusumDesign design;     // from the baseline's rate, at least kRefusalRateFloor
  BernoulliCusumRun run;           // over every scan in the order of the logs
  std::optional<long> alarm_scan;  // the scan number at which it alarmed
  long change_scan = 0;            // where the rise began (after its sum was last 0)
  std::vector<long> at_scans;      // the scan numbers it refused
};

// Where a change of the robot's scale hurts most: the point on the board,
// inside a calibrated region, whose margin (tolerance - budget at 4 sigma)
// a scale error eats first through the fixture's estimator.
struct FarCorner {
  Eigen::Vector2d in_fixture = Eigen::Vector2d::Zero();
  Eigen::Vector2d in_base = Eigen::Vector2d::Zero();
  std::string region;
  double budget_mm = 0, tolerance_mm = 0;
  double um_per_ppm = 0;  // the placement error there per ppm of scale error
  double MarginMm() const { return tolerance_mm - budget_mm; }
};

// A region whose table a scale error moves by more than its stated noise.
struct StaleRegion {
  std::string region;
  double drift_um = 0;   // the scale error times its distance from the markers' centre
  double noise_um = 0;   // 4 standard errors of its table
};

// A pose chart's drift that the robot's scale explains: a robot whose scale
// changes about its origin moves the board's measured origin as well
// (FixtureMonitor::origin_um_per_ppm).
struct ExplainedDrift {
  Quantity quantity = Quantity::kPoseX;
  double observed_per_100 = 0;   // the pose chart's own trend, µm per 100 scans
  double explained_per_100 = 0;  // the scale's trend's share of it
  bool alarms_without = false;   // the pose chart, corrected for the scale, still alarms
};

enum class FindingKind { kRobotScale, kSensor, kFixtureMoving, kRefusals };
struct Finding {
  FindingKind kind = FindingKind::kFixtureMoving;
  std::vector<Quantity> charts;  // the charts that alarmed
  long alarm_scan = 0;           // the first alarm
  long change_scan = 0;          // where the drift most likely began
  // The trend in the finding's own measure (fixture: distance of the origin
  // from nominal, µm; robot scale: the placement error at the far corner,
  // µm; sensor: the largest residual, µm), now and per scan, and the limit
  // it runs into (max_shift_mm, the far corner's margin, max_line_residual_mm).
  double now = 0, per_scan = 0, limit = 0;
  std::optional<double> scans_to_limit;  // at this rate; none when it does not approach the limit
  std::optional<ScanCheck> check;        // refusals: the check (none: every refusal together)
  std::vector<StaleRegion> stale;        // robot scale: the regions to re-measure
  std::vector<ExplainedDrift> explains;  // robot scale: the pose drifts it explains
};

struct FixtureMonitor {
  std::string name;
  const cell::Fixture* fixture = nullptr;
  long scans = 0;                     // records of it
  long accepted = 0;
  std::optional<double> seconds_per_scan;  // the median time between its records within a run, when they have times
  std::vector<std::size_t> records;   // per scan (1-based scan n at n - 1): its index into the monitored cycles
  std::vector<long> restarts;         // scans that start a new program run (the controller restarted)
  std::array<SeriesResult, kQuantities> series{};
  bool charted = false;               // a baseline was found and judged against
  FixtureBaseline baseline;           // what the charts judged against
  bool baseline_stored = false;       // from --baseline-in
  bool threshold_identifiable = true;  // the scan's layout separates the sensor's threshold from the pose
  std::vector<RefusalResult> refusals;  // every refusal together first, then each check that refused a scan
  std::optional<double> teach_scale_ppm, teach_threshold_um;  // the teach scan's, for reference
  std::optional<FarCorner> far_corner;
  Eigen::Vector2d trip_centre = Eigen::Vector2d::Zero();  // the mean of the nominal trips, base frame
  Eigen::Vector2d origin_mm = Eigen::Vector2d::Zero();    // the board's nominal origin (S1), base frame
  // With a robot scale finding: how far the board's measured origin moves
  // (µm, base frame) per ppm the marker distance changes, when the robot's
  // scale changes about its origin (through the fixture's estimator).
  std::optional<Eigen::Vector2d> origin_um_per_ppm;
  std::array<std::optional<ProcessFigures>, kQuantities> process{};
  // Scans the cell recomputes differently from the record (another pose by
  // more than kRecordAgreementMm, or another verdict).
  long disagreements = 0;
  double worst_disagreement_mm = 0;
  long first_disagreement_scan = 0;
  std::vector<Finding> findings;  // the alarms, what they mean, causes first
  bool in_control = true;
};

// Recorded poses agree with the cell's recomputation to this (far above the
// record's resolution, 1e-9 mm or finer: docs/monitor.md).
inline constexpr double kRecordAgreementMm = 1e-4;

struct MonitorResult {
  std::vector<FixtureMonitor> fixtures;  // in the cell's order, those the logs have
  bool in_control = true;
  bool judged = false;  // every fixture had a baseline (otherwise errors were reported)
};

// The records (in order) of fixtures of `cell` (matched by the caller),
// judged against the baseline window of `options` or against `stored`.
// Reports at the records' lines what makes them impossible to judge (values
// outside the robot's travel, a baseline too small or drifting; errors) and
// what a reader should know (outliers left out of a baseline, records
// another cell's tables wrote; warnings).
MonitorResult Monitor(const cell::Cell& cell, const std::vector<MonitoredCycle>& cycles, const MonitorOptions& options,
                      const MonitorBaseline* stored, Diagnostics& diags);

// The baseline a result judged against, to store (`--baseline-out`).
MonitorBaseline BaselineOf(const MonitorResult& result, const cell::Cell& cell, const std::vector<std::string>& logs);

}  // namespace smtcal
