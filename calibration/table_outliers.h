// Nodes of an error table that disagree with their neighbours far beyond the
// measurement's own noise: a digit slipped, a sign lost, a bad measurement
// (docs/error-tables.md, "Outliers"). A robot's error field is smooth at the
// scale of a table's pitch, so each node is predicted from its neighbours
// alone (linear interpolation between the two neighbours along each grid
// direction, or linear extrapolation from the two next ones at an edge; the
// predictions of both directions averaged) and the difference is compared
// with
//   - the table's own scatter of such differences: 1.4826 x their median
//     absolute value over the axis table (robust: an outlier does not raise it),
//   - the node's standard error stddev / sqrt(n) when the table states it,
//     but at most kOutlierNoiseCapFactor times the axis's median standard
//     error: a node whose own measurements scatter far beyond its axis's
//     holds a bad measurement, and its noise must not excuse it.
// A node is an outlier when its difference exceeds kOutlierScatterFactor
// times the scatter, kOutlierNoiseFactor times its (capped) standard error
// and kOutlierFloorMm.
//
// A slipped node also spoils its neighbours' predictions (an edge node
// extrapolated from it by twice its own slip), so the search blames the
// node, never its neighbours: the node that disagrees most (its difference
// over the noise its prediction carries) is taken first, each node at most
// once, and every node taken so far is replaced by what its neighbours
// predict (all at once, so two adjacent slipped nodes do not keep each
// other's slips) before the next is sought. Then a node taken only because
// a slipped neighbour spoiled its prediction, and which agrees with its
// repaired neighbours, is given back. The prediction reported is the final
// one, from the repaired neighbours.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "calibration/error_table.h"
#include "calibration/likely_slip.h"

namespace smtcal {

struct TableOutlier {
  TableAxis axis = TableAxis::X;
  std::size_t i = 0, j = 0;  // the node
  double value_mm = 0;       // as written
  double predicted_mm = 0;   // from its (repaired) neighbours
  double scatter_mm = 0;     // the threshold's scale: the larger of the table's scatter and the node's noise
  // What the slip probably was, e.g. "a decimal point moved (-0.07711 would
  // fit)", "a lost or added minus sign (0.0412 would fit)", or, for a node
  // whose own measurements scatter far beyond its axis's, that one of them
  // is probably bad; empty when nothing simple fits.
  std::string likely_slip;
};

// Every outlier of both axis tables, x first, in node order (y, then x).
// Tables with fewer than 3 nodes along both directions have no neighbours
// to ask.
std::vector<TableOutlier> FindTableOutliers(const ErrorTable& table);

// The table with every outlier's value replaced by its prediction: what the
// later checks (fold, slope, warnings) look at, so a slip is reported once,
// as the outlier it is.
ErrorTable WithOutliersRepaired(const ErrorTable& table, const std::vector<TableOutlier>& outliers);

}  // namespace smtcal
