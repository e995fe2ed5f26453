// `smtcal scan report`: the design of a fixture's marker scan at a glance
// (docs/periphery.md, "The scan's design"): its time per cycle, its capture
// range against the fixture's limits, the pose's covariance per estimator
// from the sensor, the robot's repeatability and the latch latency, the
// worst placement error the scan adds on the board (or at a program's
// placements), what limits each, and a better layout where the drawn one is
// weak. The picture: the board in its own frame with the markers' edges, the
// scan paths, the nominal trips and the scan's error ellipses at the
// placements, each marker also enlarged.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calibration/cell.h"
#include "calibration/scan_plan.h"

namespace smtcal {

// A point the scan's error is shown at: a placement of a program on the
// fixture (its text), or a point of the board.
struct ScanReportPoint {
  std::string name;
  Eigen::Vector2d in_fixture = Eigen::Vector2d::Zero();
};

// Where a point is among the calibrated regions at the fixture's nominal
// pose: the region holding it ("" in none) and its tolerance (0 in none).
struct ScanPointRegion {
  std::string region;
  double tolerance_mm = 0;
};

struct ScanReportEstimator {
  cell::Estimator estimator = cell::Estimator::kRigid;
  bool defined = false;        // the nominal trips give this estimator a pose
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();  // 1 sigma of the pose: x mm, y mm, angle deg
  double worst_mm = 0;         // the scan's part of a placement's budget at 4 sigma, worst over the points
  std::string worst_at;        // the point it is worst at
  // The same part as a share of each point's tolerance (its region's), the
  // largest over the points in a region, and that point; share < 0 when no
  // point is in a region.
  double worst_share = -1;
  std::string worst_share_at;
};

// A change to the layout and what it would buy: the fixture's estimator's
// worst share of the tolerance after it (the report's figure before).
struct ScanSuggestion {
  std::string change;
  double share_before = 0, share_after = 0;
};

struct ScanReport {
  std::string cell_name;
  const cell::Fixture* fixture = nullptr;
  ScanTiming timing;                // every leg searched in full: the first cycle's scan, and a fallback's
  ScanTiming predicted;             // every trip where the last scan predicts it (= timing without prediction)
  ScanTiming floor;                 // what no scan of these paths goes below (ScanFloor)
  bool timed_from_program = false;  // the scan starts where the program's cycle ends
  CaptureRange capture;
  double latency_mm = 0;            // how far past its edge a trip can be latched
  std::vector<ScanReportEstimator> estimators;  // paper, rigid, rigid-scale
  std::vector<ScanReportPoint> points;
  std::vector<ScanPointRegion> point_regions;  // per point
  // The scan's error at each point with the fixture's estimator: the mean
  // (the latency) and the 4-sigma ellipse's covariance (mm^2).
  std::vector<Eigen::Vector2d> point_mean_mm;
  std::vector<Eigen::Matrix2d> point_covariance_mm2;
  std::vector<double> point_budget_mm;
  std::vector<double> trip_edge_margin_mm;  // per trip: its distance from the nearer end of its edge
  std::vector<double> trip_angle_deg;       // per trip: the angle between its leg and its edge
  // Per trip: the region whose table calibrates it whatever pose the checks
  // accept (TripRegions), "" for a trip outside every table.
  std::vector<std::string> trip_table;
  std::vector<std::string> suggestions;
  // Changes that take at least kWorthwhileShareCut of the fixture's
  // estimator's worst share of the tolerance off (also in `suggestions`):
  // calibrating a region under uncalibrated trips, another estimator, a
  // longer baseline between the markers.
  std::vector<ScanSuggestion> tolerance_suggestions;
};

// A change is suggested for the tolerance when it takes at least this part
// of the worst share off (0.75 -> 0.675 or less).
inline constexpr double kWorthwhileShareCut = 0.1;

// The report of `fixture` of `cell`. `points`: where to show the scan's
// error (empty: a 5 x 3 grid over the board, S1 to S2 and S3); `from`:
// where the robot stands when the scan starts (a program's cycle end), or
// unknown.
ScanReport MakeScanReport(const cell::Cell& cell, const cell::Fixture& fixture, std::vector<ScanReportPoint> points,
                          const std::optional<ScanPoint>& from);

std::string ScanReportText(const ScanReport& report);
std::string ScanReportJson(const ScanReport& report);
std::string ScanReportSvg(const ScanReport& report);

}  // namespace smtcal
