// `smtcal scan report --cell CELL.toml [--fixture NAME] [--program P.place]
// [--json] [--svg FILE]`: the design of a fixture's marker scan (docs/periphery.md,
// "The scan's design"): time, capture range, the pose's covariance per
// estimator, the worst placement error the scan adds, suggestions, and a
// picture. The numbers are backend/reports/scan_report.h's; this file wires
// the files, the options, the output and the exit codes.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "backend/reports/scan_report.h"
#include "calibration/fixture_geometry.h"
#include "frontend/cell_toml.h"
#include "passes/correction/compile_state.h"
#include "tools/commands.h"
#include "tools/compile_or_report.h"

namespace smtcal::tools {
namespace {

struct ScanReportOptions {
  std::string cell;
  std::string fixture;  // empty: the cell's only fixture
  std::string program;  // optional: the placements and where its cycle ends
  std::string svg;
  bool json = false;
};

// The program's placements on `fixture` (fixture frame), and where its first
// Cycle on the fixture leaves the robot (the scan of the next cycle starts
// there).
void ProgramPoints(const CompileState& state, const cell::Fixture& fixture, std::vector<ScanReportPoint>& points,
                   std::optional<ScanPoint>& from) {
  for (const auto& [cycle, events] : state.cycle_traces) {
    bool ours = false;
    std::optional<ScanPoint> end;
    for (const TraceEvent& event : events) {
      if (event.kind != TraceEvent::Kind::kMotion) continue;
      const Target& target = state.targets[event.target];
      if (!target.known) continue;
      // The command (base frame; a fixture target's at the nominal pose).
      const Pose4& at = target.kind == CorrectionKind::kUncorrected ? target.required : target.nominal;
      end = ScanPoint(at[0], at[1], at[2]);
      if (target.kind != CorrectionKind::kFixture || !target.is_placement()) continue;
      if (state.fixtures[target.fixture].cell_fixture != &fixture) continue;
      ours = true;
      points.push_back({fmt::format("{} (line {})", target.text, target.stmt->loc.line), Xy(target.in_frame)});
    }
    if (ours && !from) from = end;
  }
}

void Run(const ScanReportOptions& opt, GlobalOptions& options) {
  if (FilesClash({{"--cell", opt.cell}, {"--program", opt.program}}, {{"--svg", opt.svg}, {"the report", "-"}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  CompiledProgram compiled;
  std::optional<cell::Cell> loaded_cell;
  const cell::Cell* cell = nullptr;
  if (!opt.program.empty()) {
    if (!CompileForCellOrReport(opt.program, opt.cell, false, sources, diags, compiled, options)) return;
    if (diags.has_errors()) {
      options.exit_code = PrintDiagnostics(diags, options);
      return;
    }
    cell = &*compiled.cell;
  } else {
    loaded_cell = LoadCellOrReport(opt.cell, sources, diags, options);
    if (!loaded_cell) return;
    cell = &*loaded_cell;
  }
  if (cell->fixtures.empty()) {
    // The cell is valid (`cell check` passes it); it has no scan to report.
    options.exit_code = PrintDiagnostics(diags, options);
    options.exit_code = ReportInputError(fmt::format(
        "the cell {} describes no fixture, so it has no marker scan to report; a fixture board re-registered "
        "every cycle is a [[fixture]] table of the cell file (docs/cell.md)",
        opt.cell));
    return;
  }
  const cell::Fixture* fixture = opt.fixture.empty() && cell->fixtures.size() == 1 ? &cell->fixtures.front()
                                                                                  : cell->FindFixture(opt.fixture);
  if (fixture == nullptr) {
    std::string names;
    for (const cell::Fixture& f : cell->fixtures) names += (names.empty() ? "" : ", ") + f.name;
    options.exit_code = ReportUsageError(fmt::format(
        "{}; {}",
        opt.fixture.empty()
            ? fmt::format("the cell {} has {} fixtures: name one with --fixture", opt.cell, cell->fixtures.size())
            : fmt::format("the cell {} has no fixture '{}'", opt.cell, opt.fixture),
        names.empty() ? "it describes none" : "its fixtures: " + names));
    return;
  }
  std::vector<ScanReportPoint> points;
  std::optional<ScanPoint> from;
  if (!opt.program.empty()) ProgramPoints(*compiled.program.compile, *fixture, points, from);
  const ScanReport report = MakeScanReport(*cell, *fixture, std::move(points), from);
  options.exit_code = PrintDiagnostics(diags, options);
  std::optional<StagedOutput> svg;
  if (!opt.svg.empty()) {
    Result<StagedOutput> staged = StagedOutput::Stage(opt.svg, ScanReportSvg(report));
    if (!staged) {
      options.exit_code = ReportIoError(staged.error());
      return;
    }
    svg.emplace(std::move(staged).value());
  }
  Status written = WriteFileAtomically("-", opt.json ? ScanReportJson(report) : ScanReportText(report));
  if (written && svg) written = svg->Commit();
  if (!written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (svg) SayDone(options, opt.svg, fmt::format("wrote {} (the scan of fixture '{}')", opt.svg, fixture->name));
}

}  // namespace

void AddScanCommand(CLI::App& app, GlobalOptions& options) {
  static ScanReportOptions opt;
  CLI::App* scan = app.add_subcommand("scan", "The design of a fixture's marker scan");
  scan->require_subcommand(1);
  CLI::App* report = scan->add_subcommand(
      "report",
      "A fixture's marker scan as designed (docs/periphery.md): its time a cycle, its capture range against\n"
      "the fixture's limits, the pose's covariance per estimator from the sensor, the latency and the\n"
      "repeatability, the worst placement error it adds, suggestions where the layout is weak; --svg draws\n"
      "the board with markers, paths, nominal trips and error ellipses");
  report->add_option("--cell", opt.cell, "the cell file (*.cell.toml)")->required();
  report->add_option("--fixture", opt.fixture, "the fixture's name (case-insensitive); needed when the cell has several");
  report->add_option("--program", opt.program,
                     "a .place program for the cell: the scan's error at its placements on the fixture, and the\n"
                     "scan's time from where its cycle ends (without: a grid over the board, from the first path)");
  report->add_option("--svg", opt.svg, "also write the picture (SVG)");
  report->add_flag("--json", opt.json, "print JSON instead of text");
  report->callback([&options] { Run(opt, options); });
}

}  // namespace smtcal::tools
