// Test fixtures for the periphery calibration, built in code: the paper
// cell's board (examples/paper-cell/paper.cell.toml describes the same one),
// random smooth error tables as regions, and simulated scans. Shared by
// tests/unit/fixture_*_test.cpp and tests/bench/bench_fixture.cpp.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "calibration/cell.h"
#include "calibration/error_table.h"
#include "calibration/fixture_geometry.h"

namespace smtcal::test {

inline std::uint64_t FixtureSeed(std::uint64_t fallback = 19940101) {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : fallback;
}

inline double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// The paper cell's board: nominal origin (138, 40), angle 0, L1 = 190,
// L2 = 90, markers at two corners, two V paths, trips T1..T8 on
// p2, p1, p1, p2, p3, p4, p4, p3.
inline cell::Fixture PaperFixture(cell::Estimator estimator = cell::Estimator::kPaper) {
  cell::Fixture f;
  f.name = "Board";
  f.origin_mm = {138, 40};
  f.angle_deg = 0;
  f.l1_mm = 190;
  f.l2_mm = 90;
  f.edges[0] = {"p1", {0, 0}, {8, 0}, {}};
  f.edges[1] = {"p2", {0, 0}, {0, 8}, {}};
  f.edges[2] = {"p3", {190, 82}, {190, 90}, {}};
  f.edges[3] = {"p4", {182, 90}, {190, 90}, {}};
  cell::ScanPath v1, v2;
  v1.name = "V1";
  v1.points = {cell::Point2(-3, 6), cell::Point2(6, -3), cell::Point2(-3, 12)};
  v2.name = "V2";
  v2.points = {cell::Point2(193, 84), cell::Point2(184, 93), cell::Point2(193, 78)};
  f.scan_paths = {v1, v2};
  f.scan_z_mm = -2;
  f.scan_speed_mm_s = 12;
  f.trip_window_mm = 3;
  f.sensor_accuracy_mm = 0.05;
  f.estimator = estimator;
  f.max_shift_mm = 2;
  f.max_rotation_deg = 0.5;
  f.length_tolerance_mm = 0.1;
  f.squareness_deg = 0.2;
  f.max_line_residual_mm = 0.05;
  return f;
}

// The same board with the example's hairpin paths (examples/paper-cell/
// paper.cell.toml): marker 2's path first, every leg across its edge at a
// right angle through the edge's middle; two-stage probing at 40 and 8 mm/s.
inline cell::Fixture HairpinFixture(cell::Estimator estimator = cell::Estimator::kRigid) {
  cell::Fixture f = PaperFixture(estimator);
  cell::ScanPath m2, m1;
  m2.name = "M2";
  m2.points = {cell::Point2(194.1, 85.9), cell::Point2(185.9, 85.9), cell::Point2(185.9, 94.1),
               cell::Point2(186.1, 94.1), cell::Point2(186.1, 86.1), cell::Point2(194.1, 86.1)};
  m1.name = "M1";
  m1.points = {cell::Point2(-2.6, 3.9), cell::Point2(3.9, 3.9), cell::Point2(3.9, -2.6),
               cell::Point2(4.1, -2.6), cell::Point2(4.1, 4.1), cell::Point2(-2.6, 4.1)};
  f.scan_paths = {m2, m1};
  f.scan_speed_mm_s = 40;
  f.latch_speed_mm_s = 8;
  f.trip_window_mm = 4.5;
  f.max_line_residual_mm = 0.07;
  return f;
}

// Where a straight move from `from` to `to` (base frame) crosses the line
// n . x = d (base frame), as a parameter along the move; nullopt when
// parallel.
inline std::optional<Eigen::Vector2d> CrossLine(const Eigen::Vector2d& from, const Eigen::Vector2d& to,
                                                const Eigen::Vector2d& normal, double offset) {
  const double along = normal.dot(to - from);
  if (std::abs(along) < 1e-12) return std::nullopt;
  const double t = (offset - normal.dot(from)) / along;
  return from + t * (to - from);
}

// A simulated scan: the sensor follows the scan paths at the nominal pose
// and trips where each leg crosses its edge's line on the board at its true
// pose `truth` (any affine FIX), `sensor_mm[k]` across the edge from it (the
// detector's error) while the robot stands `robot_mm[k]` from where it was
// commanded (its repeatability). Returns the commanded trip points.
inline std::vector<Eigen::Vector2d> SimulateTrips(const cell::Fixture& fixture, const Eigen::Affine3d& truth,
                                                  const std::vector<double>& sensor_mm = {},
                                                  const std::vector<Eigen::Vector2d>& robot_mm = {}) {
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const Eigen::Matrix2d a = truth.linear().topLeftCorner<2, 2>();
  std::vector<Eigen::Vector2d> trips;
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const ExpectedTrip& e = expected[k];
    const auto& points = fixture.scan_paths[e.path].points;
    // The leg in the base frame, where the robot is commanded.
    const Eigen::Vector2d from = ToBase(nominal, points[e.leg]), to = ToBase(nominal, points[e.leg + 1]);
    // The edge line in the base frame: m . x = d + m . p with m = A^-T n.
    const EdgeLine line = EdgeLineOf(fixture.edges[static_cast<std::size_t>(e.edge)]);
    Eigen::Vector2d m = a.inverse().transpose() * line.normal;
    double offset = line.offset + m.dot(FixOrigin(truth));
    const double length = m.norm();
    m /= length;
    offset /= length;
    // The robot really stands at commanded + r; it trips where that point is
    // sensor_mm across the line: m . (c + r) = offset + e.
    const double e_mm = k < sensor_mm.size() ? sensor_mm[k] : 0;
    const Eigen::Vector2d r = k < robot_mm.size() ? robot_mm[k] : Eigen::Vector2d::Zero();
    std::optional<Eigen::Vector2d> trip = CrossLine(from, to, m, offset + e_mm - m.dot(r));
    trips.push_back(trip ? *trip : from);
  }
  return trips;
}

inline std::vector<std::optional<Eigen::Vector2d>> Present(const std::vector<Eigen::Vector2d>& trips) {
  return {trips.begin(), trips.end()};
}

// A random smooth error table on [x0, x0 + w] x [y0, y0 + h] with `nodes`
// lines per axis (the y table's grid offset by a few micrometres, as the
// paper measured), errors up to `amplitude` mm, slopes far below the
// validation limits.
inline ErrorTable RandomSmoothTable(std::mt19937_64& rng, double x0, double y0, double w, double h, int nodes,
                                    double amplitude) {
  ErrorTable table;
  table.name = "random";
  const double kx = Uniform(rng, 0.5, 2) * 2 * std::numbers::pi / w;
  const double ky = Uniform(rng, 0.5, 2) * 2 * std::numbers::pi / h;
  const double phase = Uniform(rng, 0, 6.28), tilt = Uniform(rng, -1, 1) * amplitude / w;
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = table[axis];
    const double shift = axis == TableAxis::Y ? 0.004 : 0;
    for (int i = 0; i < nodes; ++i) t.xs.push_back(x0 + shift + w * i / (nodes - 1));
    for (int j = 0; j < nodes; ++j) t.ys.push_back(y0 - shift + h * j / (nodes - 1));
    const double sign = axis == TableAxis::X ? 1 : -1;
    for (int j = 0; j < nodes; ++j) {
      for (int i = 0; i < nodes; ++i) {
        const double x = t.xs[static_cast<std::size_t>(i)], y = t.ys[static_cast<std::size_t>(j)];
        t.error_mm.push_back(amplitude * 0.7 * std::sin(kx * (x - x0) + sign * ky * (y - y0) + phase) +
                             tilt * (x - x0) - 0.3 * amplitude * sign);
      }
    }
  }
  return table;
}

// A region around a table: bounds `margin` inside its domain.
inline cell::Region RegionOf(std::string name, ErrorTable table, double margin = 0.5,
                             OutsidePolicy outside = OutsidePolicy::kError) {
  cell::Region region;
  region.name = std::move(name);
  const Rect domain = TableDomain(table);
  region.x_mm = {domain.x0 + margin, domain.x1 - margin};
  region.y_mm = {domain.y0 + margin, domain.y1 - margin};
  region.difficulty_level = 2;
  region.difficulty_axes = {cell::TaskAxis::X, cell::TaskAxis::Y};
  region.table = std::move(table);
  region.tolerance_mm = 0.1;
  region.outside = outside;
  return region;
}

// At most one fault in a random one of the trips, each kind with
// probability `each`: the trip missing, far off (up to 4 mm), off (up to
// 0.3 mm), so the scan's checks refuse some scans.
inline void InjectTripFault(std::vector<std::optional<Eigen::Vector2d>>& trips, std::mt19937_64& rng, double each) {
  const double fault = Uniform(rng, 0, 1);
  const std::size_t k = std::uniform_int_distribution<std::size_t>(0, trips.size() - 1)(rng);
  if (fault < each) {
    trips[k].reset();
  } else if (fault < 2 * each) {
    *trips[k] += Eigen::Vector2d(Uniform(rng, -4, 4), Uniform(rng, -4, 4));
  } else if (fault < 3 * each) {
    *trips[k] += Eigen::Vector2d(Uniform(rng, -0.3, 0.3), Uniform(rng, -0.3, 0.3));
  }
}

}  // namespace smtcal::test
