// How an error table changed (`smtcal table diff A B`, docs/error-tables.md):
// the first thing a process engineer checks after re-measuring a region.
//
// Per axis, every node of either table's grid that lies in the other
// table's grid rectangle is compared: a node's own value against the other
// table's bilinear interpolation there (the same interpolation F uses), so
// tables on different grids compare on their common area, and tables on the
// same grid node by node. A change is B - A.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "calibration/cell.h"
#include "calibration/error_table.h"

namespace smtcal {

struct NodeChange {
  TableAxis axis = TableAxis::X;
  double x_mm = 0, y_mm = 0;
  double old_mm = 0, new_mm = 0;  // A's and B's value at the node (one of them interpolated, unless on both grids)
  double change_um = 0;           // (new - old) in µm
  bool on_old_grid = false, on_new_grid = false;
};

// Statistics of the changes of one axis over a set of nodes.
struct ChangeStats {
  std::size_t nodes = 0;
  double max_abs_um = 0;  // the largest |change|
  double mean_um = 0;     // signed: a shift of the whole table shows here
  double rms_um = 0;
  double min_um = 0, max_um = 0;  // the smallest and largest change, signed
  // Every node changed alike: the spread of the changes is below what a
  // change is printed to (kTableDiffUniformUm), so no node changed "most".
  bool uniform() const;
  std::size_t largest = 0;  // index into TableChanges::nodes; valid when nodes > 0
  std::size_t beyond = 0;   // nodes whose |change| is above the threshold
};

struct AxisComparison {
  bool same_grid = false;  // identical grid lines: a node-by-node comparison
  Rect common{};           // the common rectangle of the two grids
  bool overlap = false;    // the grids share an area
  std::size_t old_nodes_outside = 0, new_nodes_outside = 0;  // not compared: outside the other grid
  ChangeStats stats;
};

struct TableChanges {
  std::array<AxisComparison, 2> axes;
  std::vector<NodeChange> nodes;  // axis x first, then by y, then by x
  // A region of the cell: the nodes within its bounds, per axis.
  struct RegionChanges {
    std::string name;
    std::array<ChangeStats, 2> axes;
  };
  std::vector<RegionChanges> regions;
  double threshold_um = 0;
  std::size_t beyond() const { return axes[0].stats.beyond + axes[1].stats.beyond; }
};

// Both tables usable (HasUsableShape). `regions`: those of a cell whose
// bounds hold compared nodes get their own statistics (may be null).
TableChanges CompareTables(const ErrorTable& old_table, const ErrorTable& new_table, double threshold_um,
                           const std::vector<cell::Region>* regions);

// The spread below which an axis's change is uniform: half the 0.1 µm a
// change is printed to.
inline constexpr double kTableDiffUniformUm = 0.05;

// The nodes with the largest |change|, at most `count`, largest first (ties
// in node order), of the axes whose change is not uniform (a uniform change
// has no node that changed most); a node whose |change| is below
// kTableDiffUniformUm (printed as 0.0 µm) is never among them.
std::vector<std::size_t> LargestChanges(const TableChanges& changes, std::size_t count);

// The change as a table (B - A in mm) on one grid per axis: A's lines
// within the common rectangle, or B's where those are fewer than 2 x 2.
// nullopt when an axis has no common area of 2 x 2 nodes.
std::optional<ErrorTable> ChangeTable(const ErrorTable& old_table, const ErrorTable& new_table);

}  // namespace smtcal
