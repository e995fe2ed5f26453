// CSV files of the error tables (docs/error-tables.md): error tables, raw
// measurements, and the point lists of `smtcal table forward|inverse`.
//
// The CSV dialect: fields separated by ',', optionally quoted with '"' ("" is
// a quote inside a quoted field; a quoted field ends on its own line); LF or
// CRLF line ends; an optional UTF-8 byte order mark; blank lines and lines
// whose first non-blank character is '#' are skipped; spaces around fields are
// ignored. The first line names the columns, in any order (the point lists may
// leave it out: then the columns are x_mm,y_mm); a column smtcal does not know
// is an error naming it. Numbers are read locale-independently ('.' decimal
// point, optional exponent); nan, inf and lengths beyond kMaxLengthMm
// (calibration/tolerances.h) are rejected.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/error_table.h"
#include "calibration/error_table_build.h"
#include "calibration/measurement_plan.h"

namespace smtcal {

struct CsvField {
  std::string text;   // unquoted, spaces around it removed
  SourceRange range;  // where it is in the file (an empty field: its position)
};

struct CsvRecord {
  std::uint32_t line = 0;
  std::vector<CsvField> fields;
  SourceLoc end;  // just after the last character of the line
};

// Splits the file registered as `file` in diags.sources() into records,
// skipping blank and comment lines. A line with a quoting error is reported
// and left out.
std::vector<CsvRecord> SplitCsv(std::uint32_t file, Diagnostics& diags);

// An error table: axis,x_mm,y_mm,error_mm[,stddev_mm][,n][,kind], one row
// per node and axis (and per check point: kind = check), rows in any order. Reports everything wrong with the rows and the
// grid (AssembleErrorTable); nullopt when anything was an error. The table is
// not validated yet (ValidateErrorTable).
std::optional<ErrorTable> ReadErrorTable(std::uint32_t file, Diagnostics& diags);

// Raw measurements: axis,x_mm,y_mm,set,repetition,error_mm[,kind].
std::optional<std::vector<RawMeasurement>> ReadRawMeasurements(std::uint32_t file, Diagnostics& diags);

// A point list: x_mm,y_mm (the header may be left out).
struct PointRow {
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  SourceRange range;  // from the first to the last field of the row
};
std::optional<std::vector<PointRow>> ReadPoints(std::uint32_t file, Diagnostics& diags);

// A measurement plan (`smtcal measure plan`, docs/measure.md):
// visit,region,axes,station,kind,node,x_mm,y_mm,set,repetitions, one row
// per visit in the order the visits are made. The rows as written; checking
// them against the cell is measure::PlanFromRows's.
struct PlanRow {
  int visit = 0;
  std::string region;
  measure::MeasuredAxes axes = measure::MeasuredAxes::kXY;
  int station = 1;
  measure::VisitKind kind = measure::VisitKind::kNode;
  int node = 0;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  int set = 1;
  int repetitions = 1;
  int direction = 1;  // the optional approach column: +1 (the final approach), -1 (against it)
  std::uint32_t line = 0;
  SourceRange visit_field, region_field, node_field;
};
std::optional<std::vector<PlanRow>> ReadMeasurementPlan(std::uint32_t file, Diagnostics& diags);

// An external system's readings: node,set,repetition,x_mm,y_mm, the
// position it measured (robot base frame) for the node, set and repetition
// the measuring program showed it (docs/measure.md).
struct ExternalReading {
  long long node = 0;
  long long set = 0;
  long long repetition = 0;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  std::uint32_t line = 0;
  SourceRange range;  // its node field
};
std::optional<std::vector<ExternalReading>> ReadExternalReadings(std::uint32_t file, Diagnostics& diags);

}  // namespace smtcal
