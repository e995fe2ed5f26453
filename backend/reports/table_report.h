// Text outputs of the error-table commands: the table CSV that `table build`
// writes, the statistics of `table stats` (text and JSON), and the result
// rows of `table forward|inverse`. All formatting is fixed, so the same input
// gives byte-identical output.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "calibration/error_table.h"
#include "calibration/error_table_check.h"
#include "calibration/inverse_calibration.h"

namespace smtcal {

// An error table as CSV (docs/error-tables.md): `comment` lines first (each
// prefixed with "# "), then the header axis,x_mm,y_mm,error_mm[,stddev_mm][,n]
// (the optional columns when any node has them) and one row per node: the x
// table, then the y table, each row by row (y, then x, increasing).
// Coordinates as FormatMm, values with 6 decimals (nanometres).
std::string FormatTableCsv(const ErrorTable& table, const std::vector<std::string>& comment);

// The comment `table build` writes above a table built from `raw_name` (also
// used by the example generator, so both give the same bytes).
std::vector<std::string> BuiltTableComment(std::string_view raw_name);

// `table stats`: the paper's figures per axis, the origin shift by the means,
// and the inverse calibration's properties.
std::string FormatStatsText(const ErrorTable& table, const TableStats& stats, const TableAnalysis& analysis,
                            int iteration_bound);
std::string FormatStatsJson(const ErrorTable& table, const TableStats& stats, const TableAnalysis& analysis,
                            int iteration_bound);

// `table forward|inverse` output: the header x_mm,y_mm,residual_mm,iterations
// and one row per solution (mm with 6 decimals, the residual as %.3e).
std::string FormatSolutionsCsv(const std::vector<Solution>& solutions);

}  // namespace smtcal
