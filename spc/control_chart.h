// Statistical process control for `smtcal monitor` (docs/monitor.md): the
// quantiles the confidence intervals need, process figures with their
// intervals, and control charts of individual values — the centre line and
// sigma from a baseline, Nelson's rules, and a CUSUM and an EWMA for slow
// drifts.
//
// Names follow the SPC literature: Montgomery, "Introduction to Statistical
// Quality Control"; L. S. Nelson, "The Shewhart Control Chart — Tests for
// Special Causes", J. Quality Technology 16 (1984); Bissell, "How Reliable is
// Your Capability Index?", Applied Statistics 39 (1990); Lucas and
// Saccucci, "Exponentially Weighted Moving Average Control Schemes",
// Technometrics 32 (1990).
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

namespace smtcal {

// --- distributions ---------------------------------------------------------------

// The p-quantile (0 < p < 1) of the standard normal, of Student's t with
// `dof` degrees of freedom and of chi-square with `dof` degrees of freedom
// (dof > 0), to a relative 1e-10.
double NormalQuantile(double p);
double StudentTQuantile(double p, double dof);
double ChiSquareQuantile(double p, double dof);
// P(X >= k) for X binomial(n, p).
double BinomialUpperTail(long k, long n, double p);

// --- process figures ---------------------------------------------------------------

struct Interval {
  double value = 0;
  double lo = 0, hi = 0;  // the confidence interval
};

// A sample's mean and standard deviation with their confidence intervals
// (t for the mean, chi-square for sigma) and, against a limit, the
// capability: two-sided Cmk = (limit - |mean|) / 3 sigma for a limit on
// |value|, one-sided (limit - mean) / 3 sigma for an upper limit, with
// Bissell's interval (normal approximation of its sampling distribution).
struct ProcessFigures {
  long n = 0;
  Interval mean, sigma;
  std::optional<Interval> cmk;  // with a limit and n >= 2 and sigma > 0
};
enum class LimitKind { kNone, kTwoSided, kUpper };
// n >= 2 for intervals (a single value: its mean, zero sigma, no intervals).
ProcessFigures FiguresOf(const std::vector<double>& values, double confidence, LimitKind kind, double limit);

// --- control charts ------------------------------------------------------------------

// The rules a chart applies. Nelson's numbers: 1 a point beyond 3 sigma;
// 2 nine points in a row on one side of the centre line; 3 six points in a
// row steadily increasing or decreasing; 5 two of three points in a row
// beyond 2 sigma on the same side; 6 four of five beyond 1 sigma on the same
// side. The moving range beyond D4 = 3.267 times its mean (the MR chart). A
// tabular CUSUM crossing its decision interval, upwards or downwards. An
// EWMA beyond its control limit, upwards or downwards.
enum class ChartRule {
  kNelson1, kNelson2, kNelson3, kNelson5, kNelson6, kMovingRange, kCusumUp, kCusumDown, kEwmaUp, kEwmaDown
};
inline constexpr std::size_t kChartRules = 10;
std::string_view ChartRuleName(ChartRule rule);         // "nelson-1", ..., "cusum-up"
std::string_view ChartRuleDescription(ChartRule rule);  // "a point beyond 3 sigma", ...

enum class Direction { kBoth, kUp, kDown };  // the drifts a CUSUM watches for

struct ChartOptions {
  std::size_t baseline = 30;  // RunChart without a reference: the first values set the centre line and sigma
  // The tabular CUSUM: reference value k and decision interval h in sigmas;
  // each standardized value is clipped to +-clip first (a robust CUSUM: one
  // wild value moves it by at most clip - k).
  double cusum_k = 0.5;
  double cusum_h = 10;
  double cusum_clip = 4;
  // The EWMA of the standardized values (clipped as the CUSUM's), started at
  // the centre line: E = lambda z + (1 - lambda) E. It alarms beyond
  // ewma_l of its own standard deviations (the exact one of value i,
  // sigma sqrt(lambda / (2 - lambda) (1 - (1 - lambda)^2i))), plus the
  // centre's uncertainty when guarded. A small lambda averages long: it
  // sees a slow drift (a ramp) sooner than the CUSUM, whose reference value
  // k it must first outgrow.
  double ewma_lambda = 0.05;
  double ewma_l = 4.1;
  Direction direction = Direction::kBoth;
  double resolution = 0;  // sigma is at least this (the record's resolution)
  // A baseline of n values knows the centre and sigma only roughly, and a
  // sigma estimated low, or a centre off by a fraction of sigma, makes a
  // CUSUM alarm in long in-control runs. Guarded: sigma is its upper 95 %
  // confidence bound, and the CUSUM's reference value k and the EWMA's limit
  // grow by the centre's uncertainty, 1.645 / sqrt(n) sigmas.
  bool guard_estimates = true;
};

// One run of a rule: the points where it holds, from `first` to `last`
// (indices into the values).
struct RuleRun {
  ChartRule rule = ChartRule::kNelson1;
  std::size_t first = 0, last = 0;
};

// What a chart judges values against (Phase I's result, spc/baseline.h, or
// a stored baseline): the centre line and sigma and the number of values
// they were estimated from, which the guard widens the chart by.
struct ChartReference {
  long n = 0;
  double center = 0;
  double sigma_estimate = 0;  // max(moving range mean / d2 (1.128), the sample's), at least the resolution
  double mr_mean = 0;         // the mean moving range
};

// The plain estimate from all of `values` (at least 2: checked).
ChartReference EstimateReference(const std::vector<double>& values, double resolution);

// The decision statistics of a chart, one standardized value at a time:
// the two tabular CUSUMs and the EWMA with its limit (all in sigmas). The
// one implementation of the verdict's arithmetic: RunChart, the pictures'
// traces and the run-length simulations use it.
class ChartStatistic {
 public:
  // k: the CUSUM's reference value; centre_uncertainty: what the EWMA's
  // limit grows by (both in sigmas; ChartOptions::guard_estimates).
  ChartStatistic(const ChartOptions& options, double k, double centre_uncertainty);
  struct Step {
    double clipped = 0;                  // the value the statistics took (clipped to +-clip)
    double cusum_up = 0, cusum_down = 0;  // >= 0
    double ewma = 0, ewma_limit = 0;      // the EWMA and its limit at this value (the limit's own sigma grows)
    bool cusum_up_alarm = false, cusum_down_alarm = false, ewma_up_alarm = false, ewma_down_alarm = false;
    bool alarm() const { return cusum_up_alarm || cusum_down_alarm || ewma_up_alarm || ewma_down_alarm; }
  };
  Step Add(double z);

 private:
  ChartOptions options_;
  double k_, centre_uncertainty_;
  bool up_, down_;
  double c_up_ = 0, c_down_ = 0, ewma_ = 0, decay_ = 1;
};

struct ChartResult {
  std::size_t baseline = 0;  // values of the reference (ChartReference::n)
  double center = 0;
  double sigma_estimate = 0;  // the reference's
  double sigma = 0;           // the chart's: the estimate, guarded (ChartOptions::guard_estimates)
  double cusum_k = 0;         // the CUSUM's reference value in sigmas, guarded
  double centre_uncertainty = 0;  // in sigmas: what guarding added to k and to the EWMA's limit
  double mr_mean = 0;         // mean moving range of the reference
  ChartOptions options;       // as run
  std::vector<RuleRun> runs;  // every run of every rule, in order of their first point
  // The first alarm of the CUSUM or the EWMA: where it crossed its limit,
  // the rule, the direction, and where the shift it signals most likely
  // began (the CUSUM's: the last value before it at which that CUSUM was
  // zero; the EWMA's: the last value before it at which the EWMA was on the
  // centre line's other side).
  std::optional<std::size_t> alarm;
  ChartRule alarm_rule = ChartRule::kCusumUp;
  Direction alarm_direction = Direction::kBoth;
  std::size_t change_point = 0;
  std::size_t started = 0;  // the value the CUSUM and the EWMA started at (RunChart's `from`)
};

// A chart of individual values against a reference. The CUSUM and the
// EWMA start at value `from` (0: the first; after an alarm that was no
// shift, the chart starts again after it); the other rules run over all.
ChartResult RunChart(const std::vector<double>& values, const ChartReference& reference, const ChartOptions& options,
                     std::size_t from = 0);
// ... against the plain estimate of the first options.baseline values (at
// least 2: checked).
ChartResult RunChart(const std::vector<double>& values, const ChartOptions& options);

// What a picture or a spreadsheet draws of a chart: per value its
// standardized value, the statistics (ChartStatistic) and the moving range.
struct ChartTrace {
  std::vector<double> cusum_up, cusum_down, ewma, ewma_limit, moving_range;
};
ChartTrace TraceChart(const std::vector<double>& values, const ChartResult& chart);

// A least-squares line through (x, y) pairs: the slope with its standard
// error and the line's value at the last x. At least 3 points with distinct
// x (checked).
struct Trend {
  double slope = 0, slope_se = 0;
  double at_end = 0;  // the fitted value at the last x
  double end_x = 0;
};
Trend FitTrend(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace smtcal
