// The geometry of a fixture's marker scan (see fixture_geometry.h). Assumes a
// fixture the cell loader accepted (edges of non-zero length, paths of at
// least two distinct points); guarantees trips in path order.
#include "calibration/fixture_geometry.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "base/check.h"

namespace smtcal {

Eigen::Affine3d PlanarFix(const Eigen::Vector2d& origin, double angle_rad, double scale) {
  Eigen::Affine3d fix = Eigen::Affine3d::Identity();
  const double c = std::cos(angle_rad) * scale, s = std::sin(angle_rad) * scale;
  fix.linear().topLeftCorner<2, 2>() << c, -s, s, c;
  fix.translation() << origin.x(), origin.y(), 0;
  return fix;
}

Eigen::Affine3d NominalFix(const cell::Fixture& fixture) {
  return PlanarFix(fixture.origin_mm, fixture.angle_deg * kRadPerDeg);
}

Eigen::Vector2d ToBase(const Eigen::Affine3d& fix, const Eigen::Vector2d& in_fixture) {
  return fix.linear().topLeftCorner<2, 2>() * in_fixture + fix.translation().head<2>();
}

Eigen::Vector2d ToFixtureFrame(const Eigen::Affine3d& fix, const Eigen::Vector2d& in_base) {
  const Eigen::Matrix2d linear = fix.linear().topLeftCorner<2, 2>();
  return linear.inverse() * (in_base - fix.translation().head<2>());
}

Eigen::Vector2d FixOrigin(const Eigen::Affine3d& fix) { return fix.translation().head<2>(); }

double FixAngleRad(const Eigen::Affine3d& fix) { return std::atan2(fix.linear()(1, 0), fix.linear()(0, 0)); }

double RelativeAngleRad(const Eigen::Affine3d& a, const Eigen::Affine3d& b) {
  const Eigen::Vector2d na = a.linear().col(0).head<2>(), nb = b.linear().col(0).head<2>();
  return std::atan2(na.x() * nb.y() - na.y() * nb.x(), na.dot(nb));
}

EdgeLine EdgeLineOf(const cell::MarkerEdge& edge) {
  const Eigen::Vector2d along = edge.to - edge.from;
  const double length = along.norm();
  SMTCAL_CHECK(length > 0, "a marker edge of zero length (the cell loader rejects it)");
  EdgeLine line;
  line.normal = Eigen::Vector2d(-along.y(), along.x()) / length;
  line.offset = line.normal.dot(edge.from);
  return line;
}

namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Segments a0-a1 (the leg) and b0-b1 (the edge) cross at a0 + t (a1 - a0)
// with t and u in [0, 1] (ends included, up to rounding). Parallel segments
// do not cross: a leg running along an edge cannot make a clean trip.
bool Crossing(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1, const Eigen::Vector2d& b0,
              const Eigen::Vector2d& b1, double& t) {
  const Eigen::Vector2d r = a1 - a0, s = b1 - b0, q = b0 - a0;
  const double denominator = Cross(r, s);
  if (std::abs(denominator) <= 1e-12 * r.norm() * s.norm()) return false;
  t = Cross(q, s) / denominator;
  const double u = Cross(q, r) / denominator;
  constexpr double kEnds = 1e-12;  // a crossing exactly at an end point counts
  return t >= -kEnds && t <= 1 + kEnds && u >= -kEnds && u <= 1 + kEnds;
}

}  // namespace

std::vector<ExpectedTrip> ExpectedTrips(const cell::Fixture& fixture) {
  std::vector<ExpectedTrip> trips;
  for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
    const std::vector<cell::Point2>& points = fixture.scan_paths[p].points;
    for (std::size_t leg = 0; leg + 1 < points.size(); ++leg) {
      const Eigen::Vector2d from = points[leg], to = points[leg + 1];
      const double length = (to - from).norm();
      if (length == 0) continue;
      std::vector<ExpectedTrip> on_leg;
      for (int e = 0; e < static_cast<int>(fixture.edges.size()); ++e) {
        const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(e)];
        double t = 0;
        if (!Crossing(from, to, edge.from, edge.to, t)) continue;
        t = std::clamp(t, 0.0, 1.0);
        ExpectedTrip trip;
        trip.path = p;
        trip.leg = leg;
        trip.edge = e;
        trip.in_fixture = from + t * (to - from);
        trip.along_mm = t * length;
        trip.leg_direction = (to - from) / length;
        on_leg.push_back(trip);
      }
      std::stable_sort(on_leg.begin(), on_leg.end(),
                       [](const ExpectedTrip& a, const ExpectedTrip& b) { return a.along_mm < b.along_mm; });
      trips.insert(trips.end(), on_leg.begin(), on_leg.end());
    }
  }
  return trips;
}

std::vector<Eigen::Vector2d> NominalTrips(const cell::Fixture& fixture, const Eigen::Affine3d& fix) {
  std::vector<Eigen::Vector2d> points;
  for (const ExpectedTrip& trip : ExpectedTrips(fixture)) points.push_back(ToBase(fix, trip.in_fixture));
  return points;
}

std::vector<std::vector<Eigen::Vector2d>> ScanPathsInBase(const cell::Fixture& fixture,
                                                          const Eigen::Affine3d& fix) {
  std::vector<std::vector<Eigen::Vector2d>> paths;
  for (const cell::ScanPath& path : fixture.scan_paths) {
    std::vector<Eigen::Vector2d> points;
    for (const cell::Point2& point : path.points) points.push_back(ToBase(fix, point));
    paths.push_back(std::move(points));
  }
  return paths;
}

std::vector<TripWindow> TripWindows(const cell::Fixture& fixture) {
  const Eigen::Affine3d nominal = NominalFix(fixture);
  std::vector<TripWindow> windows;
  for (const ExpectedTrip& trip : ExpectedTrips(fixture)) {
    const std::vector<cell::Point2>& points = fixture.scan_paths[trip.path].points;
    const double length = (points[trip.leg + 1] - points[trip.leg]).norm();
    const double lo = std::max(0.0, trip.along_mm - fixture.trip_window_mm);
    const double hi = std::min(length, trip.along_mm + fixture.trip_window_mm);
    const Eigen::Vector2d start = points[trip.leg];
    windows.push_back(TripWindow{ToBase(nominal, trip.in_fixture), ToBase(nominal, start + lo * trip.leg_direction),
                                 ToBase(nominal, start + hi * trip.leg_direction)});
  }
  return windows;
}

std::string TripName(std::size_t index) { return fmt::format("T{}", index + 1); }

}  // namespace smtcal
