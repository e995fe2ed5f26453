// Reports of `smtcal monitor` (docs/monitor.md): the text summary, the JSON
// report and the SVG control charts of what a log of cycle records says
// (spc/cycle_monitor.h). Deterministic: the same logs give the same
// bytes.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/source.h"
#include "calibration/cell.h"
#include "spc/cycle_monitor.h"

namespace smtcal {

struct MonitorContext {
  std::vector<std::string> logs;  // as given
  const cell::Cell* cell = nullptr;
  MonitorOptions options;
  long records = 0;  // every record read
  const std::vector<MonitoredCycle>* cycles = nullptr;  // what the result's scans index
  const SourceManager* sources = nullptr;               // the logs' names and lines
  std::string baseline_in;                              // --baseline-in, when given
};

// The verdict first (in control, or each finding: what it means, how soon
// it reaches its limit, what to do), then per fixture its charts, the rules
// that fired, the refusals and the process figures.
std::string MonitorReportText(const MonitorResult& result, const MonitorContext& context);
nlohmann::ordered_json MonitorReportJson(const MonitorResult& result, const MonitorContext& context);
// The picture a line reads: the verdict and the findings first; per fixture
// the charts that alarmed first, each its values (centre line, 3 sigma, the
// baseline shaded, restarts marked), the statistic that decides (the
// CUSUMs and the EWMA against their limits) and the moving range, then the
// refusals' CUSUMs; against the scan number. Many scans are drawn as the
// range of the values per column of the plot, so the picture's size is
// bounded whatever the logs' length.
std::string MonitorReportSvg(const MonitorResult& result, const MonitorContext& context);
// Every scan, one row: its fixture, scan number, log and line, run, cycle,
// time, verdict and the values the charts took (docs/monitor.md, "--csv").
std::string MonitorReportCsv(const MonitorResult& result, const MonitorContext& context);

}  // namespace smtcal
