// The virtual cell's true error field F_true (simulation/true_field.h).
#include "simulation/true_field.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

#include "base/check.h"
#include "calibration/fixture_geometry.h"
#include "calibration/limits.h"
#include "simulation/sim_random.h"

namespace smtcal {
namespace {

bool SameName(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// Every node moved by a normal draw of its mean's standard error; a node
// without stddev and count counts as one measurement with the robot's
// repeatability as its spread (calibration/placement_budget.h does the same).
ErrorTable Perturbed(ErrorTable table, double scale, double repeatability_mm, SimRandom& random) {
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = table[axis];
    for (std::size_t k = 0; k < t.error_mm.size(); ++k) {
      const double draw = random.Normal();
      t.error_mm[k] += scale * draw * t.StandardErrorMm(k).value_or(repeatability_mm);
    }
  }
  return table;
}

// sin(pi u) for u the position of v in grid lines (u = i + s in cell i,
// clamped to the lines), as (-1)^i sin(pi s): exactly 0 on every line.
double SineOfGridPosition(const std::vector<double>& lines, double v) {
  if (v <= lines.front() || v >= lines.back()) return 0;
  const auto above = std::upper_bound(lines.begin(), lines.end(), v);
  const std::size_t i = static_cast<std::size_t>(above - lines.begin()) - 1;
  const double sine = std::sin(std::numbers::pi * (v - lines[i]) / (lines[i + 1] - lines[i]));
  return i % 2 == 0 ? sine : -sine;
}

double DistanceToRect(const Rect& r, const Eigen::Vector2d& p) {
  const double dx = std::max({r.x0 - p.x(), 0.0, p.x() - r.x1});
  const double dy = std::max({r.y0 - p.y(), 0.0, p.y() - r.y1});
  return std::hypot(dx, dy);
}

}  // namespace

TrueField::TrueField(const cell::Cell& cell, const TruthSpec& spec, std::uint64_t seed)
    : outside_(spec.outside), fade_mm_(spec.fade_mm) {
  SimRandom random(seed);
  for (const cell::Region& region : cell.regions) {
    const TruthRegionTable* given = nullptr;
    for (const TruthRegionTable& t : spec.region_tables) {
      if (SameName(t.region, region.name)) given = &t;
    }
    Departure departure;
    if (given == nullptr && spec.tables == TruthTables::kDerived) {
      for (TableAxis axis : kTableAxes) {
        const int a = static_cast<int>(axis);
        departure.xs[a] = region.table[axis].xs;
        departure.ys[a] = region.table[axis].ys;
      }
      departure.size_mm = spec.interpolation_scale * region.interpolation.PerAxisMm();
    }
    if (given != nullptr) {
      maps_.emplace_back(given->table);
    } else if (spec.tables == TruthTables::kDerived && spec.noise) {
      maps_.emplace_back(Perturbed(region.table, spec.perturbation_scale,
                                   spec.repeatability_mm.value_or(cell.robot.repeatability_mm), random));
    } else if (spec.tables != TruthTables::kNone) {
      maps_.emplace_back(region.table);
    }
    if (spec.tables != TruthTables::kNone || given != nullptr) departures_.push_back(std::move(departure));
  }
  const double angle = spec.rotation_deg * kRadPerDeg;
  const double scale = 1 + spec.scale_ppm * 1e-6;
  Eigen::Matrix2d rotation;
  rotation << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  linear_minus_identity_ = scale * rotation - Eigen::Matrix2d::Identity();
  about_ = spec.about_mm;
  offset_ = spec.offset_mm;

  // The uncalibrated field: drawn after the tables, from the same stream.
  const std::optional<double> declared =
      spec.uncalibrated_accuracy_mm ? spec.uncalibrated_accuracy_mm : cell.robot.uncalibrated_accuracy_mm;
  accuracy_mm_ = declared.value_or(kAssumedUncalibratedAccuracyMm);
  accuracy_assumed_ = !declared;
  correlation_mm_ = spec.uncalibrated_correlation_mm.value_or(cell.robot.uncalibrated_correlation_mm);
  constexpr int kWavesPerAxis = 6;
  for (std::vector<Wave>& axis : waves_) {
    for (int m = 0; m < kWavesPerAxis; ++m) {
      const double wavelength = correlation_mm_ * random.Uniform(3, 6);
      const double direction = random.Uniform(0, 2 * std::numbers::pi);
      Wave wave;
      wave.k = (2 * std::numbers::pi / wavelength) * Eigen::Vector2d(std::cos(direction), std::sin(direction));
      wave.phase = random.Uniform(0, 2 * std::numbers::pi);
      wave.weight = random.Uniform(0.5, 1);
      axis.push_back(wave);
    }
  }
  // The departures' directions: drawn after the field, from the same stream,
  // so that they do not move the draws above.
  for (Departure& departure : departures_) {
    for (int a = 0; a < 2; ++a) {
      const double theta = random.Uniform(0, 2 * std::numbers::pi);
      const double norm = std::abs(std::cos(theta)) + std::abs(std::sin(theta));
      departure.along_x[static_cast<std::size_t>(a)] = std::cos(theta) / norm;
      departure.along_y[static_cast<std::size_t>(a)] = std::sin(theta) / norm;
    }
  }
  // Scaled so that its largest magnitude over the robot's reach (on a grid of
  // L / 8) is A: the field reaches the declared size, and no more. The
  // grid's size was bounded by the cell and truth loaders
  // (calibration/truth_spec.h); counted in integers, so a step far below
  // the coordinates' resolution cannot stall the loop.
  field_scale_ = 1;
  const cell::Interval& xs = cell.robot.limits[0];
  const cell::Interval& ys = cell.robot.limits[1];
  SMTCAL_CHECK(TrueFieldSamples(cell.robot, correlation_mm_) <= limits::kMaxTrueFieldSamples,
               "the true field's grid is larger than the loaders allow");
  const double step = TrueFieldStepMm(correlation_mm_);
  const long nx = static_cast<long>(TrueFieldSamplesAlong(xs, correlation_mm_));
  const long ny = static_cast<long>(TrueFieldSamplesAlong(ys, correlation_mm_));
  double largest = 0;
  for (long i = 0; i < nx; ++i) {
    for (long j = 0; j < ny; ++j) {
      const Eigen::Vector2d n(xs.lo + static_cast<double>(i) * step, ys.lo + static_cast<double>(j) * step);
      largest = std::max(largest, Uncalibrated(n).norm());
    }
  }
  field_scale_ = largest > 0 ? accuracy_mm_ / largest : 0.0;
}

Eigen::Vector2d TrueField::Uncalibrated(const Eigen::Vector2d& n) const {
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  for (int a = 0; a < 2; ++a) {
    for (const Wave& wave : waves_[static_cast<std::size_t>(a)]) g[a] += wave.weight * std::cos(wave.k.dot(n) + wave.phase);
  }
  return field_scale_ * g;
}

Eigen::Vector2d TrueField::Departure::At(const Eigen::Vector2d& n) const {
  Eigen::Vector2d d = Eigen::Vector2d::Zero();
  for (std::size_t a = 0; a < 2; ++a) {
    if (size_mm[static_cast<int>(a)] == 0) continue;
    d[static_cast<int>(a)] = size_mm[static_cast<int>(a)] * (along_x[a] * SineOfGridPosition(xs[a], n.x()) +
                                                             along_y[a] * SineOfGridPosition(ys[a], n.y()));
  }
  return d;
}

Eigen::Vector2d TrueField::TableError(const Eigen::Vector2d& n) const {
  const CalibrationMap* nearest = nullptr;
  double nearest_distance = 0;
  for (std::size_t m = 0; m < maps_.size(); ++m) {
    const CalibrationMap& map = maps_[m];
    const double distance = DistanceToRect(map.domain(), n);
    if (distance == 0) return map.Delta(n) + departures_[m].At(n);
    if (nearest == nullptr || distance < nearest_distance) {
      nearest = &map;
      nearest_distance = distance;
    }
  }
  switch (outside_) {
    case TruthOutside::kField: {
      if (nearest == nullptr) return Uncalibrated(n);
      const double weight = std::max(0.0, 1 - nearest_distance / correlation_mm_);
      return weight * nearest->Delta(n) + (1 - weight) * Uncalibrated(n);
    }
    case TruthOutside::kClamp: return nearest != nullptr ? nearest->Delta(n) : Eigen::Vector2d::Zero();
    case TruthOutside::kFade: {
      if (nearest == nullptr) return Eigen::Vector2d::Zero();
      const double weight = fade_mm_ > 0 ? std::max(0.0, 1 - nearest_distance / fade_mm_) : 0.0;
      return weight * nearest->Delta(n);
    }
  }
  return Eigen::Vector2d::Zero();
}

Eigen::Vector2d TrueField::Actual(const Eigen::Vector2d& commanded) const {
  return commanded + TableError(commanded) + linear_minus_identity_ * (commanded - about_) + offset_;
}

}  // namespace smtcal
