// Phase I: a chart's reference from a window of values (spc/baseline.h).
#include "spc/baseline.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/check.h"
#include "calibration/sample_statistics.h"

namespace smtcal {
namespace {

// The median of |X1 - X2| for normal X over sigma: sqrt(2) 0.6745.
constexpr double kMedianMovingRange = 0.9539;
constexpr std::size_t kLocalHalfWidth = 3;  // the median of up to 7 values about each
constexpr std::size_t kDriftMinSide = 3;    // values on each side of a drift's start

struct Line {
  double slope = 0, t = 0;
};

// The least-squares line of values against their index.
Line LineOf(const std::vector<double>& y) {
  const double n = static_cast<double>(y.size());
  double mx = (n - 1) / 2, my = 0;
  for (double v : y) my += v;
  my /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    sxx += (static_cast<double>(i) - mx) * (static_cast<double>(i) - mx);
    sxy += (static_cast<double>(i) - mx) * (y[i] - my);
  }
  Line line;
  line.slope = sxy / sxx;
  double residuals = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double r = y[i] - (my + line.slope * (static_cast<double>(i) - mx));
    residuals += r * r;
  }
  const double se = std::sqrt(residuals / (n - 2) / sxx);
  line.t = se > 0 ? line.slope / se : (line.slope == 0 ? 0 : std::numeric_limits<double>::infinity());
  return line;
}

// The sum of squares a model y = a + b r leaves.
double HingeResiduals(const std::vector<double>& y, const std::vector<double>& r) {
  const double n = static_cast<double>(y.size());
  double mr = 0, my = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    mr += r[i];
    my += y[i];
  }
  mr /= n;
  my /= n;
  double srr = 0, sry = 0, syy = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    srr += (r[i] - mr) * (r[i] - mr);
    sry += (r[i] - mr) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  return srr > 0 ? syy - sry * sry / srr : syy;
}

// Where the drift lies: a window steady and then ramping from c on, or
// ramping until c and steady after it, whichever leaves less.
BaselineDrift Locate(const std::vector<double>& y) {
  BaselineDrift best;
  double best_residuals = std::numeric_limits<double>::infinity();
  const std::size_t n = y.size();
  for (std::size_t c = kDriftMinSide; c + kDriftMinSide < n; ++c) {
    for (bool at_start : {false, true}) {
      std::vector<double> r(n);
      for (std::size_t i = 0; i < n; ++i) {
        const double d = static_cast<double>(i) - static_cast<double>(c);
        r[i] = at_start ? std::min(0.0, d) : std::max(0.0, d);
      }
      const double residuals = HingeResiduals(y, r);
      if (residuals < best_residuals) {
        best_residuals = residuals;
        best.at_start = at_start;
        best.first = at_start ? 0 : c;
        best.last = at_start ? c : n - 1;
      }
    }
  }
  return best;
}

}  // namespace

BaselineEstimate EstimateBaseline(const std::vector<double>& values, double resolution) {
  SMTCAL_CHECK(values.size() >= 3, "a baseline of at least 3 values");
  BaselineEstimate estimate;
  const std::size_t n = values.size();
  // Outliers: far from the median of their neighbours, in robust sigmas.
  std::vector<double> ranges;
  for (std::size_t i = 1; i < n; ++i) ranges.push_back(std::abs(values[i] - values[i - 1]));
  const double robust_sigma = std::max(Median(ranges) / kMedianMovingRange, resolution);
  std::vector<double> kept;
  std::vector<std::size_t> kept_index;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t from = i >= kLocalHalfWidth ? i - kLocalHalfWidth : 0;
    const std::size_t to = std::min(n, i + kLocalHalfWidth + 1);
    const double local = Median(std::vector<double>(values.begin() + static_cast<std::ptrdiff_t>(from),
                                                    values.begin() + static_cast<std::ptrdiff_t>(to)));
    if (std::abs(values[i] - local) > kBaselineOutlierSigmas * robust_sigma) {
      estimate.outliers.push_back(i);
    } else {
      kept.push_back(values[i]);
      kept_index.push_back(i);
    }
  }
  if (kept.size() < 3) {  // no neighbourhood to judge by: every value kept
    kept = values;
    kept_index.clear();
    for (std::size_t i = 0; i < n; ++i) kept_index.push_back(i);
    estimate.outliers.clear();
  }
  estimate.reference = EstimateReference(kept, resolution);
  // A drift: the slope against its standard error.
  const Line line = LineOf(kept);
  const double limit = StudentTQuantile(1 - kBaselineDriftAlpha / 2, static_cast<double>(kept.size()) - 2);
  if (std::abs(line.t) > limit) {
    BaselineDrift drift = Locate(kept);
    drift.first = kept_index[drift.first];
    drift.last = kept_index[drift.last];
    drift.slope = line.slope;
    drift.t = line.t;
    estimate.drift = drift;
  }
  return estimate;
}

}  // namespace smtcal
