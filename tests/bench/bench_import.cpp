// `smtcal import` of a generated 100 000-row KiCad CSV placement list: the
// whole path from the list's text to the printed program (detection,
// reading row by row, feeder matching, the IR, the canonical printer).
// Target (tests/bench/README.md): under 0.3 s; `peak_rss_mb` is the
// process's peak resident memory (run this benchmark alone), and
// `list_mb` / `program_mb` the sizes of the input and the output.
// BM_ImportDuplicateDesignators: lists whose every row is U1, linear in n.
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include "backend/place/place_printer.h"
#include "frontend/cad/cad_reader.h"
#include "frontend/cad/cad_to_program.h"
#include "frontend/feeders_toml.h"
#include "tests/bench/bench_support.h"

namespace smtcal {
namespace {

constexpr int kRows = 100000;

struct Kind {
  const char* package;
  const char* value;
};
constexpr Kind kKinds[] = {
    {"C_0402_1005Metric", "100n"}, {"C_0603_1608Metric", "1u"},   {"C_0805_2012Metric", "10u"},
    {"R_0402_1005Metric", "10k"},  {"R_0603_1608Metric", "4k7"},  {"R_0805_2012Metric", "0R"},
    {"SOT-23", "BC847"},           {"SOD-123", "1N4148W"},       {"SOIC-8_3.9x4.9mm_P1.27mm", "LM358"},
    {"LED_0603_1608Metric", "red"}, {"L_1210_3225Metric", "10uH"}, {"QFN-32_5x5mm_P0.5mm", "STM32G0"},
};

// A KiCad CSV of kRows parts on a 400 x 300 mm board, both sides.
const std::string& GeneratedList() {
  static const std::string text = [] {
    std::string list = "Ref,Val,Package,PosX,PosY,Rot,Side\n";
    list.reserve(static_cast<std::size_t>(kRows) * 72);
    for (int i = 0; i < kRows; ++i) {
      const Kind& kind = kKinds[i % std::size(kKinds)];
      list += fmt::format("\"U{}\",\"{}\",\"{}\",{:.4f},{:.4f},{:.4f},{}\n", i + 1, kind.value, kind.package,
                          (i % 400) + 0.125 * (i % 7), (i / 400) % 300 + 0.0625 * (i % 5), (i % 8) * 45.0,
                          i % 10 == 0 ? "bottom" : "top");
    }
    return list;
  }();
  return text;
}

cad::FeedersFile Feeders() {
  cad::FeedersFile file;
  int lane = 0;
  for (const Kind& kind : kKinds) {
    cad::FeederSpec feeder;
    feeder.name = fmt::format("Lane{}", ++lane);
    feeder.pick = {100.0 + 10 * lane, 10.0, -12.0, 0.0};
    feeder.packages = {std::string(kind.package).substr(0, 6) + "*"};
    feeder.value = kind.value;
    file.feeders.push_back(std::move(feeder));
  }
  return file;
}

// One whole import of `list`, as `smtcal import` runs it; the program's
// size in bytes, or 0 after marking the run failed.
std::size_t ImportOnce(benchmark::State& state, const std::string& list) {
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("bench.csv", list);
  std::optional<cad::FeederTable> feeders = cad::FeederTable::Build({}, Feeders(), diags);
  std::unique_ptr<cad::ListReader> reader = cad::OpenList(file, {}, diags);
  ImportOptions options;
  options.side = cad::Side::kTop;
  options.fixture = "Board";
  options.program_name = "Bench";
  CadImporter importer(*feeders, options, file, diags);
  cad::Row row;
  while (reader->Next(row)) importer.Add(row);
  std::optional<ir::Program> program = importer.Finish(*reader);
  if (!program || diags.error_count() != 0) {
    state.SkipWithError("the import failed");
    return 0;
  }
  std::string text = PrintPlace(*program);
  benchmark::DoNotOptimize(text.data());
  return text.size();
}

void BM_Import100kRows(benchmark::State& state) {
  const std::string& list = GeneratedList();
  std::size_t program_bytes = 0;
  for (auto _ : state) program_bytes = ImportOnce(state, list);
  state.counters["rows"] = kRows;
  state.counters["list_mb"] = static_cast<double>(list.size()) / 1e6;
  state.counters["program_mb"] = static_cast<double>(program_bytes) / 1e6;
  state.counters["peak_rss_mb"] = bench::PeakRssMb();
}
BENCHMARK(BM_Import100kRows)->Unit(benchmark::kMillisecond)->Iterations(5);

// A list in which every row has the same designator, U1 (issue 20: each
// duplicate used to try U1_2, U1_3, ... from 2, so n rows cost n^2 / 2
// name lookups). Each duplicate still gets its warning. The time per row
// must not grow with n (`s_per_row`).
void BM_ImportDuplicateDesignators(benchmark::State& state) {
  const auto rows = static_cast<int>(state.range(0));
  std::string list = "Ref,Val,Package,PosX,PosY,Rot,Side\n";
  for (int i = 0; i < rows; ++i) {
    list += fmt::format("\"U1\",\"10k\",\"R_0402_1005Metric\",{:.4f},{:.4f},0,top\n", (i % 400) * 0.5, (i / 400) * 0.5);
  }
  for (auto _ : state) ImportOnce(state, list);
  state.counters["rows"] = rows;
  state.counters["s_per_row"] = benchmark::Counter(static_cast<double>(rows),
                                                    benchmark::Counter::kIsIterationInvariantRate |
                                                        benchmark::Counter::kInvert);
}
BENCHMARK(BM_ImportDuplicateDesignators)->Arg(5000)->Arg(20000)->Arg(80000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace smtcal
