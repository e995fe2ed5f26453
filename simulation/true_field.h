// The virtual cell's true error field F_true (docs/simulate.md): where the
// robot really goes for a command. The measured error tables of the cell are
// noisy samples of F_true; by default F_true is derived from them, and a truth
// file (calibration/truth_spec.h, read by frontend/truth_toml.h) can give it
// explicitly.
//
//   F_true(n) = n + Delta_true(n) + (S R(theta) - I)(n - about) + offset
//
// Delta_true per region: the cell's table with every node moved by a normal
// draw of its mean's standard error stddev / sqrt(n) (`derived`), the cell's
// table as it is (`cell`), a true table file, or nothing (`none`), bilinear
// between the nodes. Outside every table domain: the nearest domain's edge
// value fading linearly to zero within fade_mm (`fade`), or kept (`clamp`).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calibration/cell.h"
#include "calibration/error_table.h"
#include "calibration/truth_spec.h"

namespace smtcal {

// F_true for one run (the perturbation is drawn once, from `seed`).
class TrueField {
 public:
  TrueField(const cell::Cell& cell, const TruthSpec& spec, std::uint64_t seed);

  // Where the robot really goes for the command n (without repeatability).
  Eigen::Vector2d Actual(const Eigen::Vector2d& commanded) const;

 private:
  Eigen::Vector2d TableError(const Eigen::Vector2d& n) const;

  std::vector<CalibrationMap> maps_;
  TruthOutside outside_;
  double fade_mm_;
  Eigen::Matrix2d linear_minus_identity_ = Eigen::Matrix2d::Zero();
  Eigen::Vector2d about_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();
};

}  // namespace smtcal
