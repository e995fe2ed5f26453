// The geometry of a fixture's marker scan (the paper's periphery calibration,
// docs/periphery.md): the fixture frame FIX as a homogeneous matrix, the
// marker edges as lines, the V-shaped scan paths in base coordinates, and the
// trips the sensor is expected to make along them.
//
// FIX is planar: the board moves in the robot's x-y plane, so FIX maps a
// fixture point (x, y, z) to the base frame with a 2 x 2 linear part
// [n o] (x and y), translation p = S1 = (p_x, p_y, 0), and z passed through
// (a = (0, 0, 1)). The paper's Eq. 4 does not make [n o] exactly orthonormal
// (n = (S2 - S1)/L1, o = (S3 - S1)/L2 from measured crossings), and the
// rigid-scale estimator scales it, so FIX is an Eigen::Affine3d: its
// inverse() is the true inverse of whatever matrix the estimator produced
// (Isometry3d::inverse() would transpose the linear part).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "calibration/cell.h"

namespace smtcal {

inline constexpr double kRadPerDeg = 0.017453292519943295;  // pi / 180
inline constexpr double kDegPerRad = 57.29577951308232;     // 180 / pi

// FIX of a planar pose: the fixture origin (S1) at `origin` in the base
// frame, its x axis (n) at `angle_rad` from the base x axis, lengths scaled
// by `scale` (1 for a rigid board).
Eigen::Affine3d PlanarFix(const Eigen::Vector2d& origin, double angle_rad, double scale = 1);
// FIX at the fixture's nominal pose (cell file: origin_mm, angle_deg).
Eigen::Affine3d NominalFix(const cell::Fixture& fixture);

// A fixture point mapped to the base frame (x, y only).
Eigen::Vector2d ToBase(const Eigen::Affine3d& fix, const Eigen::Vector2d& in_fixture);
// A base point mapped to fixture coordinates through FIX^-1 (x, y only).
Eigen::Vector2d ToFixtureFrame(const Eigen::Affine3d& fix, const Eigen::Vector2d& in_base);
// The fixture origin p in the base frame.
Eigen::Vector2d FixOrigin(const Eigen::Affine3d& fix);
// The angle of the fixture's x axis n against the base x axis (radians,
// -pi..pi): atan2(n_y, n_x).
double FixAngleRad(const Eigen::Affine3d& fix);
// The angle of b relative to a, wrapped to -pi..pi (atan2 of their
// linear parts' x axes; no subtraction of wrapped angles).
double RelativeAngleRad(const Eigen::Affine3d& a, const Eigen::Affine3d& b);

// A marker edge's line in fixture coordinates: normal . f = offset, with a
// unit normal (the edge direction turned left by 90 degrees).
struct EdgeLine {
  Eigen::Vector2d normal = Eigen::Vector2d::UnitY();
  double offset = 0;
};
// Requires an edge of non-zero length (the cell loader checks it).
EdgeLine EdgeLineOf(const cell::MarkerEdge& edge);

// One trip the scan is expected to make: where a leg of a scan path crosses
// a marker edge segment. Trips are numbered in path order (T1 = index 0):
// the first path's legs first, along each leg from its start.
struct ExpectedTrip {
  std::size_t path = 0;  // index into Fixture::scan_paths
  std::size_t leg = 0;   // leg k runs from points[k] to points[k + 1]
  int edge = 0;          // 0..3: p1..p4 (Fixture::edges)
  Eigen::Vector2d in_fixture = Eigen::Vector2d::Zero();  // the crossing, fixture coordinates
  double along_mm = 0;   // its distance from the leg's start
  Eigen::Vector2d leg_direction = Eigen::Vector2d::UnitX();  // unit, fixture coordinates
};
// Every crossing of every leg with every edge segment, ends included (a leg
// parallel to an edge crosses it nowhere). Independent of the fixture's
// pose: the paths move with the board.
std::vector<ExpectedTrip> ExpectedTrips(const cell::Fixture& fixture);

// The expected trips in the base frame for a fixture pose, in trip order.
std::vector<Eigen::Vector2d> NominalTrips(const cell::Fixture& fixture, const Eigen::Affine3d& fix);
// The scan paths in the base frame for a fixture pose: one polyline per path.
std::vector<std::vector<Eigen::Vector2d>> ScanPathsInBase(const cell::Fixture& fixture,
                                                          const Eigen::Affine3d& fix);

// The window of a trip along its leg in the base frame at the nominal pose:
// the leg points within trip_window_mm of the nominal trip, clipped to the
// leg (for reports and for driving the scan).
struct TripWindow {
  Eigen::Vector2d nominal = Eigen::Vector2d::Zero();  // the expected trip
  Eigen::Vector2d from = Eigen::Vector2d::Zero();     // window start on the leg
  Eigen::Vector2d to = Eigen::Vector2d::Zero();       // window end on the leg
};
std::vector<TripWindow> TripWindows(const cell::Fixture& fixture);

// "T3" for index 2.
std::string TripName(std::size_t index);

}  // namespace smtcal
