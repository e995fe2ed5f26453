// Periphery calibration (the paper's section 3.3; docs/periphery.md): trip
// points of the marker scan -> FIX, the checks every scan must pass, and the
// corrections that use FIX.
//
// Flow of one scan (ScanFixture):
//   trips T1..Tn (base frame, as commanded when the sensor tripped)
//   -> every trip present, each within trip_window_mm of where the nominal
//      pose puts it (on the commanded path)
//   -> direct calibration F(t) = t + Delta(t) where a region's table covers
//      the trip (the sensor was really at F(t))
//   -> the estimator: `paper` (line fits p1..p4, crossings S1..S3, Eq. 4),
//      `rigid` (rotation + translation minimising the trips' distances to
//      the marker edge lines) or `rigid-scale` (plus one scale)
//   -> checks on the estimate: |S2 - S1| vs L1, |S3 - S1| vs L2, squareness,
//      line residual, pose against nominal, per-cycle delta FIX_n FIX_{n-1}^-1
//   -> FIX only when every check passed: a failed scan gives no pose.
//
// The C runtime (runtime/c/) implements the same steps with the same fault
// codes; tests keep the two within 1e-9 mm of each other.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "calibration/cell.h"
#include "calibration/fixture_geometry.h"
#include "calibration/inverse_calibration.h"

namespace smtcal {

// The checks of a scan, in the order they run; each is a fault code. The
// numbers are the C runtime's smtcal_scan_status values.
enum class ScanCheck : int {
  kMissingTrip = 1,      // a trip is missing: the sensor did not trip on a leg
  kTripWindow = 2,       // a trip is farther than trip_window_mm from its nominal point
  kDegenerate = 3,       // the trips define no pose (coincident trips, parallel lines)
  kLengthL1 = 4,         // | |S2 - S1| - L1 | > length_tolerance_mm
  kLengthL2 = 5,         // | |S3 - S1| - L2 | > length_tolerance_mm
  kSquareness = 6,       // | angle(S2 - S1, S3 - S1) - 90 deg | > squareness_deg
  kLineResidual = 7,     // a trip lies farther than max_line_residual_mm from its edge line as FIX places it
  kNominalShift = 8,     // |p - p_nominal| > max_shift_mm
  kNominalRotation = 9,  // |angle - angle_nominal| > max_rotation_deg
  kCycleShift = 10,      // |p_n - p_{n-1}| > max_shift_mm
  kCycleRotation = 11,   // |angle_n - angle_{n-1}| > max_rotation_deg
};
inline constexpr std::array<ScanCheck, 11> kScanChecks = {
    ScanCheck::kMissingTrip,   ScanCheck::kTripWindow,      ScanCheck::kDegenerate,   ScanCheck::kLengthL1,
    ScanCheck::kLengthL2,      ScanCheck::kSquareness,      ScanCheck::kLineResidual, ScanCheck::kNominalShift,
    ScanCheck::kNominalRotation, ScanCheck::kCycleShift, ScanCheck::kCycleRotation};
// missing_trip, trip_window, degenerate, length_l1, length_l2, squareness,
// line_residual, nominal_shift, nominal_rotation, cycle_shift, cycle_rotation
std::string_view ScanCheckName(ScanCheck check);
// "mm", "deg", "trips" (missing_trip: how many) or "" (degenerate: 1 = no
// pose): the unit of the check's value and limit.
std::string_view ScanCheckUnit(ScanCheck check);

struct CheckResult {
  ScanCheck check = ScanCheck::kMissingTrip;
  // False when an earlier failure left nothing to check, or (cycle checks)
  // there is no previous scan. A check not evaluated is not a failure.
  bool evaluated = false;
  bool passed = false;
  double value = 0;  // in ScanCheckUnit: the worst case
  double limit = 0;
  int trip = -1;     // the trip it concerns (0-based: the missing one, the worst one), or -1
  std::string why;   // degenerate: what made the trips define no pose
};

// What an estimator gives (before the checks).
struct FixEstimate {
  Eigen::Affine3d fix = Eigen::Affine3d::Identity();
  // S1, S2, S3 in the base frame: FIX (0, 0), FIX (L1, 0), FIX (0, L2). For
  // `paper` these are the crossings of the fitted lines.
  std::array<Eigen::Vector2d, 3> s{};
  double scale = 1;                 // rigid-scale: the board's scale; paper: |n|; rigid: 1
  std::vector<double> residual_mm;  // per trip: distance from its edge's line as FIX places it
};

// The estimator alone, on calibrated trips (one per expected trip, in trip
// order). nullopt when the trips define no pose (two trips of an edge closer
// than kMinTripSeparationMm, lines crossing at less than kMinLineCrossingSin,
// a singular least-squares problem); then `why`, when given, says which.
// Never returns NaN.
std::optional<FixEstimate> EstimateFix(const cell::Fixture& fixture, const std::vector<ExpectedTrip>& expected,
                                       const std::vector<Eigen::Vector2d>& trips, cell::Estimator estimator,
                                       std::string* why = nullptr);

struct ScanOptions {
  cell::Estimator estimator = cell::Estimator::kPaper;
  // Trips are direct-calibrated through the first region whose table's
  // domain holds them; null or empty: no calibration.
  const std::vector<cell::Region>* regions = nullptr;
  std::optional<Eigen::Affine3d> previous;  // FIX_{n-1}: enables the cycle checks
};

struct ScanResult {
  cell::Estimator estimator = cell::Estimator::kPaper;
  std::vector<ExpectedTrip> expected;
  std::vector<std::optional<Eigen::Vector2d>> trips;  // as given
  std::vector<Eigen::Vector2d> nominal;     // where the nominal pose puts each trip
  std::vector<Eigen::Vector2d> calibrated;  // F(trip) where a table covers it, else the trip (present ones)
  std::vector<int> region;                  // per trip: the region that calibrated it, or -1
  std::vector<double> window_mm;            // per present trip: distance from its nominal point
  std::optional<FixEstimate> estimate;      // when the trips allowed one
  std::optional<Eigen::Affine3d> delta;     // FIX_n FIX_{n-1}^-1, with an estimate and a previous scan
  std::vector<CheckResult> checks;          // one per kScanChecks, in order
  std::optional<Eigen::Affine3d> fix;       // the pose: only when no check failed

  bool ok() const { return fix.has_value(); }
  const CheckResult& Check(ScanCheck check) const;
  const CheckResult* FirstFailure() const;  // null when ok
};

// A scan: `trips` holds one entry per expected trip (ExpectedTrips), nullopt
// for a trip the sensor did not make (checked: the size matches).
ScanResult ScanFixture(const cell::Fixture& fixture, const std::vector<std::optional<Eigen::Vector2d>>& trips,
                       const ScanOptions& options);

// FIX_0 for taught points: the cell's teach-time scan (teach_trips_mm, in
// trip order) through the cell's regions with the fixture's estimator.
// Check result.fix (nullopt when a check failed: DescribeFailure says why).
ScanResult TeachScan(const cell::Cell& cell, const cell::Fixture& fixture);

// One sentence on a failed check, with its value and limit, e.g.
// "|S2 - S1| = 190.25 mm is 0.25 mm from l1_mm = 190, more than length_tolerance_mm = 0.1".
std::string DescribeCheck(const CheckResult& check, const cell::Fixture& fixture);
// The first failure's description prefixed by its code ("length_l1: ..."), or "".
std::string DescribeFailure(const ScanResult& result, const cell::Fixture& fixture);

// --- corrections -------------------------------------------------------------
// Poses as homogeneous matrices (x, y, z and the rotation u about z).

// Eq. 6: ROBOT_n = FIX_n . FIXPOS_0 for a point programmed off-line in the
// fixture frame: the position the part must really reach this cycle.
Eigen::Affine3d OfflineTarget(const Eigen::Affine3d& fix_n, const Eigen::Affine3d& fixpos0);
// Eq. 7, in actual space: FIXPOS_0 = FIX_0^-1 . F(ROBOT_0), where F(ROBOT_0)
// is where the robot really was when the point was taught.
Eigen::Affine3d TaughtFixturePosition(const Eigen::Affine3d& fix0, const Eigen::Affine3d& reached0);
// Eq. 9 in closed form: FIX_n . FIX_0^-1 . F(ROBOT_0). Equal to the paper's
// recursion ROBOT_n = FIX_n . FIX_{n-1}^-1 . ROBOT_{n-1} (a test runs 1000
// cycles of it), without accumulating its rounding.
Eigen::Affine3d TaughtTarget(const Eigen::Affine3d& fix_n, const Eigen::Affine3d& fix0,
                             const Eigen::Affine3d& reached0);
// A pose (x, y, z mm, u deg) as a homogeneous matrix, and back (u from the
// x axis: atan2).
Eigen::Affine3d PoseMatrix(double x_mm, double y_mm, double z_mm, double u_deg);
std::array<double, 4> PoseValues(const Eigen::Affine3d& pose);

// The robot calibration after FIX: the command that lands on a required
// base-frame position, through the region whose bounds hold it (the C
// runtime's smtcal_correct_point does the same).
struct CorrectedPoint {
  Eigen::Vector2d required = Eigen::Vector2d::Zero();  // FIX_n . FIXPOS_0: where the part must go
  Eigen::Vector2d command = Eigen::Vector2d::Zero();   // F^-1(required): what to command
  int region = -1;  // index into the regions whose bounds hold `required`; -1: none (command = required)
  Solution solution;  // the inverse's status, residual and iterations (kUncorrected when no region)
};

class PointCorrector {
 public:
  // The regions' tables must be valid (the cell loader validates them).
  explicit PointCorrector(const std::vector<cell::Region>& regions);

  // The region whose bounds hold the point (first in cell order), or -1.
  int RegionAt(const Eigen::Vector2d& base) const;
  // F^-1 of a required base position through its region.
  CorrectedPoint Invert(const Eigen::Vector2d& required) const;
  // FIX_n . FIXPOS_0, then F^-1.
  CorrectedPoint Correct(const Eigen::Affine3d& fix_n, const Eigen::Vector2d& fixpos0) const;
  // Direct calibration of a command, as DirectCalibrateInCell does, through
  // the tables this corrector holds (no maps built per call).
  Eigen::Vector2d Forward(const Eigen::Vector2d& commanded, int* region = nullptr) const;

 private:
  const std::vector<cell::Region>& regions_;
  std::vector<InverseSolver> solvers_;
};

// Direct calibration of a commanded base point through the first region
// whose table's domain holds it; `region` gets its index or -1 (the point
// is returned unchanged).
Eigen::Vector2d DirectCalibrateInCell(const std::vector<cell::Region>& regions, const Eigen::Vector2d& commanded,
                                      int* region = nullptr);

// Where the controller records each trip of a scan of a board at `fix`, for
// a perfect sensor and a robot that moves as the cell's tables say: the
// command c with F(c) = the trip's true position (DirectCalibrateInCell
// inverted by fixed-point steps), in trip order. With trips inside tables
// these, not NominalTrips, are what gives FIX = `fix` after calibration.
std::vector<Eigen::Vector2d> CommandedTrips(const cell::Fixture& fixture, const std::vector<cell::Region>& regions,
                                            const Eigen::Affine3d& fix);

// The scan as a source of placement error (the sensor, the repeatability and
// the latency at the trips, through the estimator): calibration/placement_budget.h.

}  // namespace smtcal
