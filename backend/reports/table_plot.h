// `smtcal table plot`: the error field as a standalone SVG, like the paper's
// Figure 5 but read at a glance. Two panels, Delta-x and Delta-y, each over
// its own grid: a diverging colour map centred on 0 (blue negative, red
// positive) with a legend bar in µm, the grid nodes as dots, and the error
// vectors (Delta-x, Delta-y) at the nodes as arrows, exaggerated by a stated
// factor with a scale bar. Axes in mm. Deterministic: the same table gives the
// same bytes.
#pragma once

#include <string>
#include <string_view>

#include "calibration/error_table.h"

namespace smtcal {

// `title` is printed at the top (usually the table's file name). Requires
// HasUsableShape.
std::string PlotTableSvg(const ErrorTable& table, std::string_view title);

// What the picture says of what it shows, for plots of other fields on a
// table's grid (`table diff` draws the change of a table with it).
struct TablePlotWords {
  std::string heading;     // the bold first line
  std::string field;       // what the colour is: "the error of the axis"
  std::string arrows;      // what the arrows are: "the error vector (Δx, Δy)"
  std::string panel;       // each panel's title before its node count, {0} for the axis name: "Δ{0}: the {0} errors"
  bool state_arrow_fill = false;  // also say how long the longest arrow is drawn
  bool own_component = false;     // each panel's arrows: its own axis's component only (Δx along x, Δy along y)
};
std::string PlotTableSvg(const ErrorTable& table, const TablePlotWords& words);

}  // namespace smtcal
