// Validation of an error table beyond its grid structure: does the direct
// calibration F(n) = n + Delta(n) stay safely invertible, and does the table
// meet the paper's condition for linear interpolation?
//
// The analysis is exact, not sampled. Both axis tables are bilinear on their
// own cells, so on each piece of the union of both grids' lines (clipped to
// the domain) each component is one bilinear function. For a bilinear
// Delta = a + b u + c v + d u v, d(Delta)/dx = b + d v depends on y only and
// d(Delta)/dy = c + d u on x only. The first column of J = I + grad(Delta)
// therefore depends on y only and the second on x only, each affinely, with
// the same coefficient vector (d_x, d_y): det J = col1(y) x col2(x) has the
// xy coefficient (d_x, d_y) x (d_x, d_y) = 0, so det J is affine on the piece
// and its minimum is at a corner. Likewise |grad(Delta)|_inf per row is
// |f(y)| + |g(x)| with f, g affine, maximal at a corner. Evaluating the 4
// corners of every piece gives the exact minimum determinant and the exact
// contraction factor L = max |grad(Delta)|_inf.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/error_table.h"
#include "calibration/table_outliers.h"

namespace smtcal {

// One piece of the union grid.
struct PieceBound {
  Rect piece;
  double min_det = 1;            // min of det(I + grad Delta) over the piece
  Eigen::Vector2d min_det_at;    // the corner where it is reached
  Eigen::Matrix2d slopes_at_min_det;  // grad Delta there (row = axis)
  double max_row_slope = 0;      // max over the piece of |grad Delta|_inf
  int steepest_axis = 0;         // the row (0 = x, 1 = y) that reaches it
  Eigen::Matrix2d slopes_at_max;  // grad Delta at the corner reaching it
  std::array<std::size_t, 2> cell_i{}, cell_j{};  // the cell of each axis table holding it
};

struct TableAnalysis {
  double contraction = 0;       // L = max |grad Delta|_inf over the domain
  double max_abs_error_mm = 0;  // D = max |node value| over both axes
  double min_jacobian_det = 1;  // min det(I + grad Delta) over the domain
  std::vector<PieceBound> pieces;
};

// Requires HasUsableShape.
TableAnalysis AnalyzeTable(const ErrorTable& table);

enum class TableWarnings { kReport, kSkip };

// What ValidateErrorTable warns about, found without reporting it: per axis,
// the pairs of neighbouring nodes between which the error changes sign (both
// clearly off zero: kSignChangeMinMm and three standard errors; the first
// pair), and the nodes whose error exceeds kMaxErrorPitchFraction of the
// pitch around them (the worst).
struct SignChangeFinding {
  TableAxis axis = TableAxis::X;
  std::size_t pairs = 0;
  std::size_t i = 0, j = 0, i2 = 0, j2 = 0;  // the first pair
};
struct OverHalfPitchFinding {
  TableAxis axis = TableAxis::X;
  std::size_t count = 0;
  std::size_t i = 0, j = 0;  // the worst node
  double pitch_mm = 0;       // the smallest pitch around it
};
struct TableWarningFindings {
  std::vector<SignChangeFinding> sign_changes;      // one per axis that has any
  std::vector<OverHalfPitchFinding> over_half_pitch;  // likewise
};
// Nodes in `outliers` (FindTableOutliers) are left out of both.
TableWarningFindings FindTableWarnings(const ErrorTable& table, const std::vector<TableOutlier>& outliers = {});
// The same in one line per finding, for the summary the deciding commands
// (verify, compile, cell check) print once per table: "Δx changes sign
// between 5 pairs of neighbouring nodes (first at (150.000, 60.000))".
std::vector<std::string> SummarizeTableWarnings(const ErrorTable& table);

// Errors: the map folds or nearly folds (det < kMinJacobianDet) or the error
// is too steep for the inverse solver (L > kMaxErrorSlope); each names the
// worst cell and its slopes; a node disagrees with its neighbours far beyond
// the table's noise (calibration/table_outliers.h), named with its likely
// slip. Warnings (kReport): the error changes sign between neighbouring nodes
// that are both clearly off zero (kSignChangeMinMm); an error exceeds half
// the grid pitch.
// Returns false when an error was reported. Requires HasUsableShape.
bool ValidateErrorTable(const ErrorTable& table, Diagnostics& diags, TableWarnings warnings,
                        TableAnalysis* analysis = nullptr);

}  // namespace smtcal
