// smtcal compile of a generated program with 100 000 placements for the paper
// cell: parse, checks, cell loading, the correction passes and printing the
// corrected program. Peak resident memory is reported (run it alone:
// --benchmark_filter=Compile for a figure of its own).
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include "backend/linuxcnc/linuxcnc_emit.h"
#include "backend/place/place_printer.h"
#include "passes/compile_pipeline.h"
#include "passes/correction/compile_state.h"
#include "tests/bench/bench_support.h"

namespace smtcal {
namespace {

// Placements spread over the three layers of the paper cell, each a point of
// its own In its layer, picked from the two feeder banks.
std::string GeneratePlacements(int placements) {
  std::string text = "Program Bench\nUnits mm\nFixture Board\nVacuum 8\n";
  text += "Local Layer1 = XY(12.0, 20.0, 0.0, 0.0) In Board\n";
  text += "Local Layer2 = XY(67.8, 20.0, 0.0, 0.0) In Board\n";
  text += "Local Layer3 = XY(123.6, 20.0, 0.0, 0.0) In Board\n";
  text += "Point Bank1First = XY(160.0, 10.0, -12.0, 0.0)\nPoint Bank1Last = XY(195.0, 10.0, -12.0, 0.0)\n";
  text += "Point Bank1Back = XY(160.0, 22.0, -12.0, 0.0)\nPallet 1, Bank1First, Bank1Last, Bank1Back, 8, 2\n";
  for (int i = 0; i < placements; ++i) {
    int cell = i % 10000;  // 100 x 100 positions per layer, 0.38 mm apart
    text += fmt::format("Point P{} = XY({:.3f}, {:.3f}, -3.0, {}.0) In Layer{}\n", i, 6.0 + (cell % 100) * 0.38,
                        6.0 + (cell / 100) * 0.38, (i % 4) * 90, 1 + (i / 10000) % 3);
  }
  text += "Function Main\n  Cycle Board\n";
  for (int i = 0; i < placements; ++i) {
    text += fmt::format("    Pick Pallet(1, {}, {})\n    Place P{}\n", 1 + i % 8, 1 + (i / 8) % 2, i);
  }
  text += "  EndCycle\nFend\n";
  return text;
}

// state.range(1): 0 emits the corrected .place program, 1 the LinuxCNC
// program (DESIGN's target: "to a verified LinuxCNC program").
void BM_Compile100kPlacements(benchmark::State& state) {
  const int placements = static_cast<int>(state.range(0));
  const bool linuxcnc = state.range(1) == 1;
  const std::string text = GeneratePlacements(placements);
  const std::string cell_path = SMTCAL_SOURCE_DIR "/examples/paper-cell/paper.cell.toml";
  std::size_t errors = 0, bytes = 0;
  for (auto _ : state) {
    SourceManager sources;
    std::uint32_t file = sources.Add("bench.place", text);
    Diagnostics diags(sources);
    CompiledProgram compiled;
    Result<bool> ran = CompileForCell(file, cell_path, false, sources, diags, compiled);
    if (!ran || !ran.value()) {
      state.SkipWithError("the generated program or the paper cell does not load");
      return;
    }
    const ir::Program& program = compiled.program;
    std::string corrected;
    if (linuxcnc) {
      std::optional<LinuxCncOutput> output = EmitLinuxCnc(program, *program.compile, "bench.place", diags);
      if (!output) {
        state.SkipWithError("the LinuxCNC target refused the generated program");
        return;
      }
      corrected = std::move(output->main_text);
    } else {
      corrected = PrintPlace(program);
    }
    bytes = corrected.size();
    errors = diags.error_count();
    benchmark::DoNotOptimize(corrected);
  }
  state.counters["errors"] = static_cast<double>(errors);
  state.counters["placements"] = placements;
  state.counters["output_mb"] = static_cast<double>(bytes) / 1e6;
  state.counters["peak_rss_mb"] = bench::PeakRssMb();
}
BENCHMARK(BM_Compile100kPlacements)
    ->Args({100000, 0})
    ->Args({100000, 1})
    ->ArgNames({"placements", "linuxcnc"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

}  // namespace
}  // namespace smtcal
