// Periphery calibration: speed of the C runtime and the estimators' accuracy.
//
// Speed (examples/paper-cell/paper.cell.toml: its board and its layer tables):
// - BM_CRuntimeScan/E: one scan in the C runtime, trips -> checked FIX
//   (E: 0 paper, 1 rigid, 2 rigid-scale). Target: under 2 us per scan.
// - BM_CRuntimeScanAnd120Points/E: one scan, then 120 placements on the three
//   layers corrected (FIX_n . FIXPOS_0, region lookup, bounded inverse);
//   ns_per_point is the points' share. Target: well under 1 us per point.
// - BM_CppScan/E: the same scan through the C++ ScanFixture, for comparison.
//
// Accuracy, a Monte Carlo (BM_FixtureMonteCarlo/E/G, one iteration each): the
// same 100 000 simulated scans for every estimator (fixed seed, or
// SMTCAL_TEST_SEED): the board off nominal by up to +-0.5 mm and +-0.1 deg
// (the paper: about 0.5 mm), each trip off its edge by the sensor's
// +-0.05 mm (uniform) and the robot off its command by its repeatability,
// +-0.005 mm per axis; G = 1: the board also scaled by up to +-1e-4 (a warm
// board). Counters, over the placement area of the three layers (fixture x
// 12..172, y 20..70 mm; the error is largest at a corner): rms_um, p99_um,
// max_um of the position error the estimate makes there, angle_rms_mdeg,
// pass_pct (the scans that pass the cell's checks) and residual_p99_um (the
// 99th percentile of a scan's largest line residual: what max_line_residual_mm
// must allow so that good scans pass).
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "backend/c/c_data.h"
#include "calibration/fixture_estimation.h"
#include "frontend/cell_toml.h"
#include "runtime/c/smtcal_runtime.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

constexpr int kPoints = 120;

struct PaperCell {
  cell::Cell cell;
  std::vector<Eigen::Vector2d> trips;   // one scan of a displaced board
  std::vector<Eigen::Vector2d> points;  // 40 placements per layer, fixture frame

  PaperCell() {
    SourceManager sources;
    Diagnostics diags(sources);
    Result<std::optional<cell::Cell>> loaded =
        cell::LoadCell(std::string(SMTCAL_SOURCE_DIR) + "/examples/paper-cell/paper.cell.toml", sources, diags);
    if (!loaded || !loaded.value()) {
      std::fprintf(stderr, "bench_fixture: cannot load the example cell:\n%s", diags.RenderText().c_str());
      std::abort();
    }
    cell = std::move(*loaded.value());
    std::mt19937_64 rng(1994);
    const cell::Fixture& board = cell.fixtures.at(0);
    const Eigen::Affine3d truth = PlanarFix(board.origin_mm + Eigen::Vector2d(0.31, -0.22), 0.04 * kRadPerDeg);
    // Noise-free trips, so every estimator's scan passes its checks (the
    // time does not depend on the noise; the Monte Carlo below adds it).
    trips = test::SimulateTrips(board, truth);
    // The layers: fixture x 12.5..61.5, 67.5..116.5, 122.5..171.5; y 20.5..69.5.
    for (int i = 0; i < kPoints; ++i) {
      const double layer = 55.0 * (i % 3);
      points.emplace_back(test::Uniform(rng, 14, 60) + layer, test::Uniform(rng, 22, 68));
    }
  }
};

const PaperCell& Data() {
  static const PaperCell data;
  return data;
}

cell::Fixture BoardWith(cell::Estimator estimator) {
  cell::Fixture fixture = Data().cell.fixtures.at(0);
  fixture.estimator = estimator;
  return fixture;
}

cell::Estimator EstimatorArg(const benchmark::State& state) {
  return static_cast<cell::Estimator>(state.range(0));
}

void BM_CRuntimeScan(benchmark::State& state) {
  const cell::Fixture board = BoardWith(EstimatorArg(state));
  const smtcal_fixture fixture = CRuntimeFixture(board);
  const CRuntimeData data(Data().cell);
  std::vector<double> xy;
  for (const Eigen::Vector2d& t : Data().trips) xy.insert(xy.end(), {t.x(), t.y()});
  smtcal_scan_result result;
  for (auto _ : state) {
    benchmark::DoNotOptimize(xy.data());
    smtcal_scan(&fixture, data.regions(), data.region_count(), xy.data(), nullptr, nullptr, &result);
    benchmark::DoNotOptimize(result);
  }
  if (!result.has_fix) state.SkipWithError("the benchmark scan failed its checks");
  state.SetLabel(std::string(cell::EstimatorName(board.estimator)));
}
BENCHMARK(BM_CRuntimeScan)->DenseRange(0, 2);

void BM_CRuntimeScanAnd120Points(benchmark::State& state) {
  const cell::Fixture board = BoardWith(EstimatorArg(state));
  const smtcal_fixture fixture = CRuntimeFixture(board);
  const CRuntimeData data(Data().cell);
  std::vector<double> xy;
  for (const Eigen::Vector2d& t : Data().trips) xy.insert(xy.end(), {t.x(), t.y()});
  std::vector<double> points;
  for (const Eigen::Vector2d& p : Data().points) points.insert(points.end(), {p.x(), p.y()});
  smtcal_scan_result result;
  smtcal_corrected out;
  int corrected = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(xy.data());
    smtcal_scan(&fixture, data.regions(), data.region_count(), xy.data(), nullptr, nullptr, &result);
    corrected = 0;
    for (int i = 0; i < kPoints; ++i) {
      corrected += smtcal_correct(&result.fix, data.regions(), data.region_count(), &points[2 * i], &out) ==
                   SMTCAL_POINT_OK;
      benchmark::DoNotOptimize(out);
    }
  }
  if (!result.has_fix || corrected != kPoints) state.SkipWithError("a point was not corrected");
  state.counters["ns_per_point"] = benchmark::Counter(
      static_cast<double>(kPoints) * static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert, benchmark::Counter::OneK::kIs1000);
  state.SetLabel(std::string(cell::EstimatorName(board.estimator)));
}
BENCHMARK(BM_CRuntimeScanAnd120Points)->DenseRange(0, 2);

void BM_CppScan(benchmark::State& state) {
  const cell::Fixture board = BoardWith(EstimatorArg(state));
  ScanOptions options;
  options.estimator = board.estimator;
  options.regions = &Data().cell.regions;
  const std::vector<std::optional<Eigen::Vector2d>> trips = test::Present(Data().trips);
  for (auto _ : state) {
    ScanResult result = ScanFixture(board, trips, options);
    benchmark::DoNotOptimize(result);
  }
  state.SetLabel(std::string(cell::EstimatorName(board.estimator)));
}
BENCHMARK(BM_CppScan)->DenseRange(0, 2);

// --- the Monte Carlo --------------------------------------------------------------

void BM_FixtureMonteCarlo(benchmark::State& state) {
  const cell::Estimator estimator = EstimatorArg(state);
  const bool grows = state.range(1) != 0;
  const cell::Fixture board = BoardWith(estimator);
  const std::vector<ExpectedTrip> expected = ExpectedTrips(board);
  const std::uint64_t seed = test::FixtureSeed(19940101);
  const int scans = 100000;
  const Eigen::Vector2d corners[] = {{12, 20}, {172, 20}, {12, 70}, {172, 70}};
  std::vector<double> errors, residuals;
  double sum_squares = 0, angle_squares = 0;
  int passed = 0;
  for (auto _ : state) {
    std::mt19937_64 rng(seed);  // the same scans for every estimator
    errors.clear();
    residuals.clear();
    for (int i = 0; i < scans; ++i) {
      const Eigen::Affine3d truth = PlanarFix(
          board.origin_mm + Eigen::Vector2d(test::Uniform(rng, -0.5, 0.5), test::Uniform(rng, -0.5, 0.5)),
          test::Uniform(rng, -0.1, 0.1) * kRadPerDeg, grows ? 1 + test::Uniform(rng, -1e-4, 1e-4) : 1);
      std::vector<double> sensor;
      std::vector<Eigen::Vector2d> robot;
      for (std::size_t k = 0; k < expected.size(); ++k) {
        sensor.push_back(test::Uniform(rng, -0.05, 0.05));
        robot.emplace_back(test::Uniform(rng, -0.005, 0.005), test::Uniform(rng, -0.005, 0.005));
      }
      const std::vector<Eigen::Vector2d> trips = test::SimulateTrips(board, truth, sensor, robot);
      ScanOptions options;
      options.estimator = estimator;
      const ScanResult result = ScanFixture(board, test::Present(trips), options);
      passed += result.ok();
      if (!result.estimate) {
        errors.push_back(std::numeric_limits<double>::infinity());
        continue;
      }
      double worst = 0;
      for (const Eigen::Vector2d& corner : corners) {
        worst = std::max(worst, (ToBase(result.estimate->fix, corner) - ToBase(truth, corner)).norm());
      }
      errors.push_back(worst);
      const std::vector<double>& residual = result.estimate->residual_mm;
      residuals.push_back(*std::max_element(residual.begin(), residual.end()));
      sum_squares += worst * worst;
      const double angle = RelativeAngleRad(truth, result.estimate->fix) * kDegPerRad;
      angle_squares += angle * angle;
    }
  }
  std::sort(errors.begin(), errors.end());
  const double n = static_cast<double>(errors.size());
  state.counters["rms_um"] = 1000 * std::sqrt(sum_squares / n);
  state.counters["p99_um"] = 1000 * errors[static_cast<std::size_t>(0.99 * n)];
  state.counters["max_um"] = 1000 * errors.back();
  state.counters["angle_rms_mdeg"] = 1000 * std::sqrt(angle_squares / n);
  state.counters["pass_pct"] = 100.0 * passed / n;
  std::sort(residuals.begin(), residuals.end());
  if (!residuals.empty()) {
    state.counters["residual_p99_um"] = 1000 * residuals[static_cast<std::size_t>(0.99 * residuals.size())];
  }
  state.SetLabel(fmt::format("{}{}, seed {}", cell::EstimatorName(estimator), grows ? ", board scale +-1e-4" : "",
                             seed));
}
BENCHMARK(BM_FixtureMonteCarlo)->ArgsProduct({{0, 1, 2}, {0, 1}})->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace smtcal
