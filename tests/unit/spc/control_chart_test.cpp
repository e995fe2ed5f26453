// Statistical process control (spc/control_chart.h): the quantiles against
// published tables, the confidence intervals' coverage on random normal
// samples, each chart rule on a sequence made to fire it, the CUSUM's false
// alarms and detection delay.
#include <cmath>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "spc/control_chart.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

TEST(Spc, QuantilesMatchTheTables) {
  EXPECT_NEAR(NormalQuantile(0.975), 1.959963984540054, 1e-12);
  EXPECT_NEAR(NormalQuantile(0.001), -3.090232306167813, 1e-11);
  EXPECT_NEAR(NormalQuantile(1e-9), -5.997807015007686, 1e-9);
  EXPECT_NEAR(NormalQuantile(0.999), 3.090232306167813, 1e-11);
  EXPECT_NEAR(StudentTQuantile(0.975, 10), 2.228138851986273, 1e-9);
  EXPECT_NEAR(StudentTQuantile(0.975, 1), 12.70620473617471, 1e-7);
  EXPECT_NEAR(StudentTQuantile(0.995, 30), 2.749995653567436, 1e-9);
  EXPECT_NEAR(StudentTQuantile(0.025, 5), -2.570581835636314, 1e-9);
  EXPECT_NEAR(ChiSquareQuantile(0.975, 10), 20.48317735080739, 1e-8);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 10), 3.246972780236841, 1e-8);
  EXPECT_NEAR(ChiSquareQuantile(0.95, 1), 3.841458820694124, 1e-8);
  EXPECT_NEAR(ChiSquareQuantile(0.5, 100), 99.33412923652314, 1e-7);
  EXPECT_NEAR(BinomialUpperTail(3, 10, 0.1), 0.0701908264, 1e-10);
  EXPECT_EQ(BinomialUpperTail(0, 10, 0.1), 1);
  EXPECT_EQ(BinomialUpperTail(11, 10, 0.1), 0);
}

TEST(Spc, IntervalsCoverTheTruthAsOftenAsTheySay) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(3.0, 2.0);
  constexpr int kTrials = 4000;
  int mean_in = 0, sigma_in = 0, cmk_in = 0;
  const double true_cmk = (20 - 3.0) / (3 * 2.0);
  for (int t = 0; t < kTrials; ++t) {
    std::vector<double> sample(25);
    for (double& v : sample) v = normal(rng);
    const ProcessFigures f = FiguresOf(sample, 0.95, LimitKind::kTwoSided, 20);
    mean_in += f.mean.lo <= 3.0 && 3.0 <= f.mean.hi ? 1 : 0;
    sigma_in += f.sigma.lo <= 2.0 && 2.0 <= f.sigma.hi ? 1 : 0;
    ASSERT_TRUE(f.cmk);
    cmk_in += f.cmk->lo <= true_cmk && true_cmk <= f.cmk->hi ? 1 : 0;
  }
  // 95 % within the binomial's 3 sigma (1 %); Bissell's interval is an approximation.
  EXPECT_NEAR(mean_in / double(kTrials), 0.95, 0.011);
  EXPECT_NEAR(sigma_in / double(kTrials), 0.95, 0.011);
  EXPECT_NEAR(cmk_in / double(kTrials), 0.95, 0.02);
  const ProcessFigures one = FiguresOf({4.0}, 0.95, LimitKind::kUpper, 10);
  EXPECT_EQ(one.n, 1);
  EXPECT_EQ(one.mean.value, 4.0);
  EXPECT_FALSE(one.cmk);
}

std::vector<double> Steady(std::size_t n, double value = 0) { return std::vector<double>(n, value); }

// A baseline that alternates +-1 (sigma = 2 / 1.128, unguarded), then the sequence.
std::vector<double> After(const std::vector<double>& tail) {
  std::vector<double> values;
  for (int i = 0; i < 30; ++i) values.push_back(i % 2 == 0 ? 1 : -1);
  values.insert(values.end(), tail.begin(), tail.end());
  return values;
}

bool Fires(const ChartResult& chart, ChartRule rule) {
  for (const RuleRun& run : chart.runs) {
    if (run.rule == rule && run.first >= chart.baseline) return true;
  }
  return false;
}

TEST(Spc, EachRuleFiresOnTheSequenceMadeForIt) {
  ChartOptions options;
  options.guard_estimates = false;  // sigma exactly the baseline's: 2 / 1.128
  const double s = 2 / 1.128;
  const ChartResult one = RunChart(After({0, 3.2 * s, 0}), options);
  EXPECT_TRUE(Fires(one, ChartRule::kNelson1));
  EXPECT_FALSE(Fires(one, ChartRule::kNelson2));
  const ChartResult two = RunChart(After(Steady(9, 0.1)), options);
  EXPECT_TRUE(Fires(two, ChartRule::kNelson2));
  EXPECT_FALSE(Fires(RunChart(After(Steady(8, 0.1)), options), ChartRule::kNelson2));
  const ChartResult three = RunChart(After({-0.5, -0.4, -0.3, -0.2, -0.1, 0.0}), options);
  EXPECT_TRUE(Fires(three, ChartRule::kNelson3));
  const ChartResult five = RunChart(After({2.1 * s, 0, 2.2 * s}), options);
  EXPECT_TRUE(Fires(five, ChartRule::kNelson5));
  const ChartResult six = RunChart(After({1.1 * s, 1.2 * s, 0, 1.1 * s, 1.3 * s}), options);
  EXPECT_TRUE(Fires(six, ChartRule::kNelson6));
  const ChartResult range = RunChart(After({0, 3.5 * 2}), options);
  EXPECT_TRUE(Fires(range, ChartRule::kMovingRange));
  // Upward only: a fall fires nothing.
  options.direction = Direction::kUp;
  const ChartResult fall = RunChart(After({0, -3.2 * s, -3.3 * s, -3.1 * s, -3.2 * s, -3.4 * s, -3.1 * s, -3.2 * s}),
                                    options);
  EXPECT_FALSE(Fires(fall, ChartRule::kNelson1));
  EXPECT_FALSE(fall.alarm);
}

TEST(Spc, TheCusumRarelyAlarmsInControlAndCatchesSmallShiftsAndRamps) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0, 1);
  ChartOptions options;
  options.baseline = 1000;  // a well-known sigma: the chart's own false alarm rate
  // The two-sided CUSUM (k = 0.5, h = 10) alarms once in about 79 000
  // in-control points, the EWMA (lambda 0.05, L 4.1) once in about 65 000
  // (by simulation, docs/monitor.md), so about 4 in 10 streams of 20 000
  // alarm by either: 17 of 40, sd 3.1.
  int alarms = 0, by_ewma = 0;
  for (int stream = 0; stream < 40; ++stream) {
    std::vector<double> values(21000);
    for (double& v : values) v = normal(rng);
    const ChartResult chart = RunChart(values, options);
    alarms += chart.alarm ? 1 : 0;
    by_ewma += chart.alarm && (chart.alarm_rule == ChartRule::kEwmaUp || chart.alarm_rule == ChartRule::kEwmaDown);
  }
  EXPECT_LE(alarms, 27) << "streams of 20 000 in-control points with a false alarm, of 40";
  EXPECT_LE(by_ewma, 17) << "streams of 20 000 in-control points whose first false alarm is the EWMA's, of 40";
  // A shift of one sigma after the baseline: found within about 20 points
  // (the CUSUM's ARL for k = 0.5, h = 10 is 21).
  std::vector<double> values(1100);
  for (double& v : values) v = normal(rng);
  for (std::size_t i = 1000; i < values.size(); ++i) values[i] += 1;
  const ChartResult shift = RunChart(values, options);
  ASSERT_TRUE(shift.alarm);
  EXPECT_GE(*shift.alarm, 1000u);
  EXPECT_LE(*shift.alarm, 1070u);
  EXPECT_EQ(shift.alarm_direction, Direction::kUp);
  // The CUSUM's estimate follows a step closely; the EWMA's (where it last
  // crossed the centre line) can lie some tens of points before it.
  const bool by_cusum = shift.alarm_rule == ChartRule::kCusumUp;
  EXPECT_GE(shift.change_point, by_cusum ? 980u : 900u) << ChartRuleName(shift.alarm_rule);
  EXPECT_LE(shift.change_point, *shift.alarm);
  // A ramp of 0.02 sigma a point: found while it is still under 1.5 sigma.
  for (std::size_t i = 1000; i < values.size(); ++i) values[i] = normal(rng) - 0.02 * static_cast<double>(i - 1000);
  const ChartResult ramp = RunChart(values, options);
  ASSERT_TRUE(ramp.alarm);
  EXPECT_EQ(ramp.alarm_direction, Direction::kDown);
  EXPECT_LE(*ramp.alarm, 1075u);
  // A slow ramp, 0.005 sigma a point after the baseline, in 40 streams: the
  // EWMA alone finds it (by simulation about 160 points after it began),
  // and the chart's alarm is the first of the EWMA's and the CUSUM's. A
  // stream may alarm by chance before the ramp (about 3 % do): skipped.
  ChartOptions ewma_alone = options, cusum_alone = options;
  ewma_alone.cusum_h = 1e9;
  cusum_alone.ewma_l = 1e9;
  int early = 0;
  for (int stream = 0; stream < 40; ++stream) {
    values.assign(1400, 0);
    for (std::size_t i = 0; i < values.size(); ++i) {
      values[i] = normal(rng) + (i < 1000 ? 0 : 0.005 * static_cast<double>(i - 1000));
    }
    const ChartResult both = RunChart(values, options), ewma = RunChart(values, ewma_alone),
                      cusum = RunChart(values, cusum_alone);
    if ((both.alarm && *both.alarm < 1000) || (ewma.alarm && *ewma.alarm < 1000) ||
        (cusum.alarm && *cusum.alarm < 1000)) {
      ++early;
      continue;
    }
    ASSERT_TRUE(ewma.alarm) << "stream " << stream;
    EXPECT_EQ(ewma.alarm_rule, ChartRule::kEwmaUp);
    EXPECT_LE(*ewma.alarm, 1300u) << "stream " << stream;
    ASSERT_TRUE(both.alarm);
    EXPECT_EQ(*both.alarm, cusum.alarm ? std::min(*ewma.alarm, *cusum.alarm) : *ewma.alarm);
    EXPECT_EQ(both.alarm_direction, Direction::kUp);
    EXPECT_LE(both.change_point, *both.alarm);
  }
  EXPECT_LE(early, 6) << "of 40 streams alarmed before the ramp";
}

TEST(Spc, GuardedEstimatesWidenTheChartForSmallBaselines) {
  ChartOptions options;
  std::vector<double> values = After({0});
  const ChartResult guarded = RunChart(values, options);
  options.guard_estimates = false;
  const ChartResult plain = RunChart(values, options);
  EXPECT_NEAR(plain.sigma, 2 / 1.128, 1e-12);
  EXPECT_EQ(guarded.sigma_estimate, plain.sigma);
  // The upper 95 % bound of sigma from 30 values: sqrt(29 / 17.708) = 1.280.
  EXPECT_NEAR(guarded.sigma / plain.sigma, 1.2797, 1e-3);
  EXPECT_NEAR(guarded.cusum_k, 0.5 + 1.6449 / std::sqrt(30.0), 1e-4);
  EXPECT_EQ(plain.cusum_k, 0.5);
}

TEST(Spc, TrendIsTheLeastSquaresLine) {
  const Trend line = FitTrend({1, 2, 3, 4}, {3, 5, 7, 9});
  EXPECT_NEAR(line.slope, 2, 1e-12);
  EXPECT_NEAR(line.slope_se, 0, 1e-12);
  EXPECT_NEAR(line.at_end, 9, 1e-12);
  const Trend noisy = FitTrend({0, 1, 2, 3, 4}, {0, 1.1, 1.9, 3.2, 3.8});
  EXPECT_NEAR(noisy.slope, 0.97, 1e-12);
  EXPECT_GT(noisy.slope_se, 0);
}

}  // namespace
}  // namespace smtcal
