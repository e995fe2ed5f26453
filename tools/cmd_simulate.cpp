// smtcal simulate: a .place program compiled for a cell (the checks and the
// correction passes of `smtcal compile`), then run on the virtual cell
// (simulation/virtual_cell.h) in six correction modes on the same random draws;
// prints the placement accuracy per mode (docs/simulate.md).
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "base/json_text.h"
#include "backend/reports/compile_report.h"
#include "backend/c/record_text.h"
#include "backend/reports/simulate_report.h"
#include "base/text_output.h"
#include "calibration/cell.h"
#include "calibration/limits.h"
#include "frontend/parse.h"
#include "frontend/truth_toml.h"
#include "ir/symbols.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"
#include "passes/pass_manager.h"
#include "simulation/virtual_cell.h"
#include "ir/ir_ops.h"
#include "tools/commands.h"
#include "tools/compile_or_report.h"

namespace smtcal::tools {
namespace {

struct SimulateOptions {
  std::string program_path;
  std::string cell_path;
  std::string truth_path;
  std::string svg;
  std::string record;
  bool json = false;
  SimOptions sim;
};

// The decimals of a simulated record: 1e-9 mm or deg, finer than anything
// the simulation models, in the plain decimals of the C runtime's formatter
// (the LinuxCNC runtime writes millionths and e-6, to 1e-15; docs/monitor.md).
constexpr int kRecordDecimals = 9;

// The improved mode's scans as the controller would log them (docs/monitor.md).
Status WriteRecord(const std::string& path, const SimResult& result, const cell::Cell& cell) {
  Result<std::unique_ptr<TextOutput>> opened = TextOutput::Open(path);
  if (!opened) return opened.error();
  TextOutput& out = *opened.value();
  RecordBegin begin;
  begin.cell = cell.name;
  for (const cell::Fixture& fixture : cell.fixtures) begin.fixtures.push_back({fixture.name, ExpectedTrips(fixture).size()});
  begin.clock = "simulate";
  out.Append(RecordBeginText(begin));
  for (const CycleRecord& record : result.records) out.Append(CycleRecordText(record, kRecordDecimals));
  return out.Commit();
}

// Placements the compile-time trace could not place (warned), and whether
// any Cycle places anything at all.
bool CheckTraces(const ir::Program& program, const CompileState& state, Diagnostics& diags) {
  bool places = false;
  for (const auto& [cycle, events] : state.cycle_traces) {
    for (const TraceEvent& event : events) {
      if (event.kind != TraceEvent::Kind::kMotion) continue;
      const Target& target = state.targets[event.target];
      if (!target.is_placement()) continue;
      places = places || target.known;
      if (!target.known) {
        diags.Report(DiagKind::SimulateUnknownTarget, sema::StmtRange(*target.stmt), TargetKeyword(*target.stmt),
                     target.text, target.unknown_because);
      }
    }
  }
  if (!places) {
    SourceLoc where = program.items.empty() ? SourceLoc{} : program.items.front()->loc;
    diags.Report(DiagKind::SimulateNoCycle, SourceRange(where));
  }
  return places;
}

// The memory this process may use: the machine's, or less under a limit.
std::uint64_t UsableMemoryBytes() {
  std::uint64_t bytes = static_cast<std::uint64_t>(sysconf(_SC_PHYS_PAGES)) * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
  for (int resource : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit limit{};
    if (getrlimit(resource, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
      bytes = std::min<std::uint64_t>(bytes, limit.rlim_cur);
    }
  }
  return bytes;
}

// Every placed part's error is kept (for the percentiles): a run that cannot
// fit is refused before it starts (exit 3, as other resource failures),
// never left to run out of memory halfway.
bool FitsInMemory(const CompileState& state, const SimOptions& sim, GlobalOptions& options) {
  const long planned = PlannedPlacements(state, sim);
  const double needed = static_cast<double>(planned) * kSimBytesPerPlacement;
  const std::uint64_t usable = UsableMemoryBytes();
  if (needed <= static_cast<double>(usable)) return true;
  const long per_cycle = planned / sim.cycles;
  const long cycles = per_cycle > 0 ? static_cast<long>(static_cast<double>(usable) / kSimBytesPerPlacement / per_cycle) : 0;
  options.exit_code = ReportIoError(Error{fmt::format(
      "simulating {} cycles of {} placements keeps {:.1f} GB of placement errors ({} bytes a placement), more "
      "than the {:.1f} GB this process may use; simulate at most {} cycles",
      sim.cycles, per_cycle, needed / 1e9, kSimBytesPerPlacement, static_cast<double>(usable) / 1e9, cycles)});
  return false;
}

// The work of a run is its planned placements, each in six modes: bounded
// by limits::kMaxSimulatedPlacements before it starts (a usage error: fewer
// --cycles fit), whatever the machine's memory would allow.
bool WithinPlacementLimit(const CompileState& state, const SimOptions& sim, GlobalOptions& options) {
  const long planned = PlannedPlacements(state, sim);
  if (planned <= limits::kMaxSimulatedPlacements) return true;
  const long per_cycle = planned / sim.cycles;
  options.exit_code = ReportUsageError(fmt::format(
      "--cycles {}: {} cycles of {} placements are {} placements, more than the {} a run of simulate takes "
      "(calibration/limits.h); give --cycles {} or fewer",
      sim.cycles, sim.cycles, per_cycle, planned, limits::kMaxSimulatedPlacements,
      std::max<long>(1, limits::kMaxSimulatedPlacements / std::max<long>(1, per_cycle))));
  return false;
}

void RunSimulate(const SimulateOptions& opt, GlobalOptions& options) {
  if (FilesClash({{"PROGRAM", opt.program_path}, {"--cell", opt.cell_path}, {"--truth", opt.truth_path}},
                 {{"--svg", opt.svg}, {"--record", opt.record}, {"the report", "-"}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  CompiledProgram compiled;
  // verify's verdicts on accuracy are what the simulation measures: they do
  // not stop it, the report says how many there were.
  compiled.report_budget_findings = false;
  if (!CompileForCellOrReport(opt.program_path, opt.cell_path, false, sources, diags, compiled, options)) return;
  std::size_t over_budget = 0;
  for (const Target& target : compiled.program.compile->targets) {
    if (!target.known || target.region == nullptr || target.kind == CorrectionKind::kUncorrected) continue;
    if (!std::holds_alternative<ir::PickPlace>(target.stmt->node)) continue;
    if (!target.budget_bounded || target.budget_mm > target.region->tolerance_mm) ++over_budget;
  }
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  TruthSpec truth;
  if (!opt.truth_path.empty()) {
    Result<std::optional<TruthSpec>> loaded = LoadTruth(opt.truth_path, *compiled.cell, sources, diags);
    if (!loaded) {
      PrintDiagnostics(diags, options);
      options.exit_code = ReportIoError(loaded.error());
      return;
    }
    if (loaded.value()) truth = std::move(*loaded.value());
  }
  const CompileState& state = *compiled.program.compile;
  CheckTraces(compiled.program, state, diags);
  options.exit_code = PrintDiagnostics(diags, options);
  if (diags.has_errors()) return;

  if (!WithinPlacementLimit(state, opt.sim, options) || !FitsInMemory(state, opt.sim, options)) return;
  SimOptions sim = opt.sim;
  sim.record = !opt.record.empty();
  SimResult result = Simulate(state, truth, sim);
  SimulateContext context{opt.program_path, &*compiled.cell, &truth, over_budget};
  if (!opt.svg.empty()) {
    if (Status written = WriteFileAtomically(opt.svg, SimulateReportSvg(result, context)); !written) {
      options.exit_code = ReportIoError(written.error());
      return;
    }
  }
  if (!opt.record.empty()) {
    if (Status written = WriteRecord(opt.record, result, *compiled.cell); !written) {
      options.exit_code = ReportIoError(written.error());
      return;
    }
  }
  std::string text = opt.json ? JsonText(SimulateReportJson(result, context)) : SimulateReportText(result, context);
  if (Status written = WriteFileAtomically("-", text); !written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (!opt.svg.empty()) SayDone(options, opt.svg, fmt::format("wrote the picture {}", opt.svg));
  if (!opt.record.empty()) {
    SayDone(options, opt.record,
            fmt::format("wrote {} cycle records to {} (read them with smtcal monitor)", result.records.size(), opt.record));
  }
}

}  // namespace

void AddSimulateCommand(CLI::App& app, GlobalOptions& options) {
  static SimulateOptions opt;
  CLI::App* simulate = app.add_subcommand(
      "simulate", "Compile a .place program for a cell and run its cycles on a virtual cell with true robot errors, "
                  "board poses and sensor noise; print the placement accuracy of six correction modes");
  simulate->add_option("PROGRAM", opt.program_path, "the .place program ('-' for stdin)")->required();
  simulate->add_option("--cell", opt.cell_path, "the cell file (*.cell.toml, docs/cell.md)")->required();
  simulate->add_option("--truth", opt.truth_path,
                       "the true world (TOML, docs/simulate.md): error field, board pose distribution, sensor and "
                       "robot accuracy; default: derived from the cell's tables");
  AddNumberOption(*simulate, "--cycles", opt.sim.cycles,
                  "how many times each Cycle statement runs: every placed part's error is kept, 56 bytes per "
                  "planned placement (a run that does not fit in memory is refused, exit 3), and a run plans at "
                  "most 10000000 placements",
                  limits::kSimCycles)
      ->capture_default_str();
  AddNumberOption(*simulate, "--seed", opt.sim.seed, "the random seed: the same seed gives the same report",
                  limits::kSimSeed)
      ->capture_default_str();
  simulate->add_flag("--json", opt.json, "print the report as JSON");
  simulate->add_option("--svg", opt.svg, "also write a picture: error scatter per mode and histograms");
  simulate->add_option("--record", opt.record,
                       "also write the record of every scan of the improved mode, as the controller's runtime logs "
                       "it (docs/monitor.md; read it with smtcal monitor)");
  AddNumberOption(*simulate, "--missed-trip-rate", opt.sim.missed_trip_rate,
                  "fault injection: probability per cycle that the sensor misses one trip", limits::kProbability);
  AddNumberOption(*simulate, "--dirty-marker-rate", opt.sim.dirty_marker_rate,
                  "fault injection: probability per cycle that one trip is displaced along its leg by "
                  "--dirty-marker-mm (a dirty marker)",
                  limits::kProbability);
  AddNumberOption(*simulate, "--dirty-marker-mm", opt.sim.dirty_marker_mm, "the displacement of a dirty marker's trip",
                  limits::kDirtyMarkerMm)
      ->capture_default_str();
  AddNumberOption(*simulate, "--board-beyond-rate", opt.sim.board_beyond_rate,
                  "fault injection: probability per cycle that the board lies 0.1 to 1 mm beyond the fixture's "
                  "max_shift_mm",
                  limits::kProbability);
  simulate->callback([&options] { RunSimulate(opt, options); });
}

}  // namespace smtcal::tools
