// smtcal monitor LOG... --cell CELL: what the cycle records a controller
// kept say about the cell (docs/monitor.md): control charts, drifts and what
// they mean, refusals, process figures; exit 4 when it is out of control,
// 1 when the input cannot be judged. The reader is frontend/record_log, the
// statistics spc/cycle_monitor (the baseline file spc/baseline_file), the
// reports backend/reports/monitor_report; this file wires files, options
// and exit codes.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "backend/reports/monitor_report.h"
#include "base/field_text.h"
#include "base/json_text.h"
#include "calibration/limits.h"
#include "frontend/cell_toml.h"
#include "frontend/record_log.h"
#include "spc/baseline_file.h"
#include "spc/cycle_monitor.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

// monitor's own exit code (docs/files-and-exit-codes.md): the logs were read
// and judged, and the cell is out of control. Apart from 1 (the input could
// not be judged), so a line's script tells a drifting cell from a broken log.
constexpr int kExitOutOfControl = 4;

struct MonitorCommandOptions {
  std::vector<std::string> logs;
  std::string cell_path;
  MonitorOptions monitor;
  int baseline = static_cast<int>(MonitorOptions{}.baseline);  // --baseline, into monitor.baseline
  int baseline_from = 1;                                        // --baseline-from
  std::string baseline_in, baseline_out;
  bool json = false;
  std::string svg_path, csv_path;
  bool exit_zero = false;
};

std::string FixtureList(const cell::Cell& cell) {
  std::string list;
  for (const cell::Fixture& fixture : cell.fixtures) list += (list.empty() ? "" : ", ") + fixture.name;
  return list.empty() ? "none" : list;
}

// The log's runs against the cell: runs of another cell are left out (one
// warning per other cell), fixtures matched by name with their number of
// trips. The records as the monitor takes them.
std::vector<MonitoredCycle> Match(const RecordLog& log, const cell::Cell& cell, Diagnostics& diags) {
  std::vector<MonitoredCycle> cycles;
  std::vector<bool> ours(log.begins.size(), true), begin_ok(log.begins.size(), true);
  std::vector<long> records(log.begins.size(), 0);
  for (const LoggedCycle& logged : log.cycles) ++records[logged.begin];
  struct Other {
    std::size_t first_run = 0;
    long records = 0;
    int runs = 0;
  };
  std::map<std::string, Other> others;
  for (std::size_t b = 0; b < log.begins.size(); ++b) {
    const LoggedBegin& begin = log.begins[b];
    if (AsciiLowercase(begin.begin.cell) != AsciiLowercase(RecordName(cell.name))) {
      ours[b] = false;
      auto [it, fresh] = others.try_emplace(begin.begin.cell);
      if (fresh) it->second.first_run = b;
      it->second.records += records[b];
      ++it->second.runs;
      continue;
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
  for (const auto& [name, other] : others) {
    std::string what = other.records == 1 ? "1 record is" : fmt::format("{} records are", other.records);
    if (other.runs > 1) what = fmt::format("{} (in {} runs)", what, other.runs);
    diags.Report(DiagKind::MonitorOtherCell, log.begins[other.first_run].where, Printable(name), cell.name, what);
  }
  for (const LoggedCycle& logged : log.cycles) {
    if (!ours[logged.begin] || !begin_ok[logged.begin]) continue;
    const RecordBegin& begin = log.begins[logged.begin].begin;
    cycles.push_back({begin.fixtures[static_cast<std::size_t>(logged.record.fixture)].name, logged.record,
                      logged.restart, logged.begin, logged.where});
  }
  return cycles;
}

void RunMonitor(MonitorCommandOptions& opt, GlobalOptions& options) {
  std::vector<NamedFile> inputs;
  for (const std::string& log : opt.logs) inputs.push_back({"LOG", log});
  inputs.push_back({"--cell", opt.cell_path});
  if (!opt.baseline_in.empty()) inputs.push_back({"--baseline-in", opt.baseline_in});
  if (FilesClash(inputs, {{"--svg", opt.svg_path},
                          {"--csv", opt.csv_path},
                          {"--baseline-out", opt.baseline_out},
                          {"the report", "-"}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  opt.monitor.baseline = static_cast<std::size_t>(opt.baseline);
  opt.monitor.baseline_from = opt.baseline_from;
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
  std::optional<MonitorBaseline> stored;
  if (!opt.baseline_in.empty()) {
    Result<std::uint32_t> file = sources.Load(opt.baseline_in);
    if (!file) {
      PrintDiagnostics(diags, options);
      options.exit_code = ReportIoError(file.error());
      return;
    }
    stored = ReadBaseline(file.value(), cell, diags);
  }
  DropRepeatedRecords(log, diags);
  const std::vector<MonitoredCycle> cycles = Match(log, cell, diags);
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  const MonitorResult result = Monitor(cell, cycles, opt.monitor, stored ? &*stored : nullptr, diags);
  for (const FixtureMonitor& f : result.fixtures) {
    if (f.disagreements > 0) {
      const SourceRange where =
          cycles[f.records[static_cast<std::size_t>(f.first_disagreement_scan) - 1]].where;
      diags.Report(DiagKind::MonitorRecordDisagrees, where, f.disagreements, f.scans, f.name, cell.name,
                   f.worst_disagreement_mm > 0 ? fmt::format("{:.4f} mm", f.worst_disagreement_mm) : "its verdict");
    }
  }
  if (result.fixtures.empty() && !diags.has_errors()) {
    diags.Report(DiagKind::MonitorTooFewScans, log.begins.empty() ? SourceRange() : log.begins.front().where,
                 fmt::format("the logs hold no record of cell '{}''s fixtures ({}): nothing to judge", cell.name,
                             FixtureList(cell)));
  }
  options.exit_code = PrintDiagnostics(diags, options);
  if (options.exit_code != kExitOk) return;
  MonitorContext context{opt.logs, &cell, opt.monitor, static_cast<long>(log.cycles.size()), &cycles, &sources,
                         opt.baseline_in};
  // Every output staged, then all of them committed: a failure leaves none half-written.
  std::vector<StagedOutput> staged;
  auto stage = [&](const std::string& path, std::string_view contents) {
    if (path.empty()) return true;
    Result<StagedOutput> output = StagedOutput::Stage(path, contents);
    if (!output) {
      options.exit_code = ReportIoError(output.error());
      return false;
    }
    staged.push_back(std::move(output.value()));
    return true;
  };
  if (!stage(opt.svg_path, opt.svg_path.empty() ? "" : MonitorReportSvg(result, context)) ||
      !stage(opt.csv_path, opt.csv_path.empty() ? "" : MonitorReportCsv(result, context)) ||
      !stage(opt.baseline_out,
             opt.baseline_out.empty() ? "" : BaselineJsonText(BaselineOf(result, cell, opt.logs)))) {
    return;
  }
  for (StagedOutput& output : staged) {
    if (Status committed = output.Commit(); !committed) {
      options.exit_code = ReportIoError(committed.error());
      return;
    }
  }
  const std::string text = opt.json ? JsonText(MonitorReportJson(result, context)) : MonitorReportText(result, context);
  if (Status written = WriteFileAtomically("-", text); !written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (!opt.svg_path.empty()) SayDone(options, opt.svg_path, fmt::format("wrote the control charts {}", opt.svg_path));
  if (!opt.csv_path.empty()) SayDone(options, opt.csv_path, fmt::format("wrote every scan's values {}", opt.csv_path));
  if (!opt.baseline_out.empty()) {
    SayDone(options, opt.baseline_out, fmt::format("wrote the baseline {}", opt.baseline_out));
  }
  options.exit_code = result.in_control || opt.exit_zero ? kExitOk : kExitOutOfControl;
}

}  // namespace

void AddMonitorCommand(CLI::App& app, GlobalOptions& options) {
  static MonitorCommandOptions opt;
  CLI::App* monitor = app.add_subcommand(
      "monitor",
      "Read the cycle records a controller kept (logs of several shifts, oldest first) and report what they say: "
      "control charts of the board's pose, the marker distance, the sensor and the residuals, refusals, drifts in "
      "order of cause and what to do, process figures; exit 4 when the cell is out of control");
  monitor->add_option("LOG", opt.logs, "the logs of cycle records, oldest first (docs/monitor.md)")->required();
  monitor->add_option("--cell", opt.cell_path, "the cell file the records were made with (*.cell.toml)")->required();
  CLI::Option* baseline =
      AddNumberOption(*monitor, "--baseline", opt.baseline,
                      "the accepted scans of each fixture (from --baseline-from on) that set the charts' centre lines, "
                      "sigmas and refusal rates (Phase I)",
                      limits::kMonitorBaseline)
          ->capture_default_str();
  CLI::Option* from = AddNumberOption(*monitor, "--baseline-from", opt.baseline_from,
                                      "the scan of each fixture (1 for the first of the logs) the baseline starts at",
                                      limits::kMonitorBaselineFrom)
                          ->capture_default_str();
  monitor->add_option("--baseline-in", opt.baseline_in,
                      "judge against this stored baseline (written by --baseline-out) instead of a window of the logs")
      ->excludes(baseline)
      ->excludes(from);
  monitor->add_option("--baseline-out", opt.baseline_out,
                      "also write the baseline the charts judged against to this file (JSON), for --baseline-in");
  monitor->add_flag("--json", opt.json, "print the report as JSON (docs/monitor.md) instead of text");
  monitor->add_option("--svg", opt.svg_path, "also draw the control charts to this SVG file");
  monitor->add_option("--csv", opt.csv_path, "also write every scan's values to this CSV file (a spreadsheet, an MES)");
  monitor->add_flag("--exit-zero", opt.exit_zero,
                    "report only: exit 0 even when the cell is out of control (input errors still exit 1, I/O 3)");
  monitor->footer(
      "Exit codes: 0 in control; 4 out of control (a CUSUM or EWMA alarm on a chart, or refusals rising); 1 the "
      "input cannot be judged (errors in a log, the cell or the baseline; diagnostics printed); 2 usage; 3 I/O. "
      "A shift-start script: smtcal monitor board.log --cell cell.toml --baseline-in board.baseline -q; "
      "case $? in 0) ;; 4) stop-the-line ;; *) call-the-engineer ;; esac");
  monitor->callback([&options] { RunMonitor(opt, options); });
}

}  // namespace smtcal::tools
