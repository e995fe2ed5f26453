// The error-table family of CSV readers (docs/error-tables.md): an error
// table through validation, statistics, the plot and both solvers; raw
// measurements through averaging into a table; a point list through the
// forward map and the inverse of the example cell's placing table.
#include <cmath>

#include "backend/reports/table_plot.h"
#include "backend/reports/table_report.h"
#include "calibration/error_table_build.h"
#include "calibration/error_table_check.h"
#include "calibration/interpolation_error.h"
#include "calibration/inverse_calibration.h"
#include "frontend/table_csv.h"
#include "tests/fuzz/fuzz_solve.h"
#include "tests/fuzz/fuzz_target.h"

using namespace smtcal;

SMTCAL_FUZZ_TARGET(table_csv) {
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("table.csv", std::string(fuzz::AsText(data, size)));
  std::optional<ErrorTable> table = ReadErrorTable(file, diags);
  TableAnalysis analysis;
  if (table && ValidateErrorTable(*table, diags, TableWarnings::kReport, &analysis)) {
    TableStats stats = ComputeTableStats(*table);
    int bound = IterationBound(analysis.contraction, analysis.max_abs_error_mm);
    // The interpolation error, with check points (when the table has any)
    // and a declared roughness, and its grid advice.
    const InterpolationEstimate interpolation =
        EstimateInterpolationError(*table, DeclaredRoughness{0.25, 25}, 0.005);
    ReportCoarseGrid(interpolation, kDefaultTableToleranceMm, "the table", interpolation.Origin(), diags);
    FormatStatsText(*table, stats, analysis, bound, interpolation, kDefaultTableToleranceMm);
    FormatStatsJson(*table, stats, analysis, bound, interpolation, kDefaultTableToleranceMm);
    PlotTableSvg(*table, "table.csv");
    FormatTableCsv(*table, {"fuzz"});
    const Rect domain = TableDomain(*table);
    const fuzz::Solvers solvers(*table, analysis);
    fuzz::Solve(solvers, {(domain.x0 + domain.x1) / 2, (domain.y0 + domain.y1) / 2});
    fuzz::Solve(solvers, {domain.x0, domain.y1});
    fuzz::Solve(solvers, {domain.x1 + 1, domain.y0 - 1});
  }
  diags.RenderText();
  diags.RenderJson();
  return 0;
}
