// The refusals' Bernoulli CUSUM (spc/bernoulli_cusum.h): its exact run
// lengths against a simulation of the same chart (random refusals, the seed
// printed), the design's promises (the smallest limit with the in-control
// run length; a tripled rate caught within a few hundred scans), and where
// it alarms on a burst.
#include <cmath>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "spc/bernoulli_cusum.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

// The mean and standard error of the run length of `runs` simulated charts.
std::pair<double, double> SimulatedArl(const BernoulliCusumDesign& design, double p, int runs, std::mt19937_64& rng) {
  std::bernoulli_distribution refused(p);
  double sum = 0, squares = 0;
  for (int r = 0; r < runs; ++r) {
    int s = 0;
    long n = 0;
    do {
      ++n;
      s = std::max(0, s + (refused(rng) ? design.up : -1));
    } while (s < design.limit);
    sum += static_cast<double>(n);
    squares += static_cast<double>(n) * static_cast<double>(n);
  }
  const double mean = sum / runs;
  return {mean, std::sqrt((squares / runs - mean * mean) / runs)};
}

TEST(BernoulliCusum, ExactRunLengthsAgreeWithASimulationOfTheChart) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  // A small design (in control about 2000 scans) so the simulation is quick.
  const BernoulliCusumDesign design = DesignBernoulliCusum(0.02, 3, 2000);
  for (double p : {0.02, 0.04, 0.06, 0.2}) {
    const double exact = BernoulliCusumArl(design.up, design.limit, p);
    const auto [mean, se] = SimulatedArl(design, p, 1500, rng);
    EXPECT_NEAR(mean, exact, 4 * se) << "p " << p << ", up " << design.up << ", limit " << design.limit;
  }
  // By hand: with up = 1 and H = 1 the first refusal alarms: 1 / p scans.
  EXPECT_NEAR(BernoulliCusumArl(1, 1, 0.25), 4, 1e-12);
  // H = 2, up = 1: L0 = 1 + p L1 + q L0, L1 = 1 + q L0 -> L0 = (1 + p) / p^2.
  EXPECT_NEAR(BernoulliCusumArl(1, 2, 0.25), 1.25 / 0.0625, 1e-9);
}

TEST(BernoulliCusum, TheDesignCatchesATripledRateWithinAFewHundredScans) {
  // The floor's design: 1 % in control, 3 % to catch.
  const BernoulliCusumDesign d = DesignBernoulliCusum(kRefusalRateFloor);
  EXPECT_NEAR(d.p1, 0.03, 1e-15);
  EXPECT_GE(d.arl0, kRefusalInControlArl);
  EXPECT_LT(BernoulliCusumArl(d.up, d.limit - 1, d.p0), kRefusalInControlArl);  // the smallest such limit
  EXPECT_LT(d.arl1, 600) << "up " << d.up << ", limit " << d.limit;
  std::printf("design for 1 %%: up %d, limit %d, in control %.0f scans, at 3 %% %.1f scans\n", d.up, d.limit, d.arl0, d.arl1);
  EXPECT_GT(d.arl1, 100);
  // Rates between: monotone.
  double previous = d.arl0;
  for (double p : {0.012, 0.015, 0.02, 0.025, 0.03, 0.05}) {
    const double arl = BernoulliCusumArl(d.up, d.limit, p);
    EXPECT_LT(arl, previous) << p;
    previous = arl;
  }
  // A high in-control rate: the rise is capped below certainty.
  const BernoulliCusumDesign high = DesignBernoulliCusum(0.4);
  EXPECT_NEAR(high.p1, 0.7, 1e-15);
  EXPECT_GE(high.arl0, kRefusalInControlArl);
}

TEST(BernoulliCusum, AlarmsOnABurstAndNamesWhereItBegan) {
  const BernoulliCusumDesign d = DesignBernoulliCusum(kRefusalRateFloor);
  std::vector<bool> events(2000, false);
  events[100] = true;  // one refusal: no alarm
  EXPECT_FALSE(RunBernoulliCusum(events, d).alarm);
  for (std::size_t i = 1000; i < 1100; i += 4) events[i] = true;  // 25 % for 100 scans
  const BernoulliCusumRun run = RunBernoulliCusum(events, d);
  ASSERT_TRUE(run.alarm);
  EXPECT_GE(*run.alarm, 1000u);
  EXPECT_LE(*run.alarm, 1100u);
  EXPECT_EQ(run.change_point, 1000u);
  EXPECT_EQ(run.sum.size(), events.size());
  EXPECT_GE(run.sum[*run.alarm], d.limit);
}

}  // namespace
}  // namespace smtcal
