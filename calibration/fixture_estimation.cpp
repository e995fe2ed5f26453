// Periphery calibration: trips -> checked FIX, and the corrections that use it
// (see fixture_estimation.h; the math is derived in docs/periphery.md).
// Assumes a fixture the cell loader accepted; guarantees no NaN in any
// result (a pose the trips do not define is the `degenerate` fault) and that
// a scan failing any check carries no pose.
//
// runtime/c/smtcal_runtime.c implements the same steps in the same order; a
// change here needs the same change there (tests/unit/backend/fixture_c_runtime_test.cpp
// compares the two on thousands of random scans).
#include "calibration/fixture_estimation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/tolerances.h"

namespace smtcal {

std::string_view ScanCheckName(ScanCheck check) {
  switch (check) {
    case ScanCheck::kMissingTrip: return "missing_trip";
    case ScanCheck::kTripWindow: return "trip_window";
    case ScanCheck::kDegenerate: return "degenerate";
    case ScanCheck::kLengthL1: return "length_l1";
    case ScanCheck::kLengthL2: return "length_l2";
    case ScanCheck::kSquareness: return "squareness";
    case ScanCheck::kLineResidual: return "line_residual";
    case ScanCheck::kNominalShift: return "nominal_shift";
    case ScanCheck::kNominalRotation: return "nominal_rotation";
    case ScanCheck::kCycleShift: return "cycle_shift";
    case ScanCheck::kCycleRotation: return "cycle_rotation";
  }
  return "?";
}

std::string_view ScanCheckUnit(ScanCheck check) {
  switch (check) {
    case ScanCheck::kMissingTrip: return "trips";
    case ScanCheck::kDegenerate: return "";
    case ScanCheck::kSquareness:
    case ScanCheck::kNominalRotation:
    case ScanCheck::kCycleRotation: return "deg";
    default: return "mm";
  }
}

namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Solves the symmetric 2 x 2 system m x = b; false when m is singular
// relative to its size (kMinRelativeDeterminant).
bool Solve2(const Eigen::Matrix2d& m, const Eigen::Vector2d& b, Eigen::Vector2d& x) {
  const double det = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0);
  const double trace = std::abs(m(0, 0)) + std::abs(m(1, 1));
  if (!(std::abs(det) > kMinRelativeDeterminant * trace * trace)) return false;
  x = Eigen::Vector2d(m(1, 1) * b.x() - m(0, 1) * b.y(), m(0, 0) * b.y() - m(1, 0) * b.x()) / det;
  return true;
}

// A fitted line: a point on it (the trips' centroid) and a unit direction.
struct Line {
  Eigen::Vector2d point;
  Eigen::Vector2d direction;
};

// The total-least-squares line of an edge's trips (the principal axis of
// their scatter). nullopt when its trips are closer together than
// kMinTripSeparationMm (no direction).
std::optional<Line> FitLine(const std::vector<Eigen::Vector2d>& points, std::string* why, std::string_view edge) {
  double spread = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = i + 1; j < points.size(); ++j) spread = std::max(spread, (points[i] - points[j]).norm());
  }
  if (points.size() < 2 || !(spread >= kMinTripSeparationMm)) {
    if (why != nullptr) {
      *why = fmt::format("the trips on edge {} are {:.4f} mm apart, less than {} mm, so they define no line", edge,
                         spread, kMinTripSeparationMm);
    }
    return std::nullopt;
  }
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  double sxx = 0, sxy = 0, syy = 0;
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d d = p - centroid;
    sxx += d.x() * d.x();
    sxy += d.x() * d.y();
    syy += d.y() * d.y();
  }
  // The eigenvector of the larger eigenvalue of [[sxx, sxy], [sxy, syy]]:
  // of the two candidate columns of (S - lambda I)'s adjugate, the longer.
  const double half = 0.5 * (sxx - syy);
  const double lambda = 0.5 * (sxx + syy) + std::sqrt(half * half + sxy * sxy);
  Eigen::Vector2d a(sxy, lambda - sxx), b(lambda - syy, sxy);
  Eigen::Vector2d direction = a.squaredNorm() >= b.squaredNorm() ? a : b;
  direction /= direction.norm();
  return Line{centroid, direction};
}

std::optional<Eigen::Vector2d> Intersect(const Line& a, const Line& b, std::string* why, std::string_view a_name,
                                         std::string_view b_name) {
  const double sine = Cross(a.direction, b.direction);
  if (!(std::abs(sine) >= kMinLineCrossingSin)) {
    if (why != nullptr) {
      *why = fmt::format("the fitted lines {} and {} cross at {:.2f} deg, too flat for a crossing point", a_name,
                         b_name, std::asin(std::min(1.0, std::abs(sine))) * kDegPerRad);
    }
    return std::nullopt;
  }
  const double t = Cross(b.point - a.point, b.direction) / sine;
  return a.point + t * a.direction;
}

std::string_view EdgeName(const cell::Fixture& fixture, int edge) {
  return fixture.edges[static_cast<std::size_t>(edge)].name;
}

// Eq. 4 on the crossings of the fitted lines p1..p4.
std::optional<Eigen::Affine3d> PaperFix(const cell::Fixture& fixture, const std::vector<ExpectedTrip>& expected,
                                        const std::vector<Eigen::Vector2d>& trips, std::string* why) {
  std::array<Line, 4> lines;
  for (int e = 0; e < 4; ++e) {
    std::vector<Eigen::Vector2d> points;
    for (std::size_t k = 0; k < expected.size(); ++k) {
      if (expected[k].edge == e) points.push_back(trips[k]);
    }
    std::optional<Line> line = FitLine(points, why, EdgeName(fixture, e));
    if (!line) return std::nullopt;
    lines[static_cast<std::size_t>(e)] = *line;
  }
  // S1 = p1 x p2, S2 = p1 x p3, S3 = p2 x p4.
  std::optional<Eigen::Vector2d> s1 = Intersect(lines[0], lines[1], why, EdgeName(fixture, 0), EdgeName(fixture, 1));
  if (!s1) return std::nullopt;
  std::optional<Eigen::Vector2d> s2 = Intersect(lines[0], lines[2], why, EdgeName(fixture, 0), EdgeName(fixture, 2));
  if (!s2) return std::nullopt;
  std::optional<Eigen::Vector2d> s3 = Intersect(lines[1], lines[3], why, EdgeName(fixture, 1), EdgeName(fixture, 3));
  if (!s3) return std::nullopt;
  const Eigen::Vector2d n = (*s2 - *s1) / fixture.l1_mm, o = (*s3 - *s1) / fixture.l2_mm;
  Eigen::Affine3d fix = Eigen::Affine3d::Identity();
  fix.linear().topLeftCorner<2, 2>() << n.x(), o.x(), n.y(), o.y();
  fix.translation() << s1->x(), s1->y(), 0;
  return fix;
}

// The rigid and rigid-scale fits. In the nominal fixture frame (trips q_k =
// R_nom^T (t_k - p_nom), so the sought pose is near the identity) a trip on
// edge k (unit normal n_k, offset d_k) under the pose q = sigma R f + p has
// the residual
//   r_k = (c A_k + s B_k - n_k . (a, b)) / sigma - d_k,
//   A_k = n_k . q_k, B_k = n_k x q_k, (c, s) = (cos, sin), (a, b) = R^T p.
// Eliminating (a, b) (for a fixed rotation they solve a 2 x 2 least-squares
// problem with the edge normals N) leaves u^T Q u - 2 g^T u + const in
// u = (c, s) / sigma, with Q = M^T P M, g = M^T P d, M = [A B] and P the
// projection off the columns of N. rigid-scale: u = Q^-1 g. rigid: the same
// over |u| = 1, by Newton steps along the circle from the rigid-scale
// solution.
std::optional<Eigen::Affine3d> RigidFix(const cell::Fixture& fixture, const std::vector<ExpectedTrip>& expected,
                                        const std::vector<Eigen::Vector2d>& trips, bool with_scale,
                                        std::string* why) {
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const Eigen::Matrix2d r_nominal = nominal.linear().topLeftCorner<2, 2>();
  const Eigen::Vector2d p_nominal = FixOrigin(nominal);
  const std::size_t count = expected.size();
  std::vector<Eigen::Vector2d> normal(count);
  std::vector<double> offset(count), a(count), b(count);
  Eigen::Matrix2d ntn = Eigen::Matrix2d::Zero();
  for (std::size_t k = 0; k < count; ++k) {
    const EdgeLine line = EdgeLineOf(fixture.edges[static_cast<std::size_t>(expected[k].edge)]);
    const Eigen::Vector2d q = r_nominal.transpose() * (trips[k] - p_nominal);
    normal[k] = line.normal;
    offset[k] = line.offset;
    a[k] = line.normal.dot(q);
    b[k] = Cross(line.normal, q);
    ntn += line.normal * line.normal.transpose();
  }
  auto singular = [&](std::string_view what) {
    if (why != nullptr) *why = fmt::format("the least-squares problem is singular: {}", what);
    return std::nullopt;
  };
  // P v = v - N (N^T N)^-1 N^T v for the columns A, B and d.
  auto project = [&](const std::vector<double>& v, std::vector<double>& out) {
    Eigen::Vector2d ntv = Eigen::Vector2d::Zero();
    for (std::size_t k = 0; k < count; ++k) ntv += normal[k] * v[k];
    Eigen::Vector2d w;
    if (!Solve2(ntn, ntv, w)) return false;
    out.resize(count);
    for (std::size_t k = 0; k < count; ++k) out[k] = v[k] - normal[k].dot(w);
    return true;
  };
  std::vector<double> pa, pb, pd;
  if (!project(a, pa) || !project(b, pb) || !project(offset, pd)) {
    return singular("the marker edges all have one direction");
  }
  Eigen::Matrix2d q = Eigen::Matrix2d::Zero();
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < count; ++k) {
    q(0, 0) += pa[k] * pa[k];
    q(0, 1) += pa[k] * pb[k];
    q(1, 1) += pb[k] * pb[k];
    g.x() += pa[k] * pd[k];
    g.y() += pb[k] * pd[k];
  }
  q(1, 0) = q(0, 1);
  Eigen::Vector2d u;
  if (!Solve2(q, g, u) || !(u.norm() > 0)) return singular("the trips do not fix the rotation and scale");
  double scale = 1 / u.norm();
  u *= scale;  // (cos, sin) of the rotation
  if (!with_scale) {
    scale = 1;
    for (int i = 0; i < kRigidMaxIterations; ++i) {
      // f(u) = u^T Q u - 2 g^T u on the unit circle; t is its tangent.
      const Eigen::Vector2d t(-u.y(), u.x());
      const Eigen::Vector2d qu = q * u;
      const double slope = 2 * t.dot(qu - g);
      const double curvature = 2 * (t.dot(q * t) - u.dot(qu) + g.dot(u));
      if (!(curvature > 0)) break;  // not near a minimum: keep the rigid-scale rotation
      const double step = -slope / curvature;
      u += step * t;
      u /= u.norm();
      if (std::abs(step) <= kRigidStepTolRad) break;
    }
  }
  // The translation for this rotation: (a, b) = (N^T N)^-1 N^T (c A + s B - d / scale... ) * scale.
  std::vector<double> rhs(count);
  for (std::size_t k = 0; k < count; ++k) rhs[k] = u.x() * a[k] + u.y() * b[k] - scale * offset[k];
  Eigen::Vector2d ntv = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < count; ++k) ntv += normal[k] * rhs[k];
  Eigen::Vector2d ab;
  if (!Solve2(ntn, ntv, ab)) return singular("the marker edges all have one direction");
  Eigen::Matrix2d rotation;
  rotation << u.x(), -u.y(), u.y(), u.x();
  const Eigen::Vector2d p_delta = rotation * ab;
  Eigen::Affine3d fix = Eigen::Affine3d::Identity();
  fix.linear().topLeftCorner<2, 2>() = r_nominal * (scale * rotation);
  fix.translation().head<2>() = p_nominal + r_nominal * p_delta;
  return fix;
}

}  // namespace

std::optional<FixEstimate> EstimateFix(const cell::Fixture& fixture, const std::vector<ExpectedTrip>& expected,
                                       const std::vector<Eigen::Vector2d>& trips, cell::Estimator estimator,
                                       std::string* why) {
  SMTCAL_CHECK(trips.size() == expected.size(), "one trip per expected trip");
  std::optional<Eigen::Affine3d> fix =
      estimator == cell::Estimator::kPaper ? PaperFix(fixture, expected, trips, why)
                                           : RigidFix(fixture, expected, trips,
                                                      estimator == cell::Estimator::kRigidScale, why);
  if (!fix) return std::nullopt;
  const Eigen::Matrix2d linear = fix->linear().topLeftCorner<2, 2>();
  const double det = linear.determinant();
  if (!(std::abs(det) > kMinRelativeDeterminant * linear.squaredNorm())) {
    if (why != nullptr) *why = "the estimated FIX is singular (S1, S2 and S3 on one line)";
    return std::nullopt;
  }
  FixEstimate estimate;
  estimate.fix = *fix;
  estimate.s = {ToBase(*fix, Eigen::Vector2d(0, 0)), ToBase(*fix, Eigen::Vector2d(fixture.l1_mm, 0)),
                ToBase(*fix, Eigen::Vector2d(0, fixture.l2_mm))};
  estimate.scale = linear.col(0).norm();
  // An edge line n . f = d maps to m . x = d + m . p in the base frame with
  // m = A^-T n; a trip's distance from it is |n . A^-1 (t - p) - d| / |m|.
  const Eigen::Matrix2d inverse = linear.inverse();
  for (std::size_t k = 0; k < trips.size(); ++k) {
    const EdgeLine line = EdgeLineOf(fixture.edges[static_cast<std::size_t>(expected[k].edge)]);
    const Eigen::Vector2d m = inverse.transpose() * line.normal;
    const Eigen::Vector2d in_fixture = inverse * (trips[k] - FixOrigin(*fix));
    estimate.residual_mm.push_back(std::abs(line.normal.dot(in_fixture) - line.offset) / m.norm());
  }
  return estimate;
}

namespace {

// Through the first map whose domain holds the point; unchanged when none
// does. `map_of(r)` gives region r's map.
template <typename MapOf>
Eigen::Vector2d DirectCalibrateThrough(std::size_t regions, const MapOf& map_of, const Eigen::Vector2d& commanded,
                                       int* region) {
  for (std::size_t r = 0; r < regions; ++r) {
    const CalibrationMap& map = map_of(r);
    if (!map.Inside(commanded)) continue;
    if (region != nullptr) *region = static_cast<int>(r);
    return DirectCalibrate(map, commanded, OutsidePolicy::kClamp).point;
  }
  if (region != nullptr) *region = -1;
  return commanded;
}
Eigen::Vector2d DirectCalibrateThrough(const std::vector<CalibrationMap>& maps, const Eigen::Vector2d& commanded,
                                       int* region) {
  return DirectCalibrateThrough(
      maps.size(), [&](std::size_t r) -> const CalibrationMap& { return maps[r]; }, commanded, region);
}

std::vector<CalibrationMap> MapsOf(const std::vector<cell::Region>& regions) {
  std::vector<CalibrationMap> maps;
  maps.reserve(regions.size());
  for (const cell::Region& region : regions) maps.emplace_back(region.table);
  return maps;
}

}  // namespace

Eigen::Vector2d DirectCalibrateInCell(const std::vector<cell::Region>& regions, const Eigen::Vector2d& commanded,
                                      int* region) {
  return DirectCalibrateThrough(MapsOf(regions), commanded, region);
}

std::vector<Eigen::Vector2d> CommandedTrips(const cell::Fixture& fixture, const std::vector<cell::Region>& regions,
                                            const Eigen::Affine3d& fix) {
  const std::vector<CalibrationMap> maps = MapsOf(regions);
  std::vector<Eigen::Vector2d> commanded;
  for (const Eigen::Vector2d& trip : NominalTrips(fixture, fix)) {
    // A contraction (the tables' slopes are far below 1): c <- c + (t - F(c)).
    Eigen::Vector2d c = trip;
    for (int step = 0; step < 100; ++step) {
      const Eigen::Vector2d miss = trip - DirectCalibrateThrough(maps, c, nullptr);
      c += miss;
      if (miss.norm() < 1e-13) break;
    }
    commanded.push_back(c);
  }
  return commanded;
}

const CheckResult& ScanResult::Check(ScanCheck check) const {
  for (const CheckResult& result : checks) {
    if (result.check == check) return result;
  }
  SMTCAL_CHECK(false, "every scan result lists every check");
  return checks.front();
}

const CheckResult* ScanResult::FirstFailure() const {
  for (const CheckResult& result : checks) {
    if (result.evaluated && !result.passed) return &result;
  }
  return nullptr;
}

namespace {

CheckResult Evaluated(ScanCheck check, double value, double limit, int trip = -1) {
  return CheckResult{check, true, value <= limit, value, limit, trip, ""};
}

// The index and value of the largest element.
std::pair<int, double> Worst(const std::vector<double>& values) {
  int worst = -1;
  double largest = 0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (worst < 0 || values[k] > largest) {
      worst = static_cast<int>(k);
      largest = values[k];
    }
  }
  return {worst, largest};
}

// The estimate's own checks: shape, fit, pose against nominal and previous.
void CheckEstimate(const cell::Fixture& fixture, const ScanOptions& options, ScanResult& result) {
  const FixEstimate& estimate = *result.estimate;
  const Eigen::Vector2d n = estimate.s[1] - estimate.s[0], o = estimate.s[2] - estimate.s[0];
  auto set = [&](CheckResult check) { result.checks[static_cast<std::size_t>(check.check) - 1] = check; };
  set(Evaluated(ScanCheck::kLengthL1, std::abs(n.norm() - fixture.l1_mm), fixture.length_tolerance_mm));
  set(Evaluated(ScanCheck::kLengthL2, std::abs(o.norm() - fixture.l2_mm), fixture.length_tolerance_mm));
  const double angle = std::atan2(Cross(n, o), n.dot(o));
  set(Evaluated(ScanCheck::kSquareness, std::abs(angle - std::numbers::pi / 2) * kDegPerRad, fixture.squareness_deg));
  auto [worst, residual] = Worst(estimate.residual_mm);
  set(Evaluated(ScanCheck::kLineResidual, residual, fixture.max_line_residual_mm, worst));
  const Eigen::Affine3d nominal = NominalFix(fixture);
  set(Evaluated(ScanCheck::kNominalShift, (FixOrigin(estimate.fix) - FixOrigin(nominal)).norm(),
                fixture.max_shift_mm));
  set(Evaluated(ScanCheck::kNominalRotation, std::abs(RelativeAngleRad(nominal, estimate.fix)) * kDegPerRad,
                fixture.max_rotation_deg));
  if (options.previous) {
    result.delta = estimate.fix * options.previous->inverse();
    set(Evaluated(ScanCheck::kCycleShift, (FixOrigin(estimate.fix) - FixOrigin(*options.previous)).norm(),
                  fixture.max_shift_mm));
    set(Evaluated(ScanCheck::kCycleRotation,
                  std::abs(RelativeAngleRad(*options.previous, estimate.fix)) * kDegPerRad, fixture.max_rotation_deg));
  }
}

}  // namespace

ScanResult ScanFixture(const cell::Fixture& fixture, const std::vector<std::optional<Eigen::Vector2d>>& trips,
                       const ScanOptions& options) {
  ScanResult result;
  result.estimator = options.estimator;
  result.expected = ExpectedTrips(fixture);
  SMTCAL_CHECK(trips.size() == result.expected.size(), "ScanFixture takes one entry per expected trip");
  result.trips = trips;
  result.nominal = NominalTrips(fixture, NominalFix(fixture));
  for (ScanCheck check : kScanChecks) {
    CheckResult pending;
    pending.check = check;
    result.checks.push_back(pending);
  }
  const std::size_t count = trips.size();
  result.calibrated.assign(count, Eigen::Vector2d::Zero());
  result.region.assign(count, -1);
  result.window_mm.assign(count, 0);

  // Every trip present, each in its window.
  int missing = 0, first_missing = -1;
  for (std::size_t k = 0; k < count; ++k) {
    if (trips[k]) continue;
    if (missing++ == 0) first_missing = static_cast<int>(k);
  }
  result.checks[0] = Evaluated(ScanCheck::kMissingTrip, missing, 0, first_missing);
  if (missing > 0) return result;
  for (std::size_t k = 0; k < count; ++k) result.window_mm[k] = (*trips[k] - result.nominal[k]).norm();
  auto [worst, distance] = Worst(result.window_mm);
  result.checks[1] = Evaluated(ScanCheck::kTripWindow, distance, fixture.trip_window_mm, worst);
  if (!result.checks[1].passed) return result;

  // Where the sensor really was, then the estimator.
  const std::vector<CalibrationMap> maps =
      options.regions != nullptr ? MapsOf(*options.regions) : std::vector<CalibrationMap>();
  for (std::size_t k = 0; k < count; ++k) {
    result.calibrated[k] = DirectCalibrateThrough(maps, *trips[k], &result.region[k]);
  }
  std::string why;
  result.estimate = EstimateFix(fixture, result.expected, result.calibrated, options.estimator, &why);
  result.checks[2] = Evaluated(ScanCheck::kDegenerate, result.estimate ? 0 : 1, 0);
  result.checks[2].why = why;
  if (!result.estimate) return result;
  CheckEstimate(fixture, options, result);
  if (result.FirstFailure() == nullptr) result.fix = result.estimate->fix;
  return result;
}

ScanResult TeachScan(const cell::Cell& cell, const cell::Fixture& fixture) {
  const std::size_t expected = ExpectedTrips(fixture).size();
  SMTCAL_CHECK(fixture.teach_trips_mm.size() == expected, "the cell loader checks the teach scan's trip count");
  std::vector<std::optional<Eigen::Vector2d>> trips(fixture.teach_trips_mm.begin(), fixture.teach_trips_mm.end());
  ScanOptions options;
  options.estimator = fixture.estimator;
  options.regions = &cell.regions;
  return ScanFixture(fixture, trips, options);
}

std::string DescribeCheck(const CheckResult& check, const cell::Fixture& fixture) {
  auto trip_edge = [&](int trip) {
    std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
    const ExpectedTrip& t = expected[static_cast<std::size_t>(trip)];
    return fmt::format("{} (edge {} of scan path '{}')", TripName(static_cast<std::size_t>(trip)),
                       EdgeName(fixture, t.edge), fixture.scan_paths[t.path].name);
  };
  switch (check.check) {
    case ScanCheck::kMissingTrip:
      return fmt::format("trip {} is missing{}: the sensor did not trip where the scan path crosses that edge",
                         trip_edge(check.trip),
                         check.value > 1 ? fmt::format(" ({} trips are missing)", static_cast<int>(check.value))
                                         : std::string());
    case ScanCheck::kTripWindow:
      return fmt::format("trip {} is {:.3f} mm from where the nominal pose puts it, more than trip_window_mm = {}",
                         trip_edge(check.trip), check.value, FormatMm(check.limit));
    case ScanCheck::kDegenerate:
      return fmt::format("the trips define no pose: {}", check.why);
    case ScanCheck::kLengthL1:
      return fmt::format("|S2 - S1| differs from l1_mm = {} by {:.3f} mm, more than length_tolerance_mm = {}",
                         FormatMm(fixture.l1_mm), check.value, FormatMm(check.limit));
    case ScanCheck::kLengthL2:
      return fmt::format("|S3 - S1| differs from l2_mm = {} by {:.3f} mm, more than length_tolerance_mm = {}",
                         FormatMm(fixture.l2_mm), check.value, FormatMm(check.limit));
    case ScanCheck::kSquareness:
      return fmt::format("S2 - S1 and S3 - S1 are {:.3f} deg from square, more than squareness_deg = {}", check.value,
                         FormatMm(check.limit));
    case ScanCheck::kLineResidual:
      return fmt::format("trip {} is {:.3f} mm from its edge's line as FIX places it, more than "
                         "max_line_residual_mm = {} (an outlier trip, or markers that are not where the cell says)",
                         trip_edge(check.trip), check.value, FormatMm(check.limit));
    case ScanCheck::kNominalShift:
      return fmt::format("the fixture origin S1 is {:.3f} mm from its nominal position, more than max_shift_mm = {}",
                         check.value, FormatMm(check.limit));
    case ScanCheck::kNominalRotation:
      return fmt::format("the fixture is turned {:.3f} deg from its nominal angle, more than max_rotation_deg = {}",
                         check.value, FormatMm(check.limit));
    case ScanCheck::kCycleShift:
      return fmt::format("the fixture origin S1 moved {:.3f} mm since the previous scan, more than max_shift_mm = {}",
                         check.value, FormatMm(check.limit));
    case ScanCheck::kCycleRotation:
      return fmt::format("the fixture turned {:.3f} deg since the previous scan, more than max_rotation_deg = {}",
                         check.value, FormatMm(check.limit));
  }
  return "";
}

std::string DescribeFailure(const ScanResult& result, const cell::Fixture& fixture) {
  const CheckResult* failure = result.FirstFailure();
  if (failure == nullptr) return "";
  return fmt::format("{}: {}", ScanCheckName(failure->check), DescribeCheck(*failure, fixture));
}

// ------------------------------------------------------------------ corrections

Eigen::Affine3d OfflineTarget(const Eigen::Affine3d& fix_n, const Eigen::Affine3d& fixpos0) { return fix_n * fixpos0; }

Eigen::Affine3d TaughtFixturePosition(const Eigen::Affine3d& fix0, const Eigen::Affine3d& reached0) {
  return fix0.inverse() * reached0;
}

Eigen::Affine3d TaughtTarget(const Eigen::Affine3d& fix_n, const Eigen::Affine3d& fix0,
                             const Eigen::Affine3d& reached0) {
  return fix_n * (fix0.inverse() * reached0);
}

Eigen::Affine3d PoseMatrix(double x_mm, double y_mm, double z_mm, double u_deg) {
  Eigen::Affine3d pose = PlanarFix(Eigen::Vector2d(x_mm, y_mm), u_deg * kRadPerDeg);
  pose.translation().z() = z_mm;
  return pose;
}

std::array<double, 4> PoseValues(const Eigen::Affine3d& pose) {
  return {pose.translation().x(), pose.translation().y(), pose.translation().z(), FixAngleRad(pose) * kDegPerRad};
}

PointCorrector::PointCorrector(const std::vector<cell::Region>& regions) : regions_(regions) {
  solvers_.reserve(regions.size());
  for (const cell::Region& region : regions) solvers_.emplace_back(region.table);
}

int PointCorrector::RegionAt(const Eigen::Vector2d& base) const {
  for (std::size_t r = 0; r < regions_.size(); ++r) {
    if (regions_[r].x_mm.Contains(base.x()) && regions_[r].y_mm.Contains(base.y())) return static_cast<int>(r);
  }
  return -1;
}

CorrectedPoint PointCorrector::Invert(const Eigen::Vector2d& required) const {
  CorrectedPoint point;
  point.required = required;
  point.region = RegionAt(required);
  if (point.region < 0) {
    point.command = required;
    point.solution = Solution{required, 0, 0, SolveStatus::kUncorrected};
    return point;
  }
  const std::size_t r = static_cast<std::size_t>(point.region);
  point.solution = solvers_[r].Solve(required, regions_[r].outside);
  point.command = point.solution.point;
  return point;
}

CorrectedPoint PointCorrector::Correct(const Eigen::Affine3d& fix_n, const Eigen::Vector2d& fixpos0) const {
  return Invert(ToBase(fix_n, fixpos0));
}

Eigen::Vector2d PointCorrector::Forward(const Eigen::Vector2d& commanded, int* region) const {
  return DirectCalibrateThrough(
      solvers_.size(), [&](std::size_t r) -> const CalibrationMap& { return solvers_[r].map(); }, commanded, region);
}

}  // namespace smtcal
