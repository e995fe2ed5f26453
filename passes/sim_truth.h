// The virtual cell's true world (docs/simulate.md): where the robot really
// goes for a command (F_true), how the fixture board really sits each cycle,
// and how accurate the sensor and the robot really are. The measured error
// tables of the cell are noisy samples of F_true; by default F_true is derived
// from them, and a truth file (frontend/truth_toml.h) can give it explicitly.
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

#include "frontend/cell.h"
#include "frontend/source.h"
#include "passes/error_table.h"

namespace smtcal {

enum class TruthTables { kDerived, kCell, kNone };
enum class TruthOutside { kFade, kClamp };
enum class ShiftDistribution { kExponential, kNormal, kUniform, kFixed };

// A region's true table given in the truth file.
struct TruthRegionTable {
  std::string region;  // the cell region's name (case-insensitive)
  ErrorTable table;    // loaded and validated
  SourceRange range;   // the [[region]] table in the truth file
};

// The board's true pose each cycle, relative to the fixture's nominal pose:
// a shift of the origin S1 and a rotation about it.
struct BoardPoseModel {
  // exponential: direction uniform, length exponential with mean scale_mm;
  // normal: each axis normal with standard deviation scale_mm;
  // uniform: uniform in the disc of radius scale_mm; fixed: fixed_shift_mm.
  ShiftDistribution shift = ShiftDistribution::kExponential;
  double shift_scale_mm = 0.07;
  double shift_max_mm = 0.5;  // longer draws are drawn again (not for fixed)
  Eigen::Vector2d fixed_shift_mm = Eigen::Vector2d::Zero();
  // Rotation: normal with this standard deviation, drawn again beyond the
  // maximum; with `fixed` shift, fixed_rotation_deg.
  double rotation_sd_deg = 0.01;
  double rotation_max_deg = 0.05;
  double fixed_rotation_deg = 0;
};

struct TruthSpec {
  std::string path;  // the truth file; empty: defaults
  TruthTables tables = TruthTables::kDerived;
  double perturbation_scale = 1;  // derived: multiplies each node's standard error
  TruthOutside outside = TruthOutside::kFade;
  double fade_mm = 10;
  // The affine part, applied everywhere.
  Eigen::Vector2d offset_mm = Eigen::Vector2d::Zero();
  double rotation_deg = 0;
  Eigen::Vector2d about_mm = Eigen::Vector2d::Zero();
  double scale_ppm = 0;
  std::vector<TruthRegionTable> region_tables;
  BoardPoseModel board;
  // Defaults: the fixture's sensor_accuracy_mm and the robot's repeatability_mm.
  std::optional<double> sensor_accuracy_mm;
  std::optional<double> repeatability_mm;
  // false: no sensor error, no repeatability noise (and no table perturbation
  // for `derived`): F_true and the board pose alone decide.
  bool noise = true;
};

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
