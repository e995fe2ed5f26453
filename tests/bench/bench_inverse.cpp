// Inverse calibration speed and accuracy on the paper cell's placing table
// (examples/paper-cell/placing-table.csv), over the same random points for
// every solver: the default solver (target: >= 5 million solves per second on
// one core, residual <= 1e-9 mm) and the paper's interval search, at its
// default tolerance and asked for 1e-9 mm. Counters: solves_per_s, the largest
// residual and iteration count reached, and the default solver's bound.
#include <fstream>
#include <random>
#include <sstream>

#include <benchmark/benchmark.h>

#include "calibration/error_table_check.h"
#include "calibration/inverse_calibration.h"
#include "frontend/table_csv.h"

namespace smtcal {
namespace {

constexpr int kPoints = 4096;
constexpr std::uint64_t kSeed = 1994;

struct Fixture {
  std::optional<ErrorTable> table;
  std::vector<Eigen::Vector2d> actual;  // required positions, all inside the table

  Fixture() {
    std::ifstream in(std::string(SMTCAL_SOURCE_DIR) + "/examples/paper-cell/placing-table.csv");
    std::ostringstream text;
    text << in.rdbuf();
    SourceManager sources;
    Diagnostics diags(sources);
    table = ReadErrorTable(sources.Add("placing-table.csv", text.str()), diags);
    if (!table || !ValidateErrorTable(*table, diags, TableWarnings::kSkip)) {
      std::fprintf(stderr, "bench_inverse: cannot load the example table:\n%s", diags.RenderText().c_str());
      std::abort();
    }
    CalibrationMap map(*table);
    std::mt19937_64 rng(kSeed);
    const Rect& d = map.domain();
    std::uniform_real_distribution<double> ux(d.x0, d.x1), uy(d.y0, d.y1);
    for (int i = 0; i < kPoints; ++i) {
      Eigen::Vector2d n(ux(rng), uy(rng));
      actual.push_back(n + map.Delta(n));
    }
  }
};

const Fixture& Data() {
  static const Fixture fixture;
  return fixture;
}

template <typename Solver>
void RunSolver(benchmark::State& state, const Solver& solver) {
  const std::vector<Eigen::Vector2d>& points = Data().actual;
  double max_residual = 0;
  int max_iterations = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    Solution s = solver.Solve(points[i], OutsidePolicy::kError);
    benchmark::DoNotOptimize(s);
    max_residual = std::max(max_residual, s.residual_mm);
    max_iterations = std::max(max_iterations, s.iterations);
    if (++i == points.size()) i = 0;
  }
  state.counters["solves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["max_residual_mm"] = max_residual;
  state.counters["max_iterations"] = max_iterations;
}

void BM_InverseDefault(benchmark::State& state) {
  InverseSolver solver(*Data().table);
  RunSolver(state, solver);
  state.counters["iteration_bound"] = solver.iteration_bound();
}
BENCHMARK(BM_InverseDefault);

void BM_InversePaper(benchmark::State& state) {
  PaperSolver solver(*Data().table);  // kPaperSolverTolMm
  RunSolver(state, solver);
}
BENCHMARK(BM_InversePaper);

void BM_InversePaperAskedFor1e9(benchmark::State& state) {
  PaperSolver solver(*Data().table, kInverseResidualTolMm);
  RunSolver(state, solver);
}
BENCHMARK(BM_InversePaperAskedFor1e9);

void BM_Forward(benchmark::State& state) {
  CalibrationMap map(*Data().table);
  const std::vector<Eigen::Vector2d>& points = Data().actual;
  std::size_t i = 0;
  for (auto _ : state) {
    Solution s = DirectCalibrate(map, points[i], OutsidePolicy::kError);
    benchmark::DoNotOptimize(s);
    if (++i == points.size()) i = 0;
  }
  state.counters["solves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Forward);

}  // namespace
}  // namespace smtcal
