// Statistics of a sample, one implementation each: its mean and covariance
// (the standard deviation for one dimension) and its median. Used by the
// process figures (calibration/capability.h: verify's and simulate's
// capability), smtcal monitor's charts and figures (spc/), and wherever a
// median is taken.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace smtcal {

// A sample's mean and covariance (the standard deviation for D = 1),
// accumulated one value at a time by Welford's update: no difference of
// large sums, so a spread of 1 µm about a mean of 300 mm keeps its digits.
// The one implementation of a sample's sigma (verify's and simulate's
// capability, smtcal monitor's process figures).
template <int D>
class SampleMoments {
 public:
  using Vector = Eigen::Matrix<double, D, 1>;
  using Matrix = Eigen::Matrix<double, D, D>;
  void Add(const Vector& x) {
    ++n_;
    const Vector delta = x - mean_;
    mean_ += delta / static_cast<double>(n_);
    m2_ += delta * (x - mean_).transpose();
  }
  long count() const { return n_; }
  const Vector& mean() const { return mean_; }
  // The sample covariance (n - 1 in the denominator); zero below two values.
  Matrix Covariance() const { return n_ > 1 ? Matrix(m2_ / static_cast<double>(n_ - 1)) : Matrix::Zero(); }

 private:
  long n_ = 0;
  Vector mean_ = Vector::Zero();
  Matrix m2_ = Matrix::Zero();
};

// The mean and sample standard deviation of values (SampleMoments<1>).
struct MeanSigma {
  long n = 0;
  double mean = 0, sigma = 0;  // sigma 0 below two values
};
MeanSigma MeanAndSigma(const std::vector<double>& values);

// The median: the middle value, the mean of the two middle ones for an even
// count. At least one value (checked). The one median of smtcal: the
// measurement's screens (error_table_build, reading_screen, table_outliers)
// and the monitor's robust baseline agree on what a centre is.
double Median(std::vector<double> values);

// The median absolute deviation of a normal distribution times this is its
// standard deviation (the screens' robust scatter).
inline constexpr double kMadToSigma = 1.4826;

}  // namespace smtcal
