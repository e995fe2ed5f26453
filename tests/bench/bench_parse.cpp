// Parse + check of a generated 100 000-line program (target: < 0.3 s), and
// beside it a floor: one plain pass over the same bytes (counting lines and
// words), the least any reader of the file must do; the ratio of the two is
// what the parser costs per byte beyond touching it. Peak resident memory of
// each benchmark alone is reported as a counter.
#include <benchmark/benchmark.h>

#include "frontend/parse.h"
#include "passes/pass_manager.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/program_generator.h"

namespace smtcal {
namespace {

const std::string& Program100kLines() {
  static const std::string text = bench::GenerateProgram(100000);
  return text;
}

void BM_ParseAndCheck100kLines(benchmark::State& state) {
  const std::string& text = Program100kLines();
  std::size_t errors = 0;
  bench::ResetPeakRss();
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
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
  state.counters["errors"] = static_cast<double>(errors);
  state.counters["lines"] = 100000;
  state.counters["peak_rss_mb"] = bench::PeakRssMb();
}
BENCHMARK(BM_ParseAndCheck100kLines)->Unit(benchmark::kMillisecond)->Iterations(5);

// The floor: every byte looked at once, lines and words counted.
void BM_ByteScan100kLines(benchmark::State& state) {
  const std::string& text = Program100kLines();
  std::size_t lines = 0, words = 0;
  for (auto _ : state) {
    lines = 0;
    words = 0;
    bool in_word = false;
    for (char c : text) {
      bool space = c == ' ' || c == '\t' || c == '\n' || c == '\r';
      lines += c == '\n' ? 1 : 0;
      words += !space && !in_word ? 1 : 0;
      in_word = !space;
    }
    benchmark::DoNotOptimize(lines);
    benchmark::DoNotOptimize(words);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
  state.counters["lines"] = static_cast<double>(lines);
  state.counters["words"] = static_cast<double>(words);
}
BENCHMARK(BM_ByteScan100kLines)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace smtcal
