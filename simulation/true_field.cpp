// The virtual cell's true error field F_true (simulation/true_field.h).
#include "simulation/true_field.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "calibration/fixture_geometry.h"
#include "simulation/sim_random.h"

namespace smtcal {
namespace {

bool SameName(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// Every node moved by a normal draw of its mean's standard error; nodes
// without stddev or count stay (nothing says how far off they are).
ErrorTable Perturbed(ErrorTable table, double scale, SimRandom& random) {
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = table[axis];
    for (std::size_t k = 0; k < t.error_mm.size(); ++k) {
      const double draw = random.Normal();
      if (k >= t.stddev_mm.size() || k >= t.count.size() || !t.stddev_mm[k] || t.count[k] <= 0) continue;
      t.error_mm[k] += scale * draw * *t.stddev_mm[k] / std::sqrt(static_cast<double>(t.count[k]));
    }
  }
  return table;
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
    if (given != nullptr) {
      maps_.emplace_back(given->table);
    } else if (spec.tables == TruthTables::kDerived && spec.noise) {
      maps_.emplace_back(Perturbed(region.table, spec.perturbation_scale, random));
    } else if (spec.tables != TruthTables::kNone) {
      maps_.emplace_back(region.table);
    }
  }
  const double angle = spec.rotation_deg * kRadPerDeg;
  const double scale = 1 + spec.scale_ppm * 1e-6;
  Eigen::Matrix2d rotation;
  rotation << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  linear_minus_identity_ = scale * rotation - Eigen::Matrix2d::Identity();
  about_ = spec.about_mm;
  offset_ = spec.offset_mm;
}

Eigen::Vector2d TrueField::TableError(const Eigen::Vector2d& n) const {
  const CalibrationMap* nearest = nullptr;
  double nearest_distance = 0;
  for (const CalibrationMap& map : maps_) {
    const double distance = DistanceToRect(map.domain(), n);
    if (distance == 0) return map.Delta(n);
    if (nearest == nullptr || distance < nearest_distance) {
      nearest = &map;
      nearest_distance = distance;
    }
  }
  if (nearest == nullptr) return Eigen::Vector2d::Zero();
  if (outside_ == TruthOutside::kClamp) return nearest->Delta(n);
  const double weight = fade_mm_ > 0 ? std::max(0.0, 1 - nearest_distance / fade_mm_) : 0.0;
  return weight * nearest->Delta(n);
}

Eigen::Vector2d TrueField::Actual(const Eigen::Vector2d& commanded) const {
  return commanded + TableError(commanded) + linear_minus_identity_ * (commanded - about_) + offset_;
}

}  // namespace smtcal
