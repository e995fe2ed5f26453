// Outputs of `smtcal table diff A B` (docs/error-tables.md, "Comparing two
// tables"): the review text, the JSON document and the picture of the
// change. Deterministic: the same tables give the same bytes.
#pragma once

#include <string>

#include "calibration/table_diff.h"

namespace smtcal {

struct TableDiffNames {
  std::string old_table, new_table;  // as given
  std::string cell;                  // the cell file, when regions were given
};

// Per axis how the nodes compare and their largest, mean and rms change,
// the nodes that changed most, each region's figures, and the gate's verdict.
std::string FormatTableDiffText(const TableChanges& changes, const TableDiffNames& names);
// {"schema": "smtcal-table-diff/1", ...}: the same figures.
std::string FormatTableDiffJson(const TableChanges& changes, const TableDiffNames& names);
// Both axes' change (new - old) as colour maps with a legend in µm and the
// change vectors as arrows; "" when the tables share no area of 2 x 2 nodes.
std::string PlotTableDiffSvg(const ErrorTable& old_table, const ErrorTable& new_table, const TableDiffNames& names);

// The gate: no node changed by more than the threshold, and both axes had
// an area to compare.
bool TableDiffPasses(const TableChanges& changes);

// How many nodes the text and JSON list as the ones that changed most.
inline constexpr std::size_t kTableDiffLargest = 10;

}  // namespace smtcal
