// The placement error budget (calibration/placement_budget.h).
#include "calibration/placement_budget.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>

#include <Eigen/Eigenvalues>

#include "calibration/fixture_estimation.h"
#include "calibration/tolerances.h"

namespace smtcal {
namespace {

// A uniform draw in [-a, a] has variance a^2 / 3.
double UniformVariance(double half_width) { return half_width * half_width / 3; }

Eigen::Matrix2d Outer(const Eigen::Vector2d& v) { return v * v.transpose(); }

bool WindowInDomain(const TripWindow& window, const Rect& domain) {
  auto inside = [&](const Eigen::Vector2d& p) {
    return p.x() >= domain.x0 && p.x() <= domain.x1 && p.y() >= domain.y0 && p.y() <= domain.y1;
  };
  return inside(window.from) && inside(window.to) && inside(window.nominal);
}

// The departure from the tables' interpolation across a trip's edge
// (`across`, a unit vector), wherever the trip may fall in its window: the
// largest cell bound of each axis table over the window, |n_x| E_x + |n_y|
// E_y, and the noise of those bounds, sqrt(n_x^2 s_x^2 + n_y^2 s_y^2) (the
// two axis tables are measured apart).
LocalInterpolation TripInterpolationAcross(const InterpolationEstimate& estimate, const TripWindow& window,
                                           const Eigen::Vector2d& across) {
  Rect box{window.nominal.x(), window.nominal.x(), window.nominal.y(), window.nominal.y()};
  for (const Eigen::Vector2d& p : {window.from, window.to}) {
    box.x0 = std::min(box.x0, p.x());
    box.x1 = std::max(box.x1, p.x());
    box.y0 = std::min(box.y0, p.y());
    box.y1 = std::max(box.y1, p.y());
  }
  const LocalInterpolation x = estimate.axes[0].Over(box), y = estimate.axes[1].Over(box);
  LocalInterpolation local;
  local.bound_mm = std::abs(across.x()) * x.bound_mm + std::abs(across.y()) * y.bound_mm;
  local.noise_mm = std::hypot(across.x() * x.noise_mm, across.y() * y.noise_mm);
  return local;
}

}  // namespace

double ErrorShare::SigmaMm() const {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance_mm2, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, solver.eigenvalues().maxCoeff()));
}

double ErrorShare::BudgetMm() const { return mean_mm.norm() + bound_mm + kBudgetSigmas * SigmaMm(); }

ErrorShare& ErrorShare::operator+=(const ErrorShare& other) {
  mean_mm += other.mean_mm;
  bound_mm += other.bound_mm;
  covariance_mm2 += other.covariance_mm2;
  worst_mm += other.worst_mm;
  return *this;
}

std::string_view ErrorSourceName(ErrorSource source) {
  switch (source) {
    case ErrorSource::kResidual: return "residual";
    case ErrorSource::kRepeatability: return "repeatability";
    case ErrorSource::kTable: return "table";
    case ErrorSource::kInterpolation: return "interpolation";
    case ErrorSource::kSensor: return "sensor";
    case ErrorSource::kScanRepeatability: return "scan_repeatability";
    case ErrorSource::kLatency: return "latency";
    case ErrorSource::kTripTables: return "trip_tables";
    case ErrorSource::kUncalibratedTrips: return "uncalibrated_trips";
  }
  return "?";
}

std::string_view ErrorSourceDescription(ErrorSource source) {
  switch (source) {
    case ErrorSource::kResidual: return "the inverse's residual";
    case ErrorSource::kRepeatability: return "the robot's repeatability";
    case ErrorSource::kTable: return "the table's measurement uncertainty";
    case ErrorSource::kInterpolation: return "the interpolation error between the tables' nodes";
    case ErrorSource::kSensor: return "the marker sensor's accuracy through the estimator";
    case ErrorSource::kScanRepeatability: return "the robot's repeatability at the trips";
    case ErrorSource::kLatency: return "the trip latency (scan speed x servo period)";
    case ErrorSource::kTripTables: return "the measurement uncertainty of the tables under the trips";
    case ErrorSource::kUncalibratedTrips: return "the robot's own error at trips outside every table";
  }
  return "?";
}

ErrorShare ErrorBudget::Total() const {
  ErrorShare total;
  for (const ErrorShare& share : shares) total += share;
  if (!bounded) total.bound_mm = total.worst_mm = std::numeric_limits<double>::infinity();
  return total;
}

ErrorSource ErrorBudget::Largest() const {
  std::size_t largest = 0;
  for (std::size_t k = 1; k < shares.size(); ++k) {
    if (shares[k].BudgetMm() > shares[largest].BudgetMm()) largest = k;
  }
  if (!bounded) return ErrorSource::kUncalibratedTrips;
  return static_cast<ErrorSource>(largest);
}

// The measurement's own uncertainty (docs/measure.md, "The measurement's
// uncertainty"): the scatter of a node's readings (type A, stddev / sqrt(n))
// and everything else measure read budgets (type B: the artefact's
// certificate, the stylus and hole diameters, the probe's latency, the
// registration of the artefact's placements; the table's u_mm column),
// combined per node as GUM does; the largest over the axis's nodes.
Eigen::Vector2d TableStandardErrorMm(const ErrorTable& table, double repeatability_mm) {
  Eigen::Vector2d se = Eigen::Vector2d::Zero();
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    double worst = 0;
    for (std::size_t k = 0; k < t.error_mm.size(); ++k) {
      const double scatter = t.StandardErrorMm(k).value_or(repeatability_mm);
      const double rest = k < t.u_mm.size() ? t.u_mm[k].value_or(0.0) : 0.0;
      worst = std::max(worst, std::hypot(scatter, rest));
    }
    se[static_cast<int>(axis)] = worst;
  }
  return se;
}

double WorstCaseSumMm(const std::vector<Eigen::Vector2d>& terms) {
  // |sum s_k v_k| is largest for the signs s_k = sign(u . v_k) of some
  // direction u, and those signs change only where u is perpendicular to a
  // v_k: one candidate per arc between those directions.
  std::vector<double> breaks;
  for (const Eigen::Vector2d& v : terms) {
    if (!(v.norm() > 0)) continue;
    const double angle = std::atan2(v.y(), v.x());
    for (double b : {angle + 0.5 * std::numbers::pi, angle - 0.5 * std::numbers::pi}) {
      breaks.push_back(std::remainder(b, 2 * std::numbers::pi) + std::numbers::pi);  // in [0, 2 pi]
    }
  }
  if (breaks.empty()) return 0;
  std::sort(breaks.begin(), breaks.end());
  double largest = 0;
  for (std::size_t k = 0; k < breaks.size(); ++k) {
    const double next = k + 1 < breaks.size() ? breaks[k + 1] : breaks.front() + 2 * std::numbers::pi;
    const double mid = 0.5 * (breaks[k] + next);
    const Eigen::Vector2d u(std::cos(mid), std::sin(mid));
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& v : terms) sum += u.dot(v) >= 0 ? v : Eigen::Vector2d(-v);
    largest = std::max(largest, sum.norm());
  }
  return largest;
}

ErrorShare RegionInterpolationShare(const InterpolationEstimate& estimate) {
  // The departure is systematic: the same every time the robot goes there,
  // so a bound (taken in its worst direction by the process figures), never
  // a random part that could average out. What the check points cannot tell
  // from their own noise is random: their residuals' standard deviations.
  ErrorShare share;
  const Eigen::Vector2d noise = estimate.PerAxisNoiseMm();
  share.bound_mm = estimate.NormMm();
  share.covariance_mm2 = noise.cwiseAbs2().asDiagonal();
  share.worst_mm = share.bound_mm + kBudgetSigmas * noise.norm();
  return share;
}

ErrorBudget StaticBudget(const cell::Cell& cell, const cell::Region* region, double residual_mm) {
  return StaticBudget(cell, region, residual_mm,
                      region != nullptr ? TableStandardErrorMm(region->table, cell.robot.repeatability_mm)
                                        : Eigen::Vector2d::Zero());
}

std::vector<Eigen::Vector2d> RegionTableNoise(const cell::Cell& cell) {
  std::vector<Eigen::Vector2d> noise;
  for (const cell::Region& region : cell.regions) {
    noise.push_back(TableStandardErrorMm(region.table, cell.robot.repeatability_mm));
  }
  return noise;
}

ErrorBudget StaticBudget(const cell::Cell& cell, const cell::Region* region, double residual_mm,
                         const Eigen::Vector2d& table_se) {
  ErrorBudget budget;
  const double r = cell.robot.repeatability_mm;
  ErrorShare& residual = budget[ErrorSource::kResidual];
  residual.bound_mm = residual.worst_mm = residual_mm;
  ErrorShare& repeat = budget[ErrorSource::kRepeatability];
  repeat.covariance_mm2 = UniformVariance(r) * Eigen::Matrix2d::Identity();
  repeat.worst_mm = r * std::numbers::sqrt2;
  if (region != nullptr) {
    const Eigen::Vector2d& se = table_se;
    ErrorShare& table = budget[ErrorSource::kTable];
    table.covariance_mm2 = se.cwiseAbs2().asDiagonal();
    table.worst_mm = kBudgetSigmas * se.norm();
    budget[ErrorSource::kInterpolation] = RegionInterpolationShare(region->interpolation);
  }
  return budget;
}

std::vector<int> TripRegions(const cell::Fixture& fixture, const std::vector<cell::Region>& regions) {
  std::vector<int> result;
  for (const TripWindow& window : TripWindows(fixture)) {
    int found = -1;
    for (std::size_t r = 0; r < regions.size() && found < 0; ++r) {
      if (WindowInDomain(window, TableDomain(regions[r].table))) found = static_cast<int>(r);
    }
    result.push_back(found);
  }
  return result;
}

FixtureErrorModel::FixtureErrorModel(const cell::Cell& cell, const cell::Fixture& fixture,
                                     std::vector<Eigen::Vector2d> region_table_se)
    : cell_(cell),
      sensor_accuracy_mm_(fixture.sensor_accuracy_mm),
      latency_mm_(fixture.TripLatchSpeedMmS() * cell.robot.servo_period_s),
      region_table_se_(region_table_se.empty() ? RegionTableNoise(cell) : std::move(region_table_se)) {
  trip_regions_ = TripRegions(fixture, cell.regions);
  const std::vector<TripWindow> windows = TripWindows(fixture);
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const std::vector<Eigen::Vector2d> trips = NominalTrips(fixture, nominal);
  const Eigen::Matrix2d rotation = nominal.linear().topLeftCorner<2, 2>();
  nominal_x_axis_ = rotation.col(0);
  const double h = kTripSensitivityStepMm;
  for (std::size_t k = 0; k < trips.size(); ++k) {
    const Eigen::Vector2d normal = EdgeLineOf(fixture.edges[static_cast<std::size_t>(expected[k].edge)]).normal;
    // An error moves the trip across its edge: along the edge's normal in
    // the base frame (a move along the edge changes no fit).
    const Eigen::Vector2d across = rotation * normal;
    std::vector<Eigen::Vector2d> plus = trips, minus = trips;
    plus[k] += h * across;
    minus[k] -= h * across;
    std::optional<FixEstimate> a = EstimateFix(fixture, expected, plus, fixture.estimator);
    std::optional<FixEstimate> b = EstimateFix(fixture, expected, minus, fixture.estimator);
    if (!a || !b) return;  // defined_ stays false
    d_linear_.push_back((a->fix.linear().topLeftCorner<2, 2>() - b->fix.linear().topLeftCorner<2, 2>()) / (2 * h));
    d_origin_.push_back((FixOrigin(a->fix) - FixOrigin(b->fix)) / (2 * h));
    leg_across_.push_back(expected[k].leg_direction.dot(normal));
    double se = 0;
    LocalInterpolation interpolation;
    if (trip_regions_[k] >= 0) {
      const cell::Region& region = cell.regions[static_cast<std::size_t>(trip_regions_[k])];
      const Eigen::Vector2d axis_se = TableStandardErrorMm(region.table, cell.robot.repeatability_mm);
      se = std::sqrt(across.cwiseAbs2().dot(axis_se.cwiseAbs2()));
      interpolation = TripInterpolationAcross(region.interpolation, windows[k], across);
    }
    trip_table_se_.push_back(se);
    trip_interpolation_.push_back(interpolation);
  }
  defined_ = true;
}

std::vector<std::size_t> FixtureErrorModel::UncalibratedTrips() const {
  std::vector<std::size_t> trips;
  for (std::size_t k = 0; k < trip_regions_.size(); ++k) {
    if (trip_regions_[k] < 0) trips.push_back(k);
  }
  return trips;
}

ErrorBudget FixtureErrorModel::At(const Eigen::Vector2d& point_in_fixture, const cell::Region* region,
                                  double residual_mm) const {
  ErrorBudget budget =
      region != nullptr
          ? StaticBudget(cell_, region, residual_mm, region_table_se_[static_cast<std::size_t>(region - cell_.regions.data())])
          : StaticBudget(cell_, region, residual_mm);
  if (!defined_) {
    budget.bounded = false;
    return budget;
  }
  const cell::Robot& robot = cell_.robot;
  ErrorShare& sensor = budget[ErrorSource::kSensor];
  ErrorShare& scan_repeat = budget[ErrorSource::kScanRepeatability];
  ErrorShare& latency = budget[ErrorSource::kLatency];
  ErrorShare& trip_tables = budget[ErrorSource::kTripTables];
  ErrorShare& uncalibrated = budget[ErrorSource::kUncalibratedTrips];
  for (std::size_t k = 0; k < d_linear_.size(); ++k) {
    const Eigen::Vector2d g = d_linear_[k] * point_in_fixture + d_origin_[k];
    const double gain = g.norm();
    const Eigen::Matrix2d gg = Outer(g);
    sensor.covariance_mm2 += UniformVariance(sensor_accuracy_mm_) * gg;
    sensor.worst_mm += gain * sensor_accuracy_mm_;
    scan_repeat.covariance_mm2 += UniformVariance(robot.repeatability_mm) * gg;
    scan_repeat.worst_mm += gain * robot.repeatability_mm * std::numbers::sqrt2;
    // Late by a uniform draw in [0, v T] along the leg: mean v T / 2, spread
    // +-v T / 2, of which the part across the edge counts.
    const double late = latency_mm_ * leg_across_[k];
    latency.mean_mm += 0.5 * late * g;
    latency.covariance_mm2 += UniformVariance(0.5 * late) * gg;
    latency.worst_mm += gain * std::abs(late);
    if (trip_regions_[k] >= 0) {
      trip_tables.covariance_mm2 += trip_table_se_[k] * trip_table_se_[k] * gg;
      trip_tables.worst_mm += kBudgetSigmas * trip_table_se_[k] * gain;
    } else if (robot.uncalibrated_accuracy_mm) {
      uncalibrated.bound_mm += gain * *robot.uncalibrated_accuracy_mm;
      uncalibrated.worst_mm += gain * *robot.uncalibrated_accuracy_mm;
    } else {
      budget.bounded = false;
    }
  }
  budget[ErrorSource::kInterpolation] = Interpolation(point_in_fixture, region);
  return budget;
}

std::vector<Eigen::Vector2d> FixtureErrorModel::TripGains(const Eigen::Vector2d& point_in_fixture) const {
  std::vector<Eigen::Vector2d> gains;
  for (std::size_t k = 0; k < d_linear_.size(); ++k) gains.push_back(d_linear_[k] * point_in_fixture + d_origin_[k]);
  return gains;
}

ErrorShare FixtureErrorModel::Interpolation(const Eigen::Vector2d& point_in_fixture, const cell::Region* region) const {
  ErrorShare share = region != nullptr ? RegionInterpolationShare(region->interpolation) : ErrorShare{};
  if (!defined_) return share;
  // The bound: the largest displacement the departures can make together,
  // each anywhere within its bound: the target region's along x and y, and
  // each calibrated trip's across its edge through the estimator (g_k). The
  // exact worst case of the linear map over that box (WorstCaseSumMm), not
  // the sum of each part's worst: a trip pair on one edge moves the board
  // alike, trips on crossing edges do not.
  std::vector<Eigen::Vector2d> terms;
  if (region != nullptr) {
    const Eigen::Vector2d own = region->interpolation.PerAxisMm();
    terms = {Eigen::Vector2d(own.x(), 0), Eigen::Vector2d(0, own.y())};
  }
  // The noise: the trips under one table may share a check point's noise,
  // so per table the worst sum of its trips' noises, in any direction.
  std::map<int, std::vector<Eigen::Vector2d>> noise_by_region;
  const std::vector<Eigen::Vector2d> gains = TripGains(point_in_fixture);
  for (std::size_t k = 0; k < gains.size(); ++k) {
    if (trip_regions_[k] < 0) continue;
    terms.push_back(trip_interpolation_[k].bound_mm * gains[k]);
    noise_by_region[trip_regions_[k]].push_back(trip_interpolation_[k].noise_mm * gains[k]);
  }
  share.bound_mm = WorstCaseSumMm(terms);
  share.worst_mm = share.bound_mm + (region != nullptr ? kBudgetSigmas * region->interpolation.PerAxisNoiseMm().norm() : 0.0);
  for (const auto& [r, noises] : noise_by_region) {
    const double sigma = WorstCaseSumMm(noises);
    share.covariance_mm2 += sigma * sigma * Eigen::Matrix2d::Identity();
    share.worst_mm += kBudgetSigmas * sigma;
  }
  return share;
}

Eigen::Matrix3d FixtureErrorModel::PoseCovariance() const {
  const cell::Robot& robot = cell_.robot;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < d_linear_.size(); ++k) {
    // How the pose moves with trip k moving across its edge: its origin, and
    // its angle (n turns by the part of dn across n).
    const Eigen::Vector2d dn = d_linear_[k].col(0);
    const Eigen::Vector3d j(d_origin_[k].x(), d_origin_[k].y(),
                            nominal_x_axis_.x() * dn.y() - nominal_x_axis_.y() * dn.x());
    const double late = latency_mm_ * leg_across_[k];
    const double variance = UniformVariance(sensor_accuracy_mm_) + UniformVariance(robot.repeatability_mm) +
                            UniformVariance(0.5 * late) + trip_table_se_[k] * trip_table_se_[k];
    covariance += variance * j * j.transpose();
  }
  return covariance;
}

double OutsideProbability(const Eigen::Vector2d& mean_mm, const Eigen::Matrix2d& covariance_mm2,
                          double tolerance_mm) {
  const double t = tolerance_mm;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance_mm2);
  // Principal axes: u along the larger spread, v along the smaller.
  const Eigen::Vector2d axis_u = solver.eigenvectors().col(1), axis_v = solver.eigenvectors().col(0);
  const double su = std::sqrt(std::max(0.0, solver.eigenvalues()(1)));
  const double sv = std::sqrt(std::max(0.0, solver.eigenvalues()(0)));
  const double mu = axis_u.dot(mean_mm), mv = axis_v.dot(mean_mm);
  const double tiny = 1e-12 * std::max(t, 1e-300);
  auto upper_tail = [](double z) { return 0.5 * std::erfc(z / std::numbers::sqrt2); };  // P(Z > z)
  // P(v outside [-h, h]) for the v part.
  auto v_outside = [&](double h) {
    if (sv <= tiny) return std::abs(mv) > h ? 1.0 : 0.0;
    return upper_tail((h - mv) / sv) + upper_tail((h + mv) / sv);
  };
  if (su <= tiny) return std::abs(mu) > t ? 1.0 : v_outside(std::sqrt(std::max(0.0, t * t - mu * mu)));
  // P(|u| > t) + integral over |u| <= t of density(u) * P(v outside the
  // chord), with u = t sin(theta): the chord's half length t cos(theta) is
  // then smooth (its square root is not, at u = +-t, which Simpson's rule
  // would feel), and du = t cos(theta) d(theta).
  double p = upper_tail((t - mu) / su) + upper_tail((t + mu) / su);
  const double lo = std::asin(std::clamp((mu - 12 * su) / t, -1.0, 1.0));
  const double hi = std::asin(std::clamp((mu + 12 * su) / t, -1.0, 1.0));
  if (hi > lo) {
    constexpr int kIntervals = 4000;  // even, for Simpson's rule
    const double step = (hi - lo) / kIntervals;
    double sum = 0;
    for (int i = 0; i <= kIntervals; ++i) {
      const double theta = lo + i * step;
      const double u = t * std::sin(theta), chord = t * std::cos(theta);
      const double z = (u - mu) / su;
      const double density = std::exp(-0.5 * z * z) / (su * std::sqrt(2 * std::numbers::pi));
      const double weight = i == 0 || i == kIntervals ? 1 : i % 2 == 1 ? 4 : 2;
      sum += weight * density * v_outside(chord) * chord;
    }
    p += sum * step / 3;
  }
  return std::clamp(p, 0.0, 1.0);
}

}  // namespace smtcal
