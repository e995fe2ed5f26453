// Error tables: the robot's measured position errors in a calibrated region,
// one table per calibrated axis, each on its own rectilinear grid (the paper
// measured the x errors and the y errors at slightly different points), and
// the direct calibration F(n) = n + Delta(n) by bilinear interpolation of each
// table on its own grid. docs/error-tables.md describes the files and the math.
//
// Flow: nodes (from frontend/table_csv.h or calibration/error_table_build.h)
//   -> AssembleErrorTable (grid structure: lines, missing/duplicate nodes)
//   -> ValidateErrorTable (calibration/error_table_check.h: fold, slopes, warnings)
//   -> CalibrationMap (fast evaluation) -> calibration/inverse_calibration.h.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"

namespace smtcal {

enum class TableAxis : int { X = 0, Y = 1 };
inline constexpr std::array<TableAxis, 2> kTableAxes = {TableAxis::X, TableAxis::Y};
std::string_view AxisName(TableAxis axis);  // "x" or "y"

// A length for messages and written tables: 3 decimals when that reads back
// exactly (150.004), else 6 when that does, else the shortest round-trip form.
std::string FormatMm(double mm);
// A computed position for messages: rounded to 1 nm first, so the noise of
// arithmetic (138 + 234.21 = 372.21000000000004) does not show.
std::string FormatComputedMm(double mm);

// What a row of a table or raw measurement file is (its optional `kind`
// column): a reading at a grid node (the default), or a check point, a
// reading off the grid nodes (e.g. at a cell centre) that the table keeps as
// evidence of how well the interpolation between the nodes holds
// (calibration/interpolation_error.h).
enum class ReadingKind { kNode, kCheck };
std::string_view ReadingKindName(ReadingKind kind);  // "node" or "check"

// One node (or check point) as read from a file or averaged from raw
// measurements, with where it came from so every diagnostic can point at its
// row.
struct TableNode {
  ReadingKind kind = ReadingKind::kNode;
  TableAxis axis = TableAxis::X;
  double x_mm = 0;
  double y_mm = 0;
  double error_mm = 0;
  std::optional<double> stddev_mm;  // scatter of the measurements averaged
  int count = 0;                    // measurements averaged; 0 = not given
  // The standard uncertainty of the value from everything but its own
  // scatter (the artefact, the device's geometry, the registration of the
  // artefact's set-ups: measure read's budget, docs/measure.md).
  std::optional<double> u_mm;
  // The reversal value (ISO 230-2): the error approached against the final
  // approach less the error approached with it (a bidirectional plan).
  std::optional<double> reversal_mm;
  SourceRange x_field;              // the fields in the file (unknown when built in code)
  SourceRange y_field;
  SourceRange error_field;
};

// One axis's table: a value per node of a rectilinear grid.
struct AxisTable {
  std::vector<double> xs;        // grid lines, strictly increasing (mm)
  std::vector<double> ys;        // grid lines, strictly increasing (mm)
  std::vector<double> error_mm;  // node (i, j) = (xs[i], ys[j]) at Index(i, j)
  std::vector<std::optional<double>> stddev_mm;  // empty, or one per node
  std::vector<int> count;                        // empty, or one per node (0 = not given)
  std::vector<std::optional<double>> u_mm;         // empty, or one per node (TableNode::u_mm)
  std::vector<std::optional<double>> reversal_mm;  // empty, or one per node (TableNode::reversal_mm)
  std::vector<SourceRange> origin;               // empty, or one per node: its value's field
  // Check points of this axis (kind = check): readings off the grid nodes,
  // each inside the grid's rectangle and away from the nodes
  // (kMinCheckPointShare), sorted by y, then x.
  std::vector<TableNode> checks;

  std::size_t nx() const { return xs.size(); }
  std::size_t ny() const { return ys.size(); }
  std::size_t Index(std::size_t i, std::size_t j) const { return j * xs.size() + i; }
  double At(std::size_t i, std::size_t j) const { return error_mm[Index(i, j)]; }
  // Where node (i, j) was written; an unknown range for tables built in code.
  SourceRange Origin(std::size_t i, std::size_t j) const;
  // The standard error of a node's mean, stddev / sqrt(n), when the table
  // states both; nullopt when it says nothing about the node's noise.
  std::optional<double> StandardErrorMm(std::size_t node) const;
};

struct ErrorTable {
  std::string name;               // the file it came from, for reports
  std::array<AxisTable, 2> axes;  // [X] holds Delta-x, [Y] holds Delta-y

  const AxisTable& operator[](TableAxis axis) const { return axes[static_cast<int>(axis)]; }
  AxisTable& operator[](TableAxis axis) { return axes[static_cast<int>(axis)]; }
};

// Builds the grids from nodes given in any order. Reports (naming the node
// and pointing at its row): an axis without rows, a coordinate off the grid
// (a line used by a single row: a typo), grid lines closer than
// kMinGridLineSpacingMm, duplicate nodes, missing nodes, a grid smaller than
// 2 x 2, grids that do not overlap; and of the check points (kind = check):
// one outside its axis's grid rectangle, one on or too near a grid node
// (kMinCheckPointShare), two at the same position. nullopt when anything was
// reported.
// `file` locates the diagnostics that concern the whole file.
std::optional<ErrorTable> AssembleErrorTable(std::string name, const std::vector<TableNode>& nodes,
                                             SourceLoc file, Diagnostics& diags);

// An axis-aligned rectangle, bounds included.
struct Rect {
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
};

// True when the table can be evaluated: both axes have at least 2 x 2 nodes,
// lines increasing by at least kMinGridLineSpacingMm, lines and values within
// +-kMaxLengthMm, consistent sizes, and the two
// grids' rectangles overlap in a rectangle of positive area. Tables assembled
// from files always can (the readers refuse lengths beyond kMaxLengthMm).
bool HasUsableShape(const ErrorTable& table);

// Where F is defined ("inside the table"): the intersection of both grids'
// rectangles. Requires HasUsableShape.
Rect TableDomain(const ErrorTable& table);

// Fast evaluation of Delta for the solvers: O(1) cell lookup on uniform grids
// (a guess from the mean pitch, corrected by a step), O(log n) on others, no
// allocation.
// Outside the domain Delta is extended by its edge values (Delta evaluated at
// the point clamped into the domain); the solvers decide by policy whether a
// point outside may use that (calibration/inverse_calibration.h).
class CalibrationMap {
 public:
  // The table must have HasUsableShape (checked).
  explicit CalibrationMap(const ErrorTable& table);

  const Rect& domain() const { return domain_; }
  // Inside the domain, up to kTableEdgeTolMm.
  bool Inside(const Eigen::Vector2d& n) const;
  Eigen::Vector2d ClampToDomain(const Eigen::Vector2d& n) const;

  // Delta at n clamped into the domain.
  Eigen::Vector2d Delta(const Eigen::Vector2d& n) const;
  // Delta and its Jacobian d(Delta)/dn at n, for the clamped extension: the
  // derivative along a clamped coordinate is 0. On a grid line the derivative
  // of the cell above / to the right is used.
  void DeltaAndJacobian(const Eigen::Vector2d& n, Eigen::Vector2d& delta,
                        Eigen::Matrix2d& jacobian) const;
  // One axis table at (x, y) clamped into that axis's own grid rectangle
  // (not the domain): the paper's solver works on each grid's own rows.
  double AxisDelta(TableAxis axis, double x, double y) const;

  // Grid lines of one axis table, for the paper's solver and the plot.
  const std::vector<double>& xs(TableAxis axis) const { return axes_[static_cast<int>(axis)].x.lines; }
  const std::vector<double>& ys(TableAxis axis) const { return axes_[static_cast<int>(axis)].y.lines; }
  double Node(TableAxis axis, std::size_t i, std::size_t j) const;

 private:
  struct Lines {
    std::vector<double> lines;
    double origin = 0;
    double cells_per_mm = 0;  // (lines - 1) / span: the uniform-grid guess
    int last_cell = 0;
    // The cell i with lines[i] <= v < lines[i+1] (the last cell includes its
    // end). v must lie within the lines.
    int Cell(double v) const;
  };
  struct Axis {
    Lines x, y;
    std::vector<double> values;  // row-major, as AxisTable::error_mm
  };
  // Value and gradient of one axis table at (x, y) inside its rectangle.
  static double Evaluate(const Axis& axis, double x, double y, double* ddx, double* ddy);

  std::array<Axis, 2> axes_;
  Rect domain_;
};

// The paper's statistics of one axis table (all in mm, over the nodes).
struct AxisStats {
  std::size_t nx = 0, ny = 0;
  double min_mm = 0, max_mm = 0, mean_mm = 0;
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // where min and max are
  // max |Delta - mean|: the largest error left after the task origin is
  // shifted by the mean (see docs/error-tables.md on the paper's figures).
  double abs_max_after_shift_mm = 0;
  std::size_t stddev_nodes = 0;  // nodes with a stddev given
  double stddev_mean_mm = 0, stddev_max_mm = 0;
  int count_min = 0, count_max = 0;  // measurements per node (0 = not given)
};

struct TableStats {
  std::array<AxisStats, 2> axes;
  // The origin shift by the means: (mean Delta-x, mean Delta-y).
  double shift_x_mm = 0, shift_y_mm = 0;
};

// Requires HasUsableShape.
TableStats ComputeTableStats(const ErrorTable& table);

}  // namespace smtcal
