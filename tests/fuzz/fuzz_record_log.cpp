// A controller's cycle-record log (format 2, `smtcal monitor`): the reader
// (runs, restarts, damage, repeated runs), then, when every run is the
// example cell's with its fixture and trip count (what `smtcal monitor`
// requires before it judges), the monitor with a short baseline and every
// report: text, JSON, SVG and CSV.
#include "backend/reports/monitor_report.h"
#include "base/json_text.h"
#include "calibration/cycle_record.h"
#include "calibration/fixture_geometry.h"
#include "frontend/record_log.h"
#include "spc/cycle_monitor.h"
#include "tests/fuzz/fuzz_cells.h"
#include "tests/fuzz/fuzz_target.h"

SMTCAL_FUZZ_TARGET(record_log) {
  using namespace smtcal;
  const cell::Cell& cell = fuzz::ExampleCell();
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("record.log", std::string(fuzz::AsText(data, size)));
  RecordLog log;
  if (ReadRecordLog(file, log, diags)) {
    DropRepeatedRecords(log, diags);
    bool all_ours = !log.cycles.empty();
    for (const LoggedBegin& begin : log.begins) {
      all_ours = all_ours && begin.begin.cell == RecordName(cell.name) && begin.begin.fixtures.size() == 1 &&
                 begin.begin.fixtures[0].name == RecordName(cell.fixtures[0].name) &&
                 begin.begin.fixtures[0].trips == ExpectedTrips(cell.fixtures[0]).size();
    }
    if (all_ours && !diags.has_errors()) {
      std::vector<MonitoredCycle> cycles;
      for (const LoggedCycle& logged : log.cycles) {
        cycles.push_back({cell.fixtures[0].name, logged.record, logged.restart, logged.begin, logged.where});
      }
      MonitorOptions options;
      options.baseline = 10;
      MonitorResult result = Monitor(cell, cycles, options, nullptr, diags);
      MonitorContext context;
      context.logs = {"record.log"};
      context.cell = &cell;
      context.options = options;
      context.records = static_cast<long>(log.cycles.size());
      context.cycles = &cycles;
      context.sources = &sources;
      MonitorReportText(result, context);
      JsonText(MonitorReportJson(result, context));
      MonitorReportSvg(result, context);
      MonitorReportCsv(result, context);
    }
  }
  diags.RenderText();
  return 0;
}
