// Process figures (calibration/capability.h).
#include "calibration/capability.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "calibration/placement_budget.h"

namespace smtcal {
namespace {

Capability Figures(long n, double tolerance_mm, const Eigen::Vector2d& mean, const Eigen::Matrix2d& covariance) {
  Capability c;
  c.placements = n;
  c.tolerance_mm = tolerance_mm;
  c.mean_mm = mean;
  c.sigma_mm = covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (int a = 0; a < 2; ++a) c.cmk[a] = Cmk(tolerance_mm, mean[a], c.sigma_mm[a]);
  c.reference_cmk = std::min(Cmk(kReferenceToleranceMm, mean[0], c.sigma_mm[0]),
                             Cmk(kReferenceToleranceMm, mean[1], c.sigma_mm[1]));
  return c;
}

}  // namespace

double Cmk(double tolerance_mm, double mean_mm, double sigma_mm) {
  const double margin = tolerance_mm - std::abs(mean_mm);
  if (sigma_mm <= 0) return margin > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  return margin / (3 * sigma_mm);
}

double CmkUpper(double limit, double mean, double sigma) {
  const double margin = limit - mean;
  if (sigma <= 0) return margin > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  return margin / (3 * sigma);
}

void SampleCapability::Add(const Eigen::Vector2d& error_mm, double tolerance_mm) {
  tolerance_mm_ = moments_.count() == 0 ? tolerance_mm : std::min(tolerance_mm_, tolerance_mm);
  moments_.Add(error_mm);
}

Capability SampleCapability::Result() const {
  if (moments_.count() == 0) return Capability{};
  // The sample covariance (n - 1); a single placement has no spread.
  const Eigen::Matrix2d covariance = moments_.Covariance();
  Capability c = Figures(moments_.count(), tolerance_mm_, moments_.mean(), covariance);
  c.ppm_outside = 1e6 * OutsideProbability(moments_.mean(), covariance, tolerance_mm_);
  return c;
}

void ModelCapability::Add(const Eigen::Vector2d& mean_mm, double bound_mm, const Eigen::Matrix2d& covariance_mm2,
                          double tolerance_mm) {
  // The unknown systematic part, in its worst direction: along the known
  // mean, else along the largest spread.
  Eigen::Vector2d direction = mean_mm;
  if (direction.norm() == 0) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance_mm2);
    direction = solver.eigenvectors().col(1);
  }
  const Eigen::Vector2d mean = mean_mm + bound_mm * direction.normalized();
  tolerance_mm_ = means_.count() == 0 ? tolerance_mm : std::min(tolerance_mm_, tolerance_mm);
  means_.Add(mean);
  sum_covariance_ += covariance_mm2;
  sum_outside_ += OutsideProbability(mean, covariance_mm2, tolerance_mm);
}

Capability ModelCapability::Result() const {
  if (means_.count() == 0) return Capability{};
  const double n = static_cast<double>(means_.count());
  // The mixture's covariance: the mean of the random parts' plus the
  // spread of the means about their mean (over n, the mixture's own).
  const Eigen::Matrix2d covariance = sum_covariance_ / n + means_.Covariance() * ((n - 1) / n);
  Capability c = Figures(means_.count(), tolerance_mm_, means_.mean(), covariance);
  c.ppm_outside = 1e6 * sum_outside_ / n;
  return c;
}

}  // namespace smtcal
