// The files of `smtcal measure` (docs/measure.md): the plan as CSV with its
// summary in comments, the summary alone for the terminal, and the raw
// measurements `measure read` writes for `smtcal table build`.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "calibration/cell.h"
#include "calibration/error_table_build.h"
#include "calibration/measurement_plan.h"

namespace smtcal {

// "2 h 05 min", "12 min 30 s", "45 s".
std::string FormatDuration(double seconds);

// The plan's summary, one line per item (no comment marks): the device, the
// approach, per region its grid, pitch and why, nodes, check points, sets
// and repetitions, time; the notes; the total.
std::vector<std::string> PlanSummary(const measure::Plan& plan, std::string_view cell_path);

// The plan file: the summary as '#' comments, then
// visit,region,axes,station,kind,node,x_mm,y_mm,set,repetitions.
std::string FormatPlanCsv(const measure::Plan& plan, std::string_view cell_path);

// A raw measurement file (docs/error-tables.md) with `comment` lines first
// (each written after "# "): axis,x_mm,y_mm,set,repetition,error_mm, the
// errors with 6 decimals (nanometres), in the order given; with a `kind`
// column (node or check, one per row in `checks`: true for a check point)
// when any row is a check point.
std::string FormatRawCsv(const std::vector<RawMeasurement>& rows, const std::vector<bool>& checks,
                         const std::vector<std::string>& comment);

}  // namespace smtcal
