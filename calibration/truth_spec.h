// What is really true of a cell, as opposed to what its files measured: the
// robot's true error field, how the fixture board really sits each cycle, and
// how accurate the sensor and the robot really are (docs/simulate.md, "The
// truth file"). A truth file states it (frontend/truth_toml.h reads one); the
// virtual cell (simulation/) runs programs against it. Plain data: nothing
// here needs a program.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/source.h"
#include "calibration/cell.h"
#include "calibration/error_table.h"
#include "calibration/limits.h"

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

// Slow changes of the cell, cycle by cycle (the drifts `smtcal monitor`
// watches for). Cycle c (1, 2, ... of each Cycle statement) is off by
// max(0, c - start_cycle) steps of each rate.
struct DriftModel {
  long start_cycle = 0;
  Eigen::Vector2d board_mm_per_cycle = Eigen::Vector2d::Zero();  // the board's pose walks (the fixture wearing)
  double board_deg_per_cycle = 0;                                // ... and turns
  // The robot's scale changes (warming): F_true(n) gains s (n - about), s
  // growing by this many ppm a cycle; the tables do not know it.
  double robot_scale_ppm_per_cycle = 0;
  Eigen::Vector2d robot_scale_about_mm = Eigen::Vector2d::Zero();
  // The marker sensor's threshold: it trips this much later entering a
  // marker and earlier leaving it (a dirty lens sees the markers smaller).
  double sensor_threshold_mm_per_cycle = 0;
  double sensor_accuracy_mm_per_cycle = 0;  // its scatter grows (added to the accuracy)

  bool any() const {
    return !board_mm_per_cycle.isZero() || board_deg_per_cycle != 0 || robot_scale_ppm_per_cycle != 0 ||
           sensor_threshold_mm_per_cycle != 0 || sensor_accuracy_mm_per_cycle != 0;
  }
  // The steps of cycle c (1-based).
  double Steps(long cycle) const { return cycle > start_cycle ? static_cast<double>(cycle - start_cycle) : 0.0; }
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
  DriftModel drift;
};

// The true field outside the tables is scaled to its largest magnitude over
// the robot's reach, sampled on a grid every correlation length / 8 in x and
// y (simulation/true_field.h). The grid's size along one axis and in all;
// the cell and truth loaders refuse a correlation length that makes it more
// than limits::kMaxTrueFieldSamples, before any work starts.
inline double TrueFieldStepMm(double correlation_mm) {
  return correlation_mm / limits::kTrueFieldStepsPerCorrelation;
}
inline double TrueFieldSamplesAlong(const cell::Interval& reach, double correlation_mm) {
  return std::floor((reach.hi - reach.lo) / TrueFieldStepMm(correlation_mm)) + 1;
}
inline double TrueFieldSamples(const cell::Robot& robot, double correlation_mm) {
  return TrueFieldSamplesAlong(robot.limits[0], correlation_mm) * TrueFieldSamplesAlong(robot.limits[1], correlation_mm);
}
// The smallest correlation length whose grid fits: the step s with
// (sx / s + 1)(sy / s + 1) <= kMaxTrueFieldSamples, for the message that
// refuses a smaller one.
inline double MinTrueFieldCorrelationMm(const cell::Robot& robot) {
  const double sx = robot.limits[0].hi - robot.limits[0].lo, sy = robot.limits[1].hi - robot.limits[1].lo;
  const double n = limits::kMaxTrueFieldSamples - 1;
  const double step = ((sx + sy) + std::sqrt((sx + sy) * (sx + sy) + 4 * n * sx * sy)) / (2 * n);
  return step * limits::kTrueFieldStepsPerCorrelation * 1.001;
}

}  // namespace smtcal
