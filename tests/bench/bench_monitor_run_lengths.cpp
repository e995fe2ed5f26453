// smtcal monitor's run lengths (docs/monitor.md, "Run lengths"): how many
// scans its charts take to alarm, in control and after a step, measured on
// the product's own statistics (spc/control_chart.h's ChartStatistic, the
// refusals' spc/bernoulli_cusum.h). One iteration each; the counters are the
// figures, each average with its standard error (_se), from `streams`
// simulated streams of standard normal values (seed: SMTCAL_TEST_SEED, else
// fixed).
//
// - BM_MonitorRunLengthKnown/D: sigma and the centre known (no guard), a
//   step of D/4 sigma from the first value: the CUSUM's, the EWMA's and the
//   verdict's (whichever alarms first) average run lengths. D = 0: in
//   control (streams end at 2 000 000 values: none did).
// - BM_MonitorRunLengthGuarded/N/D: the chart as smtcal runs it, its
//   reference estimated from a baseline of N in-control values (guarded),
//   then a step of D/4 sigma: the verdict's average run length (D > 0; a
//   stream that has not alarmed after 50 000 values counts as 50 000 and
//   `capped` says how many), or
//   in control (D = 0) the share of streams that alarmed within 100 000
//   values (false_alarm_pct) — too rare to average.
// - BM_MonitorCusumMarkovChain: the one-sided CUSUM's in-control run length
//   by a Markov chain on 2000 states (Brook and Evans), the two-sided one
//   from it (1 / ARL = 1 / ARL+ + 1 / ARL-), as an exact cross-check.
// - BM_MonitorRefusalRunLengths: the refusals' chart designed for 1 %
//   (exact): in control and at 1.5, 2, 3 and 5 %.
#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "calibration/sample_statistics.h"
#include "spc/bernoulli_cusum.h"
#include "spc/control_chart.h"
#include "spc/cycle_monitor.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

constexpr long kInControlCap = 2'000'000;

ChartOptions MonitorChart() {
  const MonitorOptions m;
  ChartOptions o;
  o.cusum_k = m.cusum_k;
  o.cusum_h = m.cusum_h;
  o.cusum_clip = m.cusum_clip;
  o.ewma_lambda = m.ewma_lambda;
  o.ewma_l = m.ewma_l;
  return o;
}

struct Lengths {
  SampleMoments<1> cusum, ewma, verdict;
  long capped = 0;
};

void Report(benchmark::State& state, const char* name, const SampleMoments<1>& m) {
  state.counters[name] = m.mean()(0);
  state.counters[std::string(name) + "_se"] = std::sqrt(m.Covariance()(0, 0) / static_cast<double>(m.count()));
}

void BM_MonitorRunLengthKnown(benchmark::State& state) {
  const double step = static_cast<double>(state.range(0)) / 4;
  const int streams = step == 0 ? 2000 : 20000;
  std::mt19937_64 rng(test::FixtureSeed());
  std::normal_distribution<double> normal(0, 1);
  Lengths lengths;
  for (auto _ : state) {
    for (int s = 0; s < streams; ++s) {
      ChartOptions options = MonitorChart();
      options.guard_estimates = false;
      ChartStatistic statistic(options, options.cusum_k, 0);
      long cusum = 0, ewma = 0;
      for (long n = 1; (cusum == 0 || ewma == 0) && n <= kInControlCap; ++n) {
        const ChartStatistic::Step x = statistic.Add(normal(rng) + step);
        if (cusum == 0 && (x.cusum_up_alarm || x.cusum_down_alarm)) cusum = n;
        if (ewma == 0 && (x.ewma_up_alarm || x.ewma_down_alarm)) ewma = n;
      }
      if (cusum == 0 || ewma == 0) ++lengths.capped;
      lengths.cusum.Add(Eigen::Matrix<double, 1, 1>(static_cast<double>(cusum)));
      lengths.ewma.Add(Eigen::Matrix<double, 1, 1>(static_cast<double>(ewma)));
      lengths.verdict.Add(Eigen::Matrix<double, 1, 1>(static_cast<double>(std::min(cusum, ewma))));
    }
  }
  Report(state, "cusum", lengths.cusum);
  Report(state, "ewma", lengths.ewma);
  Report(state, "verdict", lengths.verdict);
  state.counters["streams"] = streams;
  state.counters["capped"] = static_cast<double>(lengths.capped);
}
BENCHMARK(BM_MonitorRunLengthKnown)->Arg(0)->Arg(2)->Arg(4)->Arg(8)->Iterations(1)->Unit(benchmark::kSecond);

void BM_MonitorRunLengthGuarded(benchmark::State& state) {
  const auto baseline = static_cast<std::size_t>(state.range(0));
  const double step = static_cast<double>(state.range(1)) / 4;
  const bool in_control = step == 0;
  const int streams = in_control ? 1000 : 2000;
  constexpr long kWindow = 100'000;  // in control: the share that alarms within it
  constexpr long kStepCap = 50'000;  // after a step: a stream that has not alarmed by then counts as this
  std::mt19937_64 rng(test::FixtureSeed());
  std::normal_distribution<double> normal(0, 1);
  SampleMoments<1> verdict;
  long alarmed = 0, capped = 0;
  for (auto _ : state) {
    for (int s = 0; s < streams; ++s) {
      std::vector<double> reference_values(baseline);
      for (double& v : reference_values) v = normal(rng);
      const ChartReference reference = EstimateReference(reference_values, 0);
      // RunChart's arithmetic one value at a time (ChartStatistic), as guarded.
      const ChartResult chart = RunChart(reference_values, reference, MonitorChart());
      ChartStatistic statistic(chart.options, chart.cusum_k, chart.centre_uncertainty);
      long at = 0;
      const long cap = in_control ? kWindow : kStepCap;
      for (long n = 1; at == 0 && n <= cap; ++n) {
        const double value = normal(rng) + step;
        if (statistic.Add((value - chart.center) / chart.sigma).alarm()) at = n;
      }
      if (at != 0) ++alarmed;
      if (!in_control) {
        if (at == 0) ++capped;
        verdict.Add(Eigen::Matrix<double, 1, 1>(static_cast<double>(at == 0 ? cap : at)));
      }
    }
  }
  if (in_control) {
    state.counters["false_alarm_pct"] = 100.0 * static_cast<double>(alarmed) / streams;
    state.counters["false_alarm_pct_se"] =
        100.0 * std::sqrt(static_cast<double>(alarmed) / streams * (1 - static_cast<double>(alarmed) / streams) / streams);
  } else {
    Report(state, "verdict", verdict);
    state.counters["capped"] = static_cast<double>(capped);
  }
  state.counters["streams"] = streams;
}
BENCHMARK(BM_MonitorRunLengthGuarded)
    ->ArgsProduct({{20, 50, 100}, {0, 4, 8}})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// The one-sided CUSUM S = max(0, S + clip(z, -c, c) - k) for normal z: its
// in-control run length from 0 to h, by the Markov chain on `m` transient
// states (Brook and Evans 1972): state 0 holds [0, w/2), state j the
// interval of width w = 2h / (2m - 1) about j w (its value), and S >= h =
// (m - 1/2) w is the alarm.
double CusumMarkovChain(double k, double h, double clip, int m) {
  const double w = 2 * h / (2 * m - 1);
  auto cdf = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  // The increment's distribution: z clipped, minus k.
  auto below = [&](double x) {  // P(clip(z) - k < x)
    const double t = x + k;
    if (t <= -clip) return 0.0;
    if (t > clip) return 1.0;
    return cdf(t);
  };
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(m, m);
  for (int i = 0; i < m; ++i) {
    const double from = i * w;
    a(i, 0) -= below(w / 2 - from);  // to state 0: S + d < w / 2 (the reset at 0 included)
    for (int j = 1; j < m; ++j) a(i, j) -= below((j + 0.5) * w - from) - below((j - 0.5) * w - from);
  }
  const Eigen::VectorXd arl = a.partialPivLu().solve(Eigen::VectorXd::Ones(m));
  return arl(0);
}

void BM_MonitorCusumMarkovChain(benchmark::State& state) {
  const ChartOptions o = MonitorChart();
  double one_sided = 0;
  for (auto _ : state) one_sided = CusumMarkovChain(o.cusum_k, o.cusum_h, o.cusum_clip, 2000);
  state.counters["one_sided"] = one_sided;
  state.counters["two_sided"] = one_sided / 2;  // symmetric: 1 / (1 / L + 1 / L)
}
BENCHMARK(BM_MonitorCusumMarkovChain)->Iterations(1)->Unit(benchmark::kSecond);

void BM_MonitorRefusalRunLengths(benchmark::State& state) {
  BernoulliCusumDesign d;
  for (auto _ : state) d = DesignBernoulliCusum(kRefusalRateFloor);
  state.counters["up"] = d.up;
  state.counters["limit"] = d.limit;
  state.counters["at_1pct"] = d.arl0;
  for (double p : {0.015, 0.02, 0.03, 0.05}) {
    state.counters[fmt::format("at_{}pct", p * 100)] = BernoulliCusumArl(d.up, d.limit, p);
  }
}
BENCHMARK(BM_MonitorRefusalRunLengths)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace smtcal
