// Process figures a placement cell's quality engineer asks for
// (docs/compile.md and docs/simulate.md, "Process figures"): per axis the
// mean and standard deviation of the placement error, the machine capability
// Cmk = (T - |mean|) / (3 sigma) at the tolerance T, and the expected parts
// per million outside the tolerance circle, assuming the error is normal
// (a normal fitted to the sample, or the budget's normal model per target).
// The placement industry's reference is +-50 um at 4 sigma: sigma <= 12.5 um
// per axis and Cmk >= 1.33 at +-50 um.
#pragma once

#include <Eigen/Core>

#include "calibration/sample_statistics.h"

namespace smtcal {

inline constexpr double kReferenceToleranceMm = 0.050;
inline constexpr double kReferenceCmk = 1.33;

struct Capability {
  long placements = 0;
  double tolerance_mm = 0;                           // T: the smallest tolerance of the placements
  Eigen::Vector2d mean_mm = Eigen::Vector2d::Zero();  // per axis
  Eigen::Vector2d sigma_mm = Eigen::Vector2d::Zero();  // per axis
  Eigen::Vector2d cmk = Eigen::Vector2d::Zero();       // per axis, at T
  double ppm_outside = 0;      // expected, normal assumption
  double reference_cmk = 0;    // the smaller axis Cmk at +-50 um
  bool MeetsReference() const { return reference_cmk >= kReferenceCmk; }
  double WorstCmk() const { return cmk.minCoeff(); }
};

// Cmk of one axis, (T - |mean|) / 3 sigma for a tolerance +-T; +infinity
// for a spread of zero inside the tolerance. CmkUpper: the one-sided index
// (limit - mean) / 3 sigma of a quantity bounded only from above.
double Cmk(double tolerance_mm, double mean_mm, double sigma_mm);
double CmkUpper(double limit, double mean, double sigma);

// From placement errors (sample vectors, where the part landed minus where it
// belongs): the sample's mean and covariance, and a normal fitted to them.
class SampleCapability {
 public:
  void Add(const Eigen::Vector2d& error_mm, double tolerance_mm);
  Capability Result() const;

 private:
  double tolerance_mm_ = 0;
  SampleMoments<2> moments_;
};

// From the budget's model of each placement: a known mean, an unknown
// systematic part up to `bound_mm` (taken in its worst direction) and a
// normal random part. The pooled mean and spread are those of the mixture;
// the ppm is the mixture's.
class ModelCapability {
 public:
  void Add(const Eigen::Vector2d& mean_mm, double bound_mm, const Eigen::Matrix2d& covariance_mm2,
           double tolerance_mm);
  Capability Result() const;

 private:
  double tolerance_mm_ = 0;
  SampleMoments<2> means_;                                      // of the placements' means
  Eigen::Matrix2d sum_covariance_ = Eigen::Matrix2d::Zero();  // their random parts' covariances, summed
  double sum_outside_ = 0;
};

}  // namespace smtcal
