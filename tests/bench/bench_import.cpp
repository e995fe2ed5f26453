// `smtcal import` of a generated 100 000-row KiCad CSV placement list: the
// whole path from the list's text to the printed program (detection,
// reading row by row, feeder matching, the IR, the canonical printer).
// Target (tests/bench/README.md): under 0.3 s; `peak_rss_mb` is the
// process's peak resident memory (run this benchmark alone), and
// `list_mb` / `program_mb` the sizes of the input and the output.
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

void BM_Import100kRows(benchmark::State& state) {
  const std::string& list = GeneratedList();
  std::size_t program_bytes = 0;
  for (auto _ : state) {
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
    if (!program || diags.error_count() != 0) state.SkipWithError("the import failed");
    std::string text = PrintPlace(*program);
    program_bytes = text.size();
    benchmark::DoNotOptimize(text.data());
  }
  state.counters["rows"] = kRows;
  state.counters["list_mb"] = static_cast<double>(list.size()) / 1e6;
  state.counters["program_mb"] = static_cast<double>(program_bytes) / 1e6;
  state.counters["peak_rss_mb"] = bench::PeakRssMb();
}
BENCHMARK(BM_Import100kRows)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace
}  // namespace smtcal
