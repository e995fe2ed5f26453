// What can move a placement away from where it must go, as the cell states
// it, and how far (docs/compile.md, "The tolerance budget"). `smtcal verify`
// checks every Pick and Place against its region's tolerance with this; the
// virtual cell (simulation/) draws the same sources, so the two can be
// compared.
//
// The error e = (where the part lands) - (where it belongs) is a sum of
// independent sources. Each contributes
//   - a known mean (the trip latency: a trip is always late, never early),
//   - an unknown systematic part known only by a bound (the inverse's
//     residual; the robot's error at a trip no table corrects; how far the
//     robot's error departs from the tables' interpolation between their
//     nodes, at the placement and at the trips),
//   - a random part with a covariance (repeatability, the sensor, the
//     tables' own measurement noise, the latency's spread, the noise of the
//     check points that show the departure from the interpolation).
// Random parts come from bounded uniform draws (the cell's "±" figures) or
// from the tables' standard errors. Through the fixture's estimator a trip's
// error reaches a fixture point linearly: the sensitivity G_k(f) of the point
// to trip k moving across its edge (a move along the edge changes no fit).
//
// The budget is |mean| + bound + kBudgetSigmas * sigma, with sigma the
// largest standard deviation of the random part in any direction: the
// industry's "at 4 sigma" (with the random part normal, a placement lands
// beyond its budget with probability at most e^-8 = 0.034 %). `worst_mm` is a
// hard bound instead: every uniform draw at its extreme and every normal one
// at 4 sigma, all in the same direction.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "calibration/cell.h"
#include "calibration/fixture_geometry.h"

namespace smtcal {

// The budget's random part at this many standard deviations.
inline constexpr double kBudgetSigmas = 4;

// One source's part of a placement's error.
struct ErrorShare {
  Eigen::Vector2d mean_mm = Eigen::Vector2d::Zero();
  double bound_mm = 0;
  Eigen::Matrix2d covariance_mm2 = Eigen::Matrix2d::Zero();
  double worst_mm = 0;

  // The largest standard deviation in any direction.
  double SigmaMm() const;
  // |mean| + bound + kBudgetSigmas * sigma.
  double BudgetMm() const;
  ErrorShare& operator+=(const ErrorShare& other);
};

enum class ErrorSource : int {
  kResidual = 0,       // the inverse calibration's residual |F(n) - a|
  kRepeatability,      // the robot's repeatability at the placement
  kTable,              // the measurement noise of the target region's table
  kInterpolation,      // the interpolation error between table nodes: the region's and the trips' tables
  kSensor,             // the marker sensor's accuracy, through the estimator
  kScanRepeatability,  // the robot's repeatability at the trips, through the estimator
  kLatency,            // the controller's probe latch: trips late along their legs
  kTripTables,         // the measurement noise of the tables that calibrate the trips
  kUncalibratedTrips,  // the robot's own error at trips no table calibrates
};
inline constexpr std::size_t kErrorSources = 9;
// residual, repeatability, table, interpolation, sensor, scan_repeatability,
// latency, trip_tables, uncalibrated_trips
std::string_view ErrorSourceName(ErrorSource source);
// Words for messages: "the robot's repeatability", ...
std::string_view ErrorSourceDescription(ErrorSource source);

struct ErrorBudget {
  std::array<ErrorShare, kErrorSources> shares{};
  // False when a source cannot be bounded from what the cell declares (a trip
  // outside every table and no robot.uncalibrated_accuracy_mm): the budget
  // is then unknown, never small.
  bool bounded = true;

  ErrorShare& operator[](ErrorSource source) { return shares[static_cast<std::size_t>(source)]; }
  const ErrorShare& operator[](ErrorSource source) const { return shares[static_cast<std::size_t>(source)]; }
  ErrorShare Total() const;
  double BudgetMm() const { return Total().BudgetMm(); }
  // The source whose share alone is the largest budget.
  ErrorSource Largest() const;
};

// The standard error of a table's node means, per axis (stddev / sqrt(count),
// the largest over the axis's nodes). A node without stddev and count says
// nothing about its noise: it counts as one measurement with the robot's
// repeatability as its spread.
Eigen::Vector2d TableStandardErrorMm(const ErrorTable& table, double repeatability_mm);

// The largest |sum_k s_k v_k| over the signs s_k = +-1: the largest length
// a sum of terms, each anywhere between -v_k and +v_k, can reach. Exact (one
// sign pattern per arc of directions between the terms' normals).
double WorstCaseSumMm(const std::vector<Eigen::Vector2d>& terms);

// The interpolation part of a placement in a region, on its own: the bound
// |(E_x, E_y)| of the departure (a bound: systematic), and the noise of the
// check points that show it, diag(s_x^2, s_y^2) (random)
// (calibration/interpolation_error.h).
ErrorShare RegionInterpolationShare(const InterpolationEstimate& estimate);

// A placement corrected through a region's table with no fixture (a static
// target): the residual, the repeatability, the table's noise and its
// interpolation error (RegionInterpolationShare). `region` may be null (then
// only the repeatability).
ErrorBudget StaticBudget(const cell::Cell& cell, const cell::Region* region, double residual_mm);
// The same with the region's TableStandardErrorMm given: a compile asks for
// every target's budget, so the tables' noise is found once (RegionTableNoise).
ErrorBudget StaticBudget(const cell::Cell& cell, const cell::Region* region, double residual_mm,
                         const Eigen::Vector2d& table_se);

// TableStandardErrorMm of every region of the cell, in the cell's order.
std::vector<Eigen::Vector2d> RegionTableNoise(const cell::Cell& cell);

// Which region calibrates each trip of the fixture's scan whatever pose the
// checks let through: the first region whose table domain holds the trip's
// whole window on its leg (TripWindows); -1 when none does.
std::vector<int> TripRegions(const cell::Fixture& fixture, const std::vector<cell::Region>& regions);

// The fixture's scan as a source of error at its points: the sensitivities of
// a fixture point to each trip (central differences of the fixture's
// estimator at the nominal pose) and what each trip's error is made of.
class FixtureErrorModel {
 public:
  // `region_table_se`: the cell's RegionTableNoise when the caller has it
  // (a compile finds it once for all its budgets); found here when empty.
  FixtureErrorModel(const cell::Cell& cell, const cell::Fixture& fixture,
                    std::vector<Eigen::Vector2d> region_table_se = {});

  // False when the fixture's nominal trips define no pose (then every budget
  // is unbounded).
  bool defined() const { return defined_; }
  const std::vector<int>& trip_regions() const { return trip_regions_; }
  // Per trip: its calibrating table's departure across its edge over its
  // window, a bound and its noise (0 for a trip no table calibrates).
  const std::vector<LocalInterpolation>& trip_interpolation() const { return trip_interpolation_; }
  // Trips (0-based) no table calibrates.
  std::vector<std::size_t> UncalibratedTrips() const;

  // The whole budget of a placement at `point_in_fixture`, corrected through
  // `region` (may be null) with that residual.
  ErrorBudget At(const Eigen::Vector2d& point_in_fixture, const cell::Region* region, double residual_mm) const;

  // The budget's `interpolation` part of that placement (At's): the
  // departures from the tables' interpolation of the target's region (may be
  // null: then the trips' alone) and of every calibrated trip, each
  // anywhere within its bound (for a trip: the bounds of the cells its
  // window meets, across its edge), combined exactly through the
  // estimator's sensitivities (WorstCaseSumMm); the check points' noise as
  // a random part, per table in its worst direction. Without a region it is
  // the part through the trips (docs/compile.md, "The tolerance budget").
  ErrorShare Interpolation(const Eigen::Vector2d& point_in_fixture, const cell::Region* region) const;

  // How a fixture point moves with each trip moving across its edge (mm per
  // mm): the sensitivities g_k(f) of the estimator at the nominal pose.
  std::vector<Eigen::Vector2d> TripGains(const Eigen::Vector2d& point_in_fixture) const;

  // The covariance of the scanned pose (origin x, y in mm; angle in rad)
  // from the random part of every trip's error: the sensor, the robot's
  // repeatability, the latch latency's spread and the calibrating tables'
  // noise (the latency's mean and the bounds are not in it). Requires defined().
  Eigen::Matrix3d PoseCovariance() const;

 private:
  const cell::Cell& cell_;
  double sensor_accuracy_mm_ = 0;
  double latency_mm_ = 0;  // the latch feed * servo_period_s: how late a trip can be, along its leg
  bool defined_ = false;
  std::vector<int> trip_regions_;
  // Per trip: d(linear part)/de and d(translation)/de, e across the edge.
  std::vector<Eigen::Matrix2d> d_linear_;
  std::vector<Eigen::Vector2d> d_origin_;
  std::vector<double> leg_across_;    // |leg direction . edge normal|: the latency's share across the edge
  std::vector<double> trip_table_se_;  // the calibrating table's standard error across the edge; 0 if none
  // The calibrating table's departure from its interpolation across the
  // edge, over the trip's window (a bound and its check points' noise); 0 if none.
  std::vector<LocalInterpolation> trip_interpolation_;
  std::vector<Eigen::Vector2d> region_table_se_;  // RegionTableNoise of the cell
  Eigen::Vector2d nominal_x_axis_ = Eigen::Vector2d::UnitX();  // n of the nominal FIX
};

// The probability that a placement with error mean `mean_mm` and a normal
// random part of covariance `covariance_mm2` lands farther than
// `tolerance_mm` from where it belongs (a circle). Accurate to a relative
// 1e-6 or 1e-15 absolute.
double OutsideProbability(const Eigen::Vector2d& mean_mm, const Eigen::Matrix2d& covariance_mm2,
                          double tolerance_mm);

}  // namespace smtcal
