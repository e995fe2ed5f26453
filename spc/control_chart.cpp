// Statistical process control (spc/control_chart.h).
#include "spc/control_chart.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "base/check.h"
#include "calibration/capability.h"

namespace smtcal {
namespace {

constexpr double kTiny = 1e-300;        // keeps the continued fractions off zero
constexpr double kFractionEps = 1e-15;  // their convergence
constexpr int kFractionSteps = 1000;

// The continued fraction of the incomplete beta function (modified Lentz).
double BetaFraction(double a, double b, double x) {
  const double qab = a + b, qap = a + 1, qam = a - 1;
  double c = 1, d = 1 - qab * x / qap;
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1 / d;
  double h = d;
  for (int m = 1; m <= kFractionSteps; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1 / d;
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1) < kFractionEps) break;
  }
  return h;
}

// The regularized incomplete beta function I_x(a, b).
double IncompleteBeta(double a, double b, double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  const double front =
      std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1) / (a + b + 2)) return front * BetaFraction(a, b, x) / a;
  return 1 - front * BetaFraction(b, a, 1 - x) / b;
}

// The regularized lower incomplete gamma function P(a, x).
double IncompleteGamma(double a, double x) {
  if (x <= 0) return 0;
  const double front = std::exp(-x + a * std::log(x) - std::lgamma(a));
  if (x < a + 1) {  // the series
    double term = 1 / a, sum = term;
    for (int n = 1; n <= kFractionSteps; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * kFractionEps) break;
    }
    return sum * front;
  }
  // The continued fraction of Q = 1 - P (modified Lentz).
  double b = x + 1 - a, c = 1 / kTiny, d = 1 / b, h = d;
  for (int i = 1; i <= kFractionSteps; ++i) {
    const double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1 / d;
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1) < kFractionEps) break;
  }
  return 1 - front * h;
}

double StudentTCdf(double t, double dof) {
  const double tail = 0.5 * IncompleteBeta(dof / 2, 0.5, dof / (dof + t * t));
  return t >= 0 ? 1 - tail : tail;
}

// The x in [lo, hi] with cdf(x) = p, by bisection (cdf increasing); the
// bracket grows until it holds the answer.
template <typename Cdf>
double Invert(const Cdf& cdf, double p, double lo, double hi) {
  while (cdf(lo) > p) lo = lo < 0 ? 2 * lo : lo / 2 - 1;
  while (cdf(hi) < p) hi = hi > 0 ? 2 * hi : hi / 2 + 1;
  for (int i = 0; i < 200 && hi - lo > 1e-13 * std::max(1.0, std::abs(lo) + std::abs(hi)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

constexpr double kD2 = 1.128;   // E|X1 - X2| / sigma for normal X: the moving range's constant
constexpr double kD4 = 3.267;   // the MR chart's upper limit in mean moving ranges

}  // namespace

double NormalQuantile(double p) {
  SMTCAL_CHECK(p > 0 && p < 1, "a probability strictly between 0 and 1");
  // Acklam's rational approximation (relative error 1.15e-9), then one
  // Halley step on the exact CDF.
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                                 1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                                 6.680131188771972e+01,  -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                                 -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                                 3.754408661907416e+00};
  constexpr double low = 0.02425;
  double x;
  if (p < low) {
    const double q = std::sqrt(-2 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  } else if (p <= 1 - low) {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  } else {
    const double q = std::sqrt(-2 * std::log1p(-p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  const double e = 0.5 * std::erfc(-x / std::numbers::sqrt2) - p;
  const double u = e * std::sqrt(2 * std::numbers::pi) * std::exp(x * x / 2);
  return x - u / (1 + x * u / 2);
}

double StudentTQuantile(double p, double dof) {
  SMTCAL_CHECK(p > 0 && p < 1 && dof > 0, "a probability in (0, 1) and positive degrees of freedom");
  const double z = NormalQuantile(p);
  return Invert([dof](double t) { return StudentTCdf(t, dof); }, p, z - 1 - std::abs(z), z + 1 + std::abs(z));
}

double ChiSquareQuantile(double p, double dof) {
  SMTCAL_CHECK(p > 0 && p < 1 && dof > 0, "a probability in (0, 1) and positive degrees of freedom");
  return Invert([dof](double x) { return IncompleteGamma(dof / 2, x / 2); }, p, 0, dof + 10 * std::sqrt(dof) + 10);
}

double BinomialUpperTail(long k, long n, double p) {
  if (k <= 0) return 1;
  if (k > n) return 0;
  return IncompleteBeta(static_cast<double>(k), static_cast<double>(n - k + 1), p);
}

ProcessFigures FiguresOf(const std::vector<double>& values, double confidence, LimitKind kind, double limit) {
  SMTCAL_CHECK(confidence > 0 && confidence < 1, "a confidence level in (0, 1)");
  ProcessFigures f;
  f.n = static_cast<long>(values.size());
  if (values.empty()) return f;
  const MeanSigma sample = MeanAndSigma(values);  // calibration/capability.h: the one sigma
  const double mean = sample.mean, s = sample.sigma;
  f.mean = {mean, mean, mean};
  if (values.size() < 2) return f;
  const double n = static_cast<double>(values.size());
  const double alpha = 1 - confidence;
  const double t = StudentTQuantile(1 - alpha / 2, n - 1);
  f.mean = {mean, mean - t * s / std::sqrt(n), mean + t * s / std::sqrt(n)};
  f.sigma = {s, s * std::sqrt((n - 1) / ChiSquareQuantile(1 - alpha / 2, n - 1)),
             s * std::sqrt((n - 1) / ChiSquareQuantile(alpha / 2, n - 1))};
  if (kind != LimitKind::kNone && s > 0) {
    const double c = kind == LimitKind::kTwoSided ? Cmk(limit, mean, s) : CmkUpper(limit, mean, s);
    const double half = NormalQuantile(1 - alpha / 2) * std::sqrt(1 / (9 * n) + c * c / (2 * (n - 1)));
    f.cmk = Interval{c, c - half, c + half};
  }
  return f;
}

std::string_view ChartRuleName(ChartRule rule) {
  switch (rule) {
    case ChartRule::kNelson1: return "nelson-1";
    case ChartRule::kNelson2: return "nelson-2";
    case ChartRule::kNelson3: return "nelson-3";
    case ChartRule::kNelson5: return "nelson-5";
    case ChartRule::kNelson6: return "nelson-6";
    case ChartRule::kMovingRange: return "moving-range";
    case ChartRule::kCusumUp: return "cusum-up";
    case ChartRule::kCusumDown: return "cusum-down";
    case ChartRule::kEwmaUp: return "ewma-up";
    case ChartRule::kEwmaDown: return "ewma-down";
  }
  return "?";
}

std::string_view ChartRuleDescription(ChartRule rule) {
  switch (rule) {
    case ChartRule::kNelson1: return "a point beyond 3 sigma";
    case ChartRule::kNelson2: return "9 points in a row on one side of the centre line";
    case ChartRule::kNelson3: return "6 points in a row steadily increasing or decreasing";
    case ChartRule::kNelson5: return "2 of 3 points beyond 2 sigma on one side";
    case ChartRule::kNelson6: return "4 of 5 points beyond 1 sigma on one side";
    case ChartRule::kMovingRange: return "a moving range beyond 3.267 times its mean";
    case ChartRule::kCusumUp: return "the CUSUM of upward shifts beyond its decision interval";
    case ChartRule::kCusumDown: return "the CUSUM of downward shifts beyond its decision interval";
    case ChartRule::kEwmaUp: return "the EWMA above its upper control limit";
    case ChartRule::kEwmaDown: return "the EWMA below its lower control limit";
  }
  return "?";
}

ChartReference EstimateReference(const std::vector<double>& values, double resolution) {
  SMTCAL_CHECK(values.size() >= 2, "a chart's reference needs at least 2 values");
  ChartReference reference;
  reference.n = static_cast<long>(values.size());
  double ranges = 0;
  for (std::size_t i = 1; i < values.size(); ++i) ranges += std::abs(values[i] - values[i - 1]);
  const MeanSigma sample = MeanAndSigma(values);
  reference.center = sample.mean;
  reference.mr_mean = ranges / static_cast<double>(values.size() - 1);
  // sigma: the larger of the moving range's (robust to a drift in the
  // baseline) and the sample's (not fooled by heavy tails), at least the
  // resolution.
  reference.sigma_estimate = std::max({reference.mr_mean / kD2, sample.sigma, resolution});
  return reference;
}

ChartStatistic::ChartStatistic(const ChartOptions& options, double k, double centre_uncertainty)
    : options_(options),
      k_(k),
      centre_uncertainty_(centre_uncertainty),
      up_(options.direction != Direction::kDown),
      down_(options.direction != Direction::kUp) {}

ChartStatistic::Step ChartStatistic::Add(double z) {
  Step step;
  step.clipped = std::clamp(z, -options_.cusum_clip, options_.cusum_clip);
  c_up_ = up_ ? std::max(0.0, c_up_ + step.clipped - k_) : 0.0;
  c_down_ = down_ ? std::max(0.0, c_down_ - step.clipped - k_) : 0.0;
  const double lambda = options_.ewma_lambda;
  ewma_ = lambda * step.clipped + (1 - lambda) * ewma_;
  decay_ *= (1 - lambda) * (1 - lambda);
  step.cusum_up = c_up_;
  step.cusum_down = c_down_;
  step.ewma = ewma_;
  step.ewma_limit = options_.ewma_l * std::sqrt(lambda / (2 - lambda) * (1 - decay_)) + centre_uncertainty_;
  step.cusum_up_alarm = c_up_ > options_.cusum_h;
  step.cusum_down_alarm = c_down_ > options_.cusum_h;
  step.ewma_up_alarm = up_ && ewma_ > step.ewma_limit;
  step.ewma_down_alarm = down_ && ewma_ < -step.ewma_limit;
  return step;
}

namespace {

// The chart's sigma and k from its reference: guarded, sigma is its upper
// 95 % bound for the reference's size and k grows by the centre's
// uncertainty (the centre line is known to +-1.645 sigma / sqrt(n)).
ChartResult Prepared(const ChartReference& reference, const ChartOptions& options) {
  SMTCAL_CHECK(reference.n >= 2, "a chart's reference of at least 2 values");
  ChartResult chart;
  chart.options = options;
  chart.baseline = static_cast<std::size_t>(reference.n);
  chart.center = reference.center;
  chart.sigma_estimate = reference.sigma_estimate;
  chart.mr_mean = reference.mr_mean;
  chart.sigma = chart.sigma_estimate;
  chart.cusum_k = options.cusum_k;
  if (options.guard_estimates) {
    const double m = static_cast<double>(reference.n);
    chart.sigma *= std::sqrt((m - 1) / ChiSquareQuantile(0.05, m - 1));
    chart.centre_uncertainty = NormalQuantile(0.95) / std::sqrt(m);
    chart.cusum_k += chart.centre_uncertainty;
  }
  return chart;
}

double Standardized(double value, const ChartResult& chart) {
  const double deviation = value - chart.center;
  if (chart.sigma > 0) return deviation / chart.sigma;
  return deviation == 0 ? 0 : std::copysign(std::numeric_limits<double>::infinity(), deviation);
}

}  // namespace

ChartResult RunChart(const std::vector<double>& values, const ChartOptions& options) {
  const std::size_t baseline = std::min(options.baseline, values.size());
  SMTCAL_CHECK(baseline >= 2, "a control chart needs a baseline of at least 2 values");
  const std::vector<double> first(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(baseline));
  return RunChart(values, EstimateReference(first, options.resolution), options);
}

ChartResult RunChart(const std::vector<double>& values, const ChartReference& reference, const ChartOptions& options,
                     std::size_t from) {
  ChartResult chart = Prepared(reference, options);
  const bool up = options.direction != Direction::kDown, down = options.direction != Direction::kUp;
  const std::size_t n = values.size();
  std::vector<double> z(n);
  for (std::size_t i = 0; i < n; ++i) z[i] = Standardized(values[i], chart);

  // The rules at each point, then grouped into runs.
  std::vector<std::vector<bool>> holds(kChartRules, std::vector<bool>(n, false));
  auto count_beyond = [&](std::size_t end, std::size_t window, double level, double sign) {
    std::size_t count = 0;
    for (std::size_t j = end + 1 - window; j <= end; ++j) count += sign * z[j] > level ? 1 : 0;
    return count;
  };
  ChartStatistic statistic(options, chart.cusum_k, chart.centre_uncertainty);
  // Before `from` nothing is judged: a drift found after it began there at the earliest.
  std::size_t last_zero_up = from > 0 ? from - 1 : 0, last_zero_down = last_zero_up;
  bool zero_up_seen = from > 0, zero_down_seen = from > 0;
  std::optional<std::size_t> last_below, last_above;  // the EWMA's last value at or below / above the centre
  if (from > 0) last_below = last_above = from - 1;
  chart.started = from;
  for (std::size_t i = 0; i < n; ++i) {
    auto set = [&](ChartRule rule) { holds[static_cast<std::size_t>(rule)][i] = true; };
    if ((up && z[i] > 3) || (down && z[i] < -3)) set(ChartRule::kNelson1);
    if (i >= 8) {
      bool above = true, below = true;
      for (std::size_t j = i - 8; j <= i; ++j) {
        above = above && z[j] > 0;
        below = below && z[j] < 0;
      }
      if ((up && above) || (down && below)) set(ChartRule::kNelson2);
    }
    if (i >= 5) {
      bool rising = true, falling = true;
      for (std::size_t j = i - 4; j <= i; ++j) {
        rising = rising && values[j] > values[j - 1];
        falling = falling && values[j] < values[j - 1];
      }
      if ((up && rising) || (down && falling)) set(ChartRule::kNelson3);
    }
    if (i >= 2 && ((up && count_beyond(i, 3, 2, 1) >= 2) || (down && count_beyond(i, 3, 2, -1) >= 2))) {
      set(ChartRule::kNelson5);
    }
    if (i >= 4 && ((up && count_beyond(i, 5, 1, 1) >= 4) || (down && count_beyond(i, 5, 1, -1) >= 4))) {
      set(ChartRule::kNelson6);
    }
    if (i >= 1 && std::abs(values[i] - values[i - 1]) > kD4 * chart.mr_mean && chart.mr_mean > 0) {
      set(ChartRule::kMovingRange);
    }
    if (i < from) continue;
    const ChartStatistic::Step step = statistic.Add(z[i]);
    if (step.cusum_up_alarm) set(ChartRule::kCusumUp);
    if (step.cusum_down_alarm) set(ChartRule::kCusumDown);
    if (!chart.alarm && (step.cusum_up_alarm || step.cusum_down_alarm)) {
      chart.alarm = i;
      const bool upward = step.cusum_up_alarm;
      chart.alarm_rule = upward ? ChartRule::kCusumUp : ChartRule::kCusumDown;
      chart.alarm_direction = upward ? Direction::kUp : Direction::kDown;
      const bool seen = upward ? zero_up_seen : zero_down_seen;
      chart.change_point = seen ? (upward ? last_zero_up : last_zero_down) + 1 : 0;
    }
    if (step.ewma_up_alarm) set(ChartRule::kEwmaUp);
    if (step.ewma_down_alarm) set(ChartRule::kEwmaDown);
    if (!chart.alarm && (step.ewma_up_alarm || step.ewma_down_alarm)) {
      chart.alarm = i;
      chart.alarm_rule = step.ewma_up_alarm ? ChartRule::kEwmaUp : ChartRule::kEwmaDown;
      chart.alarm_direction = step.ewma_up_alarm ? Direction::kUp : Direction::kDown;
      // Where the drift began: after the EWMA last stood on the centre
      // line's other side (for a slow ramp nearer the start than the
      // CUSUM's last zero, which its reference value k holds back).
      const std::optional<std::size_t>& other_side = step.ewma_up_alarm ? last_below : last_above;
      chart.change_point = other_side ? *other_side + 1 : 0;
    }
    if (step.ewma <= 0) last_below = i;
    if (step.ewma >= 0) last_above = i;
    if (step.cusum_up == 0) {
      last_zero_up = i;
      zero_up_seen = true;
    }
    if (step.cusum_down == 0) {
      last_zero_down = i;
      zero_down_seen = true;
    }
  }
  for (std::size_t r = 0; r < kChartRules; ++r) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!holds[r][i]) continue;
      RuleRun run{static_cast<ChartRule>(r), i, i};
      while (run.last + 1 < n && holds[r][run.last + 1]) ++run.last;
      chart.runs.push_back(run);
      i = run.last;
    }
  }
  std::stable_sort(chart.runs.begin(), chart.runs.end(),
                   [](const RuleRun& a, const RuleRun& b) { return a.first < b.first; });
  return chart;
}

ChartTrace TraceChart(const std::vector<double>& values, const ChartResult& chart) {
  ChartTrace trace;
  ChartStatistic statistic(chart.options, chart.cusum_k, chart.centre_uncertainty);
  for (std::size_t i = 0; i < values.size(); ++i) {
    // Before the chart started (ChartResult::started) its statistics are 0.
    const ChartStatistic::Step step =
        i < chart.started ? ChartStatistic::Step{} : statistic.Add(Standardized(values[i], chart));
    trace.cusum_up.push_back(step.cusum_up);
    trace.cusum_down.push_back(step.cusum_down);
    trace.ewma.push_back(step.ewma);
    trace.ewma_limit.push_back(step.ewma_limit);
    trace.moving_range.push_back(i == 0 ? 0.0 : std::abs(values[i] - values[i - 1]));
  }
  return trace;
}

Trend FitTrend(const std::vector<double>& x, const std::vector<double>& y) {
  SMTCAL_CHECK(x.size() == y.size() && x.size() >= 3, "a trend needs at least 3 points");
  const double n = static_cast<double>(x.size());
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  SMTCAL_CHECK(sxx > 0, "a trend needs distinct x");
  Trend trend;
  trend.slope = sxy / sxx;
  double residuals = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = y[i] - (my + trend.slope * (x[i] - mx));
    residuals += r * r;
  }
  trend.slope_se = std::sqrt(residuals / (n - 2) / sxx);
  trend.end_x = x.back();
  trend.at_end = my + trend.slope * (x.back() - mx);
  return trend;
}

}  // namespace smtcal
