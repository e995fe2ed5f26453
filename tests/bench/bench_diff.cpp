// smtcal diff of two generated programs of 1 M placements each
// (program_generator.h; NEW has every 1000th point 2 µm further along x):
// both parsed and checked, diffed as text, then compiled for the paper cell
// (the correction passes that decide the commands) and compared on the
// machine, and the text report made, as `smtcal diff OLD NEW --cell CELL`
// does with two source programs. Counters: the targets compared and moved,
// and the peak resident memory of the benchmark alone (both program texts
// are part of it, twice each).
#include <benchmark/benchmark.h>

#include "backend/diff/diff_report.h"
#include "backend/diff/program_diff.h"
#include "frontend/cell_toml.h"
#include "frontend/parse.h"
#include "passes/machine_targets.h"
#include "passes/pass_manager.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/program_generator.h"

namespace smtcal {
namespace {

ir::Program ParseAndCheck(std::uint32_t file, Diagnostics& diags) {
  ir::Program program = ParseProgram(file, diags);
  if (!diags.has_errors()) {
    std::vector<const PassInfo*> checks;
    for (const PassInfo& info : PassRegistry()) checks.push_back(&info);
    RunPasses(program, diags, checks, /*verify_each=*/false);
  }
  return program;
}

void BM_DiffPlacements(benchmark::State& state) {
  const int placements = static_cast<int>(state.range(0));
  const std::string old_text = bench::GeneratePlacements(placements);
  const std::string new_text = bench::GeneratePlacements(placements, 1000, 0.002);
  diff::Summary summary;
  std::size_t report_bytes = 0;
  bench::ResetPeakRss();
  for (auto _ : state) {
    SourceManager sources;
    std::uint32_t old_file = sources.Add("old.place", old_text);
    std::uint32_t new_file = sources.Add("new.place", new_text);
    Diagnostics diags(sources);
    ir::Program old_program = ParseAndCheck(old_file, diags);
    ir::Program new_program = ParseAndCheck(new_file, diags);
    Result<std::optional<cell::Cell>> cell =
        cell::LoadCell(SMTCAL_SOURCE_DIR "/examples/paper-cell/paper.cell.toml", sources, diags);
    if (diags.has_errors() || !cell || !cell.value()) {
      state.SkipWithError("the generated programs or the paper cell do not load");
      break;
    }
    diff::DiffOptions options;
    options.cell = &*cell.value();
    diff::ProgramDiff result = diff::DiffPrograms(old_program, new_program, options, diags);
    const MachineTargets old_targets = SourceProgramTargets(old_program, *cell.value(), diags);
    const MachineTargets new_targets = SourceProgramTargets(new_program, *cell.value(), diags);
    if (diags.has_errors()) {
      state.SkipWithError("the generated programs do not compile for the paper cell");
      break;
    }
    diff::CompareOnMachine(result, {&*cell.value(), &old_targets, {}}, {&*cell.value(), &new_targets, {}});
    std::string text = diff::FormatDiffText(result);
    summary = result.summary;
    report_bytes = text.size();
    benchmark::DoNotOptimize(text.data());
  }
  state.counters["placements"] = placements;
  state.counters["targets_compared"] = static_cast<double>(summary.targets_compared);
  state.counters["targets_moved"] = static_cast<double>(summary.targets_moved);
  state.counters["report_mb"] = static_cast<double>(report_bytes) / 1e6;
  state.counters["peak_rss_mb"] = bench::PeakRssMb();
}
BENCHMARK(BM_DiffPlacements)->Arg(1000000)->ArgName("placements")->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace smtcal
