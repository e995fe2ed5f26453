// Reports of `smtcal monitor` (docs/monitor.md): the text summary, the JSON
// report and the SVG control charts of what a log of cycle records says
// (spc/cycle_monitor.h). Deterministic: the same logs give the same
// bytes.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calibration/cell.h"
#include "spc/cycle_monitor.h"

namespace smtcal {

struct MonitorContext {
  std::vector<std::string> logs;  // as given
  const cell::Cell* cell = nullptr;
  MonitorOptions options;
  long records = 0;  // every record read
};

// The verdict first (in control, or each finding: what it means, how soon
// it reaches its limit, what to do), then per fixture its charts, the rules
// that fired, the refusals and the process figures.
std::string MonitorReportText(const MonitorResult& result, const MonitorContext& context);
nlohmann::ordered_json MonitorReportJson(const MonitorResult& result, const MonitorContext& context);
// Per fixture, one control chart per quantity (values, centre line, 3 sigma
// limits, the baseline shaded, alarms marked) and the refusals per check.
std::string MonitorReportSvg(const MonitorResult& result, const MonitorContext& context);

}  // namespace smtcal
