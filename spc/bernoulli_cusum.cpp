// The refusals' Bernoulli CUSUM (spc/bernoulli_cusum.h).
#include "spc/bernoulli_cusum.h"

#include <algorithm>
#include <cmath>

#include "base/check.h"

namespace smtcal {

double BernoulliCusumArl(int up, int limit, double p) {
  SMTCAL_CHECK(up >= 1 && limit >= 1 && p > 0 && p < 1, "a Bernoulli CUSUM's weight, limit and a rate in (0, 1)");
  // L(s), the scans to an alarm from the sum s (0 <= s < H):
  //   L(s) = 1 + p L(s + up) + q L(max(s - 1, 0)),  L(s) = 0 for s >= H.
  // The matrix (I - Q) has one band below the diagonal and `up` above it; it
  // is an M-matrix, so elimination without pivoting is stable. Row s after
  // the elimination holds columns s .. s + up.
  const double q = 1 - p;
  const auto n = static_cast<std::size_t>(limit), width = static_cast<std::size_t>(up) + 1;
  std::vector<double> band(n * width, 0.0), rhs(n, 1.0);
  auto at = [&](std::size_t row, std::size_t column) -> double& { return band[row * width + (column - row)]; };
  for (std::size_t s = 0; s < n; ++s) {
    at(s, s) = s == 0 ? 1 - q : 1;
    if (s + static_cast<std::size_t>(up) < n) at(s, s + static_cast<std::size_t>(up)) = -p;
    if (s == 0) continue;
    // Row s holds -q in column s - 1: eliminate it with row s - 1.
    const double factor = -q / at(s - 1, s - 1);
    for (std::size_t c = s; c <= std::min(n - 1, s - 1 + static_cast<std::size_t>(up)); ++c) at(s, c) -= factor * at(s - 1, c);
    rhs[s] -= factor * rhs[s - 1];
  }
  std::vector<double> arl(n, 0.0);
  for (std::size_t s = n; s-- > 0;) {
    double sum = rhs[s];
    for (std::size_t c = s + 1; c <= std::min(n - 1, s + static_cast<std::size_t>(up)); ++c) sum -= at(s, c) * arl[c];
    arl[s] = sum / at(s, s);
  }
  return arl[0];
}

BernoulliCusumDesign DesignBernoulliCusum(double p0, double rise, double in_control_arl) {
  SMTCAL_CHECK(p0 > 0 && p0 < 1 && rise > 1 && in_control_arl > 1, "a rate in (0, 1), a rise and a run length");
  BernoulliCusumDesign design;
  design.p0 = p0;
  design.p1 = std::min(rise * p0, (1 + p0) / 2);
  const double hit = std::log(design.p1 / p0), miss = -std::log((1 - design.p1) / (1 - p0));
  design.up = std::max(1, static_cast<int>(std::lround(hit / miss)));
  // The smallest H with the in-control run length: it grows with H.
  int lo = 1, hi = 1;
  while (BernoulliCusumArl(design.up, hi, p0) < in_control_arl) {
    lo = hi + 1;
    hi *= 2;
    SMTCAL_CHECK(hi < (1 << 24), "a Bernoulli CUSUM limit within reach");
  }
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    if (BernoulliCusumArl(design.up, mid, p0) < in_control_arl) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  design.limit = hi;
  design.arl0 = BernoulliCusumArl(design.up, design.limit, p0);
  design.arl1 = BernoulliCusumArl(design.up, design.limit, design.p1);
  return design;
}

BernoulliCusumRun RunBernoulliCusum(const std::vector<bool>& events, const BernoulliCusumDesign& design) {
  BernoulliCusumRun run;
  run.sum.reserve(events.size());
  int sum = 0;
  std::size_t last_zero = 0;
  bool zero_seen = false;
  for (std::size_t i = 0; i < events.size(); ++i) {
    sum = std::max(0, sum + (events[i] ? design.up : -1));
    run.sum.push_back(sum);
    if (!run.alarm && sum >= design.limit) {
      run.alarm = i;
      run.change_point = zero_seen ? last_zero + 1 : 0;
    }
    if (sum == 0) {
      last_zero = i;
      zero_seen = true;
    }
  }
  return run;
}

}  // namespace smtcal
