// Statistics of a sample (calibration/sample_statistics.h).
#include "calibration/sample_statistics.h"

#include <algorithm>
#include <cmath>

#include "base/check.h"

namespace smtcal {

MeanSigma MeanAndSigma(const std::vector<double>& values) {
  SampleMoments<1> moments;
  for (double v : values) moments.Add(Eigen::Matrix<double, 1, 1>(v));
  return {moments.count(), moments.mean()(0), std::sqrt(std::max(0.0, moments.Covariance()(0, 0)))};
}

double Median(std::vector<double> values) {
  SMTCAL_CHECK(!values.empty(), "a median of at least one value");
  const std::size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle), values.end());
  const double upper = values[middle];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle));
  return lower + (upper - lower) / 2;
}

}  // namespace smtcal
