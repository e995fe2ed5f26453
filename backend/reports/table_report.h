// Text outputs of the error-table commands: the table CSV that `table build`
// writes, the statistics of `table stats` (text and JSON), and the result
// rows of `table forward|inverse`. All formatting is fixed, so the same input
// gives byte-identical output.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "calibration/error_table.h"
#include <nlohmann/json.hpp>

#include "calibration/error_table_check.h"
#include "calibration/interpolation_error.h"
#include "calibration/inverse_calibration.h"

namespace smtcal {

// An error table as CSV (docs/error-tables.md): `comment` lines first (each
// prefixed with "# "), then the header
// axis,x_mm,y_mm,error_mm[,stddev_mm][,n][,kind] (the optional columns when
// any node or check point has them; kind when there are check points) and one
// row per node: the x table, then the y table, each row by row (y, then x,
// increasing); then the check points, x before y, each by y, then x.
// Coordinates as FormatMm, values with 6 decimals (nanometres).
std::string FormatTableCsv(const ErrorTable& table, const std::vector<std::string>& comment);

// The comment `table build` writes above a table built from `raw_name` (also
// used by the example generator, so both give the same bytes).
std::vector<std::string> BuiltTableComment(std::string_view raw_name);

// `table stats`: the paper's figures per axis, the origin shift by the means,
// the inverse calibration's properties and the interpolation error between
// the nodes (as a share of `tolerance_mm`).
std::string FormatStatsText(const ErrorTable& table, const TableStats& stats, const TableAnalysis& analysis,
                            int iteration_bound, const InterpolationEstimate& interpolation, double tolerance_mm);
std::string FormatStatsJson(const ErrorTable& table, const TableStats& stats, const TableAnalysis& analysis,
                            int iteration_bound, const InterpolationEstimate& interpolation, double tolerance_mm);

// The interpolation estimate (calibration/interpolation_error.h) in one line:
// "0.0078 mm (Δx 0.0055, Δy 0.0055 mm), 7.8 % of ±0.1 mm, from ...", with
// the check points (and the standard deviation of their noise, which the
// budget takes as a random part) and the grid advice when there is any.
std::string InterpolationText(const InterpolationEstimate& estimate, double tolerance_mm);
// The same as JSON: {"mm", "x_mm", "y_mm", "noise_mm", "kind", "lower_bound", "share",
// "tolerance_mm", "coarse", "advice_pitch_mm", "check_points_would_settle",
// "axes": {"x": {...}, "y": {...}}}, lengths rounded to a nanometre.
nlohmann::ordered_json InterpolationJson(const InterpolationEstimate& estimate, double tolerance_mm);

// `table forward|inverse` output: the header x_mm,y_mm,residual_mm,iterations
// and one row per solution (mm with 6 decimals, the residual as %.3e).
std::string FormatSolutionsCsv(const std::vector<Solution>& solutions);

}  // namespace smtcal
