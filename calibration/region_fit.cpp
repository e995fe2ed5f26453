// How a shape sits among the calibrated regions (region_fit.h).
#include "calibration/region_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/check.h"

namespace smtcal {

bool RegionFit::fits() const { return region != nullptr && past_mm() <= kRegionFitSlackMm; }

bool RegionFit::larger() const {
  if (region == nullptr) return false;
  return width() > region->x_mm.hi - region->x_mm.lo + kRegionFitSlackMm ||
         height() > region->y_mm.hi - region->y_mm.lo + kRegionFitSlackMm;
}

double RegionFit::past_mm() const { return std::max({past_x_lo, past_x_hi, past_y_lo, past_y_hi}); }

Eigen::Vector2d RegionFit::CentringMove() const {
  if (region == nullptr) return Eigen::Vector2d::Zero();
  return {(region->x_mm.lo + region->x_mm.hi) / 2 - (x_lo + x_hi) / 2,
          (region->y_mm.lo + region->y_mm.hi) / 2 - (y_lo + y_hi) / 2};
}

RegionFit FitInRegion(const cell::Cell& cell, const std::vector<Eigen::Vector2d>& points) {
  SMTCAL_CHECK(!points.empty(), "FitInRegion needs a point");
  RegionFit fit;
  fit.x_lo = fit.y_lo = std::numeric_limits<double>::infinity();
  fit.x_hi = fit.y_hi = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& p : points) {
    fit.x_lo = std::min(fit.x_lo, p.x());
    fit.x_hi = std::max(fit.x_hi, p.x());
    fit.y_lo = std::min(fit.y_lo, p.y());
    fit.y_hi = std::max(fit.y_hi, p.y());
  }
  const Eigen::Vector2d centre((fit.x_lo + fit.x_hi) / 2, (fit.y_lo + fit.y_hi) / 2);
  fit.worst_point = centre;
  fit.region = cell.RegionAt(centre);
  if (fit.region == nullptr) {
    double most = 0;
    for (const cell::Region& region : cell.regions) {
      const double w = std::min(fit.x_hi, region.x_mm.hi) - std::max(fit.x_lo, region.x_mm.lo);
      const double h = std::min(fit.y_hi, region.y_mm.hi) - std::max(fit.y_lo, region.y_mm.lo);
      // A shape of no width or height overlaps by its length along the other axis.
      if (w < 0 || h < 0) continue;
      const double overlap = std::max(w, 0.0) * std::max(h, 0.0) + 1e-12 * (w + h);
      if (overlap > most) {
        most = overlap;
        fit.region = &region;
      }
    }
  }
  if (fit.region == nullptr) {
    fit.past_x_lo = fit.past_x_hi = fit.past_y_lo = fit.past_y_hi = std::numeric_limits<double>::infinity();
    return fit;
  }
  const cell::Region& region = *fit.region;
  double farthest = kRegionFitSlackMm;
  for (const Eigen::Vector2d& p : points) {
    const double past[4] = {region.x_mm.lo - p.x(), p.x() - region.x_mm.hi, region.y_mm.lo - p.y(),
                            p.y() - region.y_mm.hi};
    fit.past_x_lo = std::max(fit.past_x_lo, past[0]);
    fit.past_x_hi = std::max(fit.past_x_hi, past[1]);
    fit.past_y_lo = std::max(fit.past_y_lo, past[2]);
    fit.past_y_hi = std::max(fit.past_y_hi, past[3]);
    const double most = *std::max_element(std::begin(past), std::end(past));
    if (most > farthest) {
      farthest = most;
      fit.worst_point = p;
    }
  }
  return fit;
}

}  // namespace smtcal
