// smtcal simulate's Monte Carlo on the paper's example cell: layers.place
// (40 parts per cycle) compiled for paper.cell.toml, 10 000 cycles in each of
// the six correction modes on the same draws (seed 19940101, the default
// truth of docs/simulate.md). The counters are the figures docs/simulate.md
// quotes: per mode the fraction within ±0.1 mm (within_<mode>, %), the p99
// error (p99_um_<mode>) and the stopped cycles (faults_<mode>); for the
// paper's modes, which run without the cell's scan checks, the cycles those
// checks would have stopped (would_stop_<mode>).
#include <algorithm>

#include <benchmark/benchmark.h>

#include "passes/compile_pipeline.h"
#include "passes/correction/compile_state.h"
#include "simulation/virtual_cell.h"

namespace smtcal {
namespace {

void BM_SimulatePaperCell(benchmark::State& state) {
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::uint32_t> file = sources.Load(SMTCAL_SOURCE_DIR "/examples/paper-cell/layers.place");
  if (!file) {
    state.SkipWithError("the paper cell example does not load");
    return;
  }
  CompiledProgram compiled;
  Result<bool> ran = CompileForCell(file.value(), SMTCAL_SOURCE_DIR "/examples/paper-cell/paper.cell.toml", false,
                                    sources, diags, compiled);
  if (!ran || !ran.value() || diags.has_errors()) {
    state.SkipWithError("the paper cell example does not compile");
    return;
  }
  const ir::Program& program = compiled.program;
  SimOptions options;
  options.cycles = static_cast<int>(state.range(0));
  options.seed = 19940101;
  SimResult result;
  for (auto _ : state) {
    result = Simulate(*program.compile, TruthSpec{}, options);
    benchmark::DoNotOptimize(result);
  }
  for (ModeResult& mode : result.modes) {
    const std::string name(SimModeName(mode.mode));
    std::sort(mode.errors_um.begin(), mode.errors_um.end());
    state.counters["within_" + name] =
        mode.placements > 0 ? 100.0 * static_cast<double>(mode.within) / static_cast<double>(mode.placements) : 0.0;
    state.counters["p99_um_" + name] = Percentile(mode.errors_um, 0.99);
    state.counters["faults_" + name] = mode.faults;
    if (UsesPeriphery(mode.mode) && !UsesCellChecks(mode.mode)) state.counters["would_stop_" + name] = mode.would_stop;
  }
  state.counters["placements_per_s"] =
      benchmark::Counter(static_cast<double>(result.placements_planned * 6), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SimulatePaperCell)->Arg(10000)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace smtcal
