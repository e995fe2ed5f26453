// smtcal monitor LOG... --cell CELL: what the cycle records a controller
// kept say about the cell (docs/monitor.md): control charts, drifts and what
// they mean, refusals, process figures; exit 1 when it is out of control. The
// reader is frontend/record_log, the statistics calibration/cycle_monitor,
// the reports backend/reports/monitor_report; this file wires files, options
// and exit codes.
#include <fmt/core.h>

#include "backend/reports/monitor_report.h"
#include "base/field_text.h"
#include "base/json_text.h"
#include "spc/cycle_monitor.h"
#include "calibration/limits.h"
#include "frontend/cell_toml.h"
#include "frontend/record_log.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

struct MonitorCommandOptions {
  std::vector<std::string> logs;
  std::string cell_path;
  MonitorOptions monitor;
  int baseline = static_cast<int>(MonitorOptions{}.baseline);  // --baseline, into monitor.baseline
  bool json = false;
  std::string svg_path;
  bool exit_zero = false;
};

std::string FixtureList(const cell::Cell& cell) {
  std::string list;
  for (const cell::Fixture& fixture : cell.fixtures) list += (list.empty() ? "" : ", ") + fixture.name;
  return list.empty() ? "none" : list;
}

// The log's fixtures against the cell's: every one the cell has, with its
// number of trips. The records as the monitor takes them.
std::vector<MonitoredCycle> Match(const RecordLog& log, const cell::Cell& cell, Diagnostics& diags) {
  std::vector<MonitoredCycle> cycles;
  std::vector<bool> begin_ok(log.begins.size(), true);
  for (std::size_t b = 0; b < log.begins.size(); ++b) {
    const LoggedBegin& begin = log.begins[b];
    if (AsciiLowercase(begin.begin.cell) != AsciiLowercase(RecordName(cell.name)) &&
        (b == 0 || begin.begin.cell != log.begins[b - 1].begin.cell)) {
      diags.Report(DiagKind::MonitorOtherCell, begin.where, begin.begin.cell, cell.name);
    }
    for (const RecordFixture& fixture : begin.begin.fixtures) {
      const cell::Fixture* match = nullptr;
      for (const cell::Fixture& candidate : cell.fixtures) {
        if (AsciiLowercase(RecordName(candidate.name)) == AsciiLowercase(fixture.name)) match = &candidate;
      }
      if (match == nullptr) {
        diags.Report(DiagKind::MonitorUnknownFixture, begin.where, fixture.name, cell.name, FixtureList(cell));
        begin_ok[b] = false;
      } else if (ExpectedTrips(*match).size() != fixture.trips) {
        diags.Report(DiagKind::MonitorTripCount, begin.where, fixture.name, fixture.trips, ExpectedTrips(*match).size(),
                     cell.name);
        begin_ok[b] = false;
      }
    }
  }
  for (const LoggedCycle& logged : log.cycles) {
    if (!begin_ok[logged.begin]) continue;
    const RecordBegin& begin = log.begins[logged.begin].begin;
    cycles.push_back({begin.fixtures[static_cast<std::size_t>(logged.record.fixture)].name, logged.record});
  }
  return cycles;
}

// The log's n-th record (1-based) of a fixture.
const LoggedCycle* NthOf(const RecordLog& log, std::string_view fixture, long n) {
  long seen = 0;
  for (const LoggedCycle& logged : log.cycles) {
    const RecordBegin& begin = log.begins[logged.begin].begin;
    if (AsciiLowercase(begin.fixtures[static_cast<std::size_t>(logged.record.fixture)].name) !=
        AsciiLowercase(RecordName(fixture))) {
      continue;
    }
    if (++seen == n) return &logged;
  }
  return nullptr;
}

void RunMonitor(MonitorCommandOptions& opt, GlobalOptions& options) {
  std::vector<NamedFile> inputs;
  for (const std::string& log : opt.logs) inputs.push_back({"LOG", log});
  inputs.push_back({"--cell", opt.cell_path});
  if (FilesClash(inputs, {{"--svg", opt.svg_path}, {"the report", "-"}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  opt.monitor.baseline = static_cast<std::size_t>(opt.baseline);
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(opt.cell_path, sources, diags);
  if (!loaded) {
    PrintDiagnostics(diags, options);
    options.exit_code = ReportIoError(loaded.error());
    return;
  }
  RecordLog log;
  for (const std::string& path : opt.logs) {
    Result<std::uint32_t> file = sources.Load(path);
    if (!file) {
      PrintDiagnostics(diags, options);
      options.exit_code = ReportIoError(file.error());
      return;
    }
    ReadRecordLog(file.value(), log, diags);
  }
  if (diags.has_errors() || !loaded.value()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  const cell::Cell& cell = *loaded.value();
  const std::vector<MonitoredCycle> cycles = Match(log, cell, diags);
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  const MonitorResult result = Monitor(cell, cycles, opt.monitor);
  for (const FixtureMonitor& f : result.fixtures) {
    if (!f.charted) {
      const SourceRange where = log.begins.empty() ? SourceRange() : log.begins.front().where;
      diags.Report(DiagKind::MonitorTooFewScans, where, f.name, f.accepted, opt.monitor.baseline);
    }
    if (f.disagreements > 0) {
      const LoggedCycle* first = NthOf(log, f.name, f.first_disagreement_scan);
      diags.Report(DiagKind::MonitorRecordDisagrees, first != nullptr ? first->where : SourceRange(), f.disagreements,
                   f.scans, f.name, cell.name,
                   f.worst_disagreement_mm > 0 ? fmt::format("{:.4f} mm", f.worst_disagreement_mm) : "its verdict");
    }
  }
  if (result.fixtures.empty()) {
    diags.Report(DiagKind::MonitorUnknownFixture, log.begins.empty() ? SourceRange() : log.begins.front().where, "-",
                 cell.name, FixtureList(cell));
  }
  options.exit_code = PrintDiagnostics(diags, options);
  if (options.exit_code != kExitOk) return;
  MonitorContext context{opt.logs, &cell, opt.monitor, static_cast<long>(log.cycles.size())};
  if (!opt.svg_path.empty()) {
    if (Status written = WriteFileAtomically(opt.svg_path, MonitorReportSvg(result, context)); !written) {
      options.exit_code = ReportIoError(written.error());
      return;
    }
  }
  const std::string text = opt.json ? JsonText(MonitorReportJson(result, context)) : MonitorReportText(result, context);
  if (Status written = WriteFileAtomically("-", text); !written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (!opt.svg_path.empty()) SayDone(options, opt.svg_path, fmt::format("wrote the control charts {}", opt.svg_path));
  options.exit_code = result.in_control || opt.exit_zero ? kExitOk : kExitInputError;
}

}  // namespace

void AddMonitorCommand(CLI::App& app, GlobalOptions& options) {
  static MonitorCommandOptions opt;
  CLI::App* monitor = app.add_subcommand(
      "monitor",
      "Read the cycle records a controller kept (logs of several shifts, oldest first) and report what they say: "
      "control charts of the board's pose, the marker distance, the sensor and the residuals, refusals per check, "
      "drifts and what to do, process figures; exit 1 when the cell is out of control");
  monitor->add_option("LOG", opt.logs, "the logs of cycle records, oldest first (docs/monitor.md)")->required();
  monitor->add_option("--cell", opt.cell_path, "the cell file the records were made with (*.cell.toml)")->required();
  AddNumberOption(*monitor, "--baseline", opt.baseline,
                  "the first accepted scans of each fixture that set the charts' centre lines and sigmas",
                  limits::kMonitorBaseline)
      ->capture_default_str();
  monitor->add_flag("--json", opt.json, "print the report as JSON (docs/monitor.md) instead of text");
  monitor->add_option("--svg", opt.svg_path, "also draw the control charts to this SVG file");
  monitor->add_flag("--exit-zero", opt.exit_zero,
                    "report only: exit 0 even when the cell is out of control (input and I/O errors still exit 1 "
                    "and 3)");
  monitor->footer(
      "Exit codes: 0 in control, 1 out of control (a CUSUM or EWMA alarm on a chart, or refusals rising) or errors in "
      "the input, 2 usage, 3 I/O. A shift-start script: smtcal monitor board.log --cell cell.toml -q || stop.");
  monitor->callback([&options] { RunMonitor(opt, options); });
}

}  // namespace smtcal::tools
