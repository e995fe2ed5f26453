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
//   - the node's standard error stddev / sqrt(n) when the table states it.
// A node is an outlier when its difference exceeds kOutlierScatterFactor
// times the scatter, kOutlierNoiseFactor times its standard error and
// kOutlierFloorMm. The worst such node is taken first and replaced by its
// prediction before the next is sought: an outlier also spoils its
// neighbours' predictions (an edge node extrapolated from it by as much as
// its own size), and those are then no longer reported.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "calibration/error_table.h"

namespace smtcal {

struct TableOutlier {
  TableAxis axis = TableAxis::X;
  std::size_t i = 0, j = 0;  // the node
  double value_mm = 0;       // as written
  double predicted_mm = 0;   // from its neighbours
  double scatter_mm = 0;     // the threshold's scale: the larger of the table's scatter and the node's noise
  // What the slip probably was, e.g. "a decimal point moved (-0.07711 would
  // fit)", "a lost sign (0.0412 would fit)"; empty when nothing simple fits.
  std::string likely_slip;
};

// Every outlier of both axis tables, x first, in node order. Tables with
// fewer than 3 nodes along both directions have no neighbours to ask.
std::vector<TableOutlier> FindTableOutliers(const ErrorTable& table);

}  // namespace smtcal
