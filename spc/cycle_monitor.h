// What the cycle records of a cell say about it (`smtcal monitor`,
// docs/monitor.md): per fixture, control charts of what every accepted scan
// measured — the board's pose, the distance between the markers, the sensor's
// threshold and the trips' residuals — and the refusals per check; what a
// drift means (the fixture moving, the robot's scale changing, the sensor,
// tables that no longer describe the robot), how soon it reaches a limit,
// and the process figures of what the scans saw.
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

#include "calibration/cell.h"
#include "calibration/cycle_record.h"
#include "spc/control_chart.h"

namespace smtcal {

// One record of the log, with its fixture's name as the log gives it.
struct MonitoredCycle {
  std::string fixture;
  CycleRecord record;
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

struct MonitorOptions {
  std::size_t baseline = 50;  // accepted scans per fixture that set each chart's centre line and sigma
  double cusum_k = 0.5;       // sigmas
  double cusum_h = 10;        // sigmas
  double cusum_clip = 4;      // sigmas
  // In-control alarms per chart with sigma and the centre known, by
  // simulation (docs/monitor.md): the CUSUM about once in 79 000 scans, the
  // EWMA once in 65 000; the guarded estimates of a baseline make each rarer.
  double ewma_lambda = 0.05;
  double ewma_l = 4.1;        // its sigmas
  double refusal_h = 10;      // the refusals' Bernoulli CUSUM: ln(20000)
  double confidence = 0.95;   // of the process figures' intervals
};

struct SeriesResult {
  Quantity quantity = Quantity::kPoseX;
  bool gates = true;           // its CUSUM alarm puts the cell out of control
  std::vector<double> scan;    // the fixture's scan number (1, 2, ... in log order) of each value
  std::vector<double> values;  // in QuantityUnit
  ChartResult chart;
  std::optional<Trend> trend;  // per scan, from the change point on, when the chart alarmed
  // For a chart of a location (the pose, the marker distance, the
  // threshold): the CUSUM's alarm is a verdict only when the mean since the
  // change point differs from the centre line by more than kShiftConfirmed
  // of its standard errors; values that only spread more (a dirty sensor
  // scatters the whole scan) make a CUSUM alarm too, which is not a shift.
  bool shift_confirmed = true;
};
inline constexpr double kShiftConfirmed = 3;

struct RefusalResult {
  ScanCheck check = ScanCheck::kMissingTrip;
  long count = 0;              // scans it refused
  long baseline_count = 0;     // ... among the baseline's scans
  double p0 = 0;               // the in-control rate the CUSUM assumes
  std::optional<long> alarm_scan;  // the scan number at which the refusals' CUSUM alarmed
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

enum class FindingKind { kFixtureMoving, kRobotScale, kSensor, kRefusals };
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
  std::optional<ScanCheck> check;        // refusals: the check
  std::vector<StaleRegion> stale;        // robot scale: the regions to re-measure
};

struct FixtureMonitor {
  std::string name;
  const cell::Fixture* fixture = nullptr;
  long scans = 0;                     // records of it
  long accepted = 0;
  std::optional<double> seconds_per_scan;  // the median time between its records, when they have times
  std::array<SeriesResult, kQuantities> series{};
  bool charted = false;               // enough accepted scans for the baseline
  bool threshold_identifiable = true;  // the scan's layout separates the sensor's threshold from the pose
  std::vector<RefusalResult> refusals;  // every check that refused a scan
  std::optional<double> teach_scale_ppm, teach_threshold_um;  // the teach scan's, for reference
  std::optional<FarCorner> far_corner;
  Eigen::Vector2d trip_centre = Eigen::Vector2d::Zero();  // the mean of the nominal trips, base frame
  std::array<std::optional<ProcessFigures>, kQuantities> process{};
  // Scans the cell recomputes differently from the record (another pose by
  // more than kRecordAgreementMm, or another verdict).
  long disagreements = 0;
  double worst_disagreement_mm = 0;
  long first_disagreement_scan = 0;
  std::vector<Finding> findings;  // the alarms, what they mean
  bool in_control = true;
};

// Recorded poses agree with the cell's recomputation to this (far above the
// record's resolution, 1e-9 mm or finer: docs/monitor.md).
inline constexpr double kRecordAgreementMm = 1e-4;

struct MonitorResult {
  std::vector<FixtureMonitor> fixtures;  // in the cell's order, those the log has
  bool in_control = true;
};

// The log's records (in order) of fixtures of `cell` (matched by the caller).
MonitorResult Monitor(const cell::Cell& cell, const std::vector<MonitoredCycle>& cycles,
                      const MonitorOptions& options);

}  // namespace smtcal
