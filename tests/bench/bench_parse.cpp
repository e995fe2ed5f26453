// Parse + check of a generated 100 000-line program (target: < 1 s, < 300 MB).
// Peak resident memory of the whole process is reported as a counter.
#include <benchmark/benchmark.h>

#include "frontend/parse.h"
#include "passes/pass_manager.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/program_generator.h"

namespace smtcal {
namespace {

void BM_ParseAndCheck100kLines(benchmark::State& state) {
  const std::string text = bench::GenerateProgram(100000);
  std::size_t errors = 0;
  for (auto _ : state) {
    SourceManager sources;
    std::uint32_t file = sources.Add("bench.place", text);
    Diagnostics diags(sources);
    ir::Program program = ParseProgram(file, diags);
    if (!diags.has_errors()) {
      Status status = RunPasses(program, diags, std::vector<std::string>{}, false);
      if (!status) state.SkipWithError(status.error().message.c_str());
    }
    benchmark::DoNotOptimize(program);
    errors = diags.error_count();
  }
  state.counters["errors"] = static_cast<double>(errors);
  state.counters["lines"] = 100000;
  state.counters["peak_rss_mb"] = bench::PeakRssMb();
}
BENCHMARK(BM_ParseAndCheck100kLines)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace smtcal
