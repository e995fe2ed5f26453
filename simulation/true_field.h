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
// between the nodes (a node that states no stddev and count moves by a draw
// of the robot's repeatability, as the budget assumes). `derived` also
// departs from the bilinear interpolation between the nodes by as much as the
// region's interpolation estimate E says (cell::Region::interpolation, the
// budget's figure), per axis table
//
//   D(n) = E (cos(theta) sin(pi u) + sin(theta) sin(pi v)) / (|cos(theta)| + |sin(theta)|),
//
// u and v the position in grid lines (u = i + s in cell i), theta drawn once
// per region and axis: smooth, zero at every node, of size E at the cell
// centres where the two terms agree. So the virtual cell is never kinder
// between the nodes than verify's estimate. Outside every table
// domain (TruthOutside): by default a smooth random field G whose largest
// magnitude over the robot's reach is the robot's uncalibrated accuracy A,
// with the nearest table's edge value fading into it linearly over the
// correlation length L:
//
//   Delta_true(n) = w E(n) + (1 - w) G(n),  w = max(0, 1 - d(n) / L),
//
// E the nearest domain's edge value, d the distance to that domain. G is a
// sum of plane waves per axis with wavelengths 3L..6L, random directions and
// phases, drawn once per run. `fade` and `clamp` are the older choices.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calibration/cell.h"
#include "calibration/error_table.h"
#include "calibration/truth_spec.h"

namespace smtcal {

// The field's size when neither the cell (robot.uncalibrated_accuracy_mm) nor
// the truth file declares it: the paper's robot with its gripper. The
// report says it was assumed.
inline constexpr double kAssumedUncalibratedAccuracyMm = 0.25;

// F_true for one run (the perturbation is drawn once, from `seed`).
class TrueField {
 public:
  TrueField(const cell::Cell& cell, const TruthSpec& spec, std::uint64_t seed);

  // Where the robot really goes for the command n (without repeatability).
  Eigen::Vector2d Actual(const Eigen::Vector2d& commanded) const;

  // The field's size outside the tables (mm), and whether it was assumed
  // (kAssumedUncalibratedAccuracyMm) because neither the cell nor the truth
  // declares it.
  double uncalibrated_accuracy_mm() const { return accuracy_mm_; }
  bool accuracy_assumed() const { return accuracy_assumed_; }

 private:
  struct Wave {
    Eigen::Vector2d k = Eigen::Vector2d::Zero();  // rad/mm
    double phase = 0;
    double weight = 0;
  };
  // A region's departure from its table's interpolation (derived only).
  struct Departure {
    std::array<std::vector<double>, 2> xs, ys;  // per axis table: its grid lines
    Eigen::Vector2d size_mm = Eigen::Vector2d::Zero();  // E per axis, times interpolation_scale
    std::array<double, 2> along_x{}, along_y{};          // cos(theta), sin(theta) normalised, per axis
    Eigen::Vector2d At(const Eigen::Vector2d& n) const;
  };
  Eigen::Vector2d TableError(const Eigen::Vector2d& n) const;
  Eigen::Vector2d Uncalibrated(const Eigen::Vector2d& n) const;  // G(n)

  std::vector<CalibrationMap> maps_;
  std::vector<Departure> departures_;  // one per map (size 0 where none)
  TruthOutside outside_;
  double fade_mm_;
  double accuracy_mm_ = 0;
  bool accuracy_assumed_ = false;
  double correlation_mm_ = 25;
  std::array<std::vector<Wave>, 2> waves_;  // per axis
  double field_scale_ = 0;                  // sum of waves -> mm, so that max |G| = A
  Eigen::Matrix2d linear_minus_identity_ = Eigen::Matrix2d::Zero();
  Eigen::Vector2d about_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();
};

}  // namespace smtcal
