// smtcal compile of a generated CAD-sized program (program_generator.h:
// one point and one Pick/Place pair per placement) for the paper cell, at
// 1 k, 10 k, 100 k and 1 M placements: parse, checks, cell loading, the
// correction passes (compile-time run, static inversion, fixture correction,
// verify) and the output written to a file, as `smtcal compile -o` does.
// BM_CompilePlace writes the corrected .place program, BM_CompileLinuxCnc the
// LinuxCNC directory (DESIGN's target: 100 000 placements to a verified
// LinuxCNC program in under 1 s and 300 MB; 1 M in 10 s and 2 GB). Counters:
// the main output's size and the peak resident memory of the benchmark alone
// (the generated program text is part of it, twice: the generator's copy and
// the SourceManager's); each family's BigO line fits the CPU time to N.
#include <unistd.h>

#include <filesystem>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "backend/linuxcnc/linuxcnc_emit.h"
#include "backend/place/place_printer.h"
#include "passes/compile_pipeline.h"
#include "passes/correction/compile_state.h"
#include "tests/bench/bench_support.h"
#include "tests/bench/program_generator.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

// Writes the compiled program as `smtcal compile -o PATH` does (as it is
// produced, into a temporary renamed at the end); returns the bytes of the
// main output, or nullopt when the emitter refused it.
std::optional<std::uintmax_t> WriteOutput(const ir::Program& program, bool linuxcnc, const fs::path& path,
                                          Diagnostics& diags) {
  if (linuxcnc) {
    const std::string main_name = LinuxCncMainName("bench.place");
    Result<std::unique_ptr<LinuxCncDirectory>> directory = LinuxCncDirectory::Open(path, main_name);
    if (!directory) return std::nullopt;
    std::optional<LinuxCncOutput> output =
        EmitLinuxCnc(program, *program.compile, "bench.place", directory.value()->main(), diags);
    if (!output || diags.has_errors() || !directory.value()->Commit(*output)) return std::nullopt;
    return fs::file_size(path / main_name);
  }
  if (!WritePlace(path.string(), program)) return std::nullopt;
  return fs::file_size(path);
}

void Compile(benchmark::State& state, bool linuxcnc) {
  const int placements = static_cast<int>(state.range(0));
  const std::string text = bench::GeneratePlacements(placements);
  const std::string cell_path = SMTCAL_SOURCE_DIR "/examples/paper-cell/paper.cell.toml";
  const fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_bench_compile_{}", ::getpid());
  fs::create_directories(dir);
  const fs::path out = dir / (linuxcnc ? "out" : "out.place");
  std::uintmax_t bytes = 0;
  bench::ResetPeakRss();
  for (auto _ : state) {
    SourceManager sources;
    std::uint32_t file = sources.Add("bench.place", text);
    Diagnostics diags(sources);
    CompiledProgram compiled;
    Result<bool> ran = CompileForCell(file, cell_path, false, sources, diags, compiled);
    if (!ran || !ran.value() || diags.has_errors()) {
      state.SkipWithError("the generated program or the paper cell does not compile");
      break;
    }
    std::optional<std::uintmax_t> written = WriteOutput(compiled.program, linuxcnc, out, diags);
    if (!written) {
      state.SkipWithError("the output was refused or could not be written");
      break;
    }
    bytes = *written;
  }
  const double peak_mb = bench::PeakRssMb();
  fs::remove_all(dir);
  state.SetComplexityN(placements);
  state.counters["placements"] = placements;
  state.counters["output_mb"] = static_cast<double>(bytes) / 1e6;
  state.counters["peak_rss_mb"] = peak_mb;
}

void BM_CompilePlace(benchmark::State& state) { Compile(state, false); }
void BM_CompileLinuxCnc(benchmark::State& state) { Compile(state, true); }
BENCHMARK(BM_CompilePlace)
    ->RangeMultiplier(10)
    ->Range(1000, 1000000)
    ->ArgName("placements")
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);
BENCHMARK(BM_CompileLinuxCnc)
    ->RangeMultiplier(10)
    ->Range(1000, 1000000)
    ->ArgName("placements")
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);

}  // namespace
}  // namespace smtcal
