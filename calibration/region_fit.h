// How a shape in the robot base frame sits among the cell's calibrated
// regions: a fixture's pocket at its nominal pose (`smtcal cell check`), the
// parts of an imported board as placed (`smtcal import`), their marks in the
// picture of the cell. A part placed where no region's table corrects the
// robot is refused by verify, so a pocket or a board that sticks out of its
// region is worth saying before anything is placed.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "calibration/cell.h"

namespace smtcal {

struct RegionFit {
  // The region the shape belongs to: the one holding the centre of its
  // bounding box, else the one its bounding box overlaps most (the first in
  // the cell's order among equals); null when it overlaps none.
  const cell::Region* region = nullptr;
  // The shape's bounding box (robot base frame, mm).
  double x_lo = 0, x_hi = 0, y_lo = 0, y_hi = 0;
  // How far the shape reaches past each edge of the region (mm, 0 when it
  // does not): past x_mm.lo, x_mm.hi, y_mm.lo, y_mm.hi. Infinite without a region.
  double past_x_lo = 0, past_x_hi = 0, past_y_lo = 0, past_y_hi = 0;
  // The point of the shape farthest past an edge (its bounding box's centre
  // when it fits or has no region).
  Eigen::Vector2d worst_point = Eigen::Vector2d::Zero();

  double width() const { return x_hi - x_lo; }
  double height() const { return y_hi - y_lo; }
  // Within the region (to kRegionFitSlackMm).
  bool fits() const;
  // Larger than the region along x or y: no translation makes it fit.
  bool larger() const;
  // The farthest it reaches past an edge.
  double past_mm() const;
  // The translation (base frame) that moves its bounding box's centre onto
  // the region's centre: when it is not larger(), the move that makes it fit
  // with the most room on every side.
  Eigen::Vector2d CentringMove() const;
};

// Rounding slack: a shape that reaches past an edge by no more than this
// still fits (the 1 nm of computed corners, a list's 0.1 µm resolution).
inline constexpr double kRegionFitSlackMm = 1e-6;

// `points` (robot base frame, at least one) against `cell`'s regions.
RegionFit FitInRegion(const cell::Cell& cell, const std::vector<Eigen::Vector2d>& points);

}  // namespace smtcal
