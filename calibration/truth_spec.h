// What is really true of a cell, as opposed to what its files measured: the
// robot's true error field, how the fixture board really sits each cycle, and
// how accurate the sensor and the robot really are (docs/simulate.md, "The
// truth file"). A truth file states it (frontend/truth_toml.h reads one); the
// virtual cell (simulation/) runs programs against it. Plain data: nothing
// here needs a program.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/source.h"
#include "calibration/error_table.h"

namespace smtcal {

enum class TruthTables { kDerived, kCell, kNone };
// Outside every table domain: `field` (default), a smooth random field whose
// size is the robot's uncalibrated accuracy, into which each table's edge
// value fades over the correlation length; `fade`, the edge value fading to
// zero over fade_mm (a robot accurate far from its tables: kinder than any
// cell file says, kept for comparison); `clamp`, the edge value everywhere.
enum class TruthOutside { kField, kFade, kClamp };
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
  // derived: multiplies the departure between the nodes, whose size is the
  // region's interpolation estimate (cell::Region::interpolation)
  double interpolation_scale = 1;
  TruthOutside outside = TruthOutside::kField;
  double fade_mm = 10;
  // The field's size and correlation length; default: the cell's robot keys
  // (uncalibrated_accuracy_mm, uncalibrated_correlation_mm).
  std::optional<double> uncalibrated_accuracy_mm;
  std::optional<double> uncalibrated_correlation_mm;
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
  // Default: the cell's robot.servo_period_s (the trips' latch latency).
  std::optional<double> servo_period_s;
  // false: no sensor error, no repeatability noise, no trip latency (and no
  // table perturbation for `derived`): F_true and the board pose alone decide.
  bool noise = true;
};

}  // namespace smtcal
