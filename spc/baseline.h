// Phase I of a control chart (Montgomery, "Introduction to Statistical
// Quality Control", ch. 7): the reference a chart judges new values
// against, estimated from a window of values the user says were in
// control — robustly, because a window that holds a wild value or a drift
// makes a chart that sees nothing:
// - a value far from its neighbours (kBaselineOutlierSigmas robust sigmas
//   from the median of the values around it; the sigma from the median
//   moving range, which neither outliers nor a drift move much) is left out
//   of the estimate and named;
// - a window whose values drift (the least-squares slope beyond its
//   standard error times Student's t at kBaselineDriftAlpha: a window in
//   control is taken for a drifting one once in 1000 per chart) is no
//   reference: the drift is named
//   with the values to exclude — from where it starts to the window's end
//   (the cell began to drift inside the window), or from the window's start
//   to where it ends (a warm-up) — whichever fits better.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "spc/control_chart.h"

namespace smtcal {

inline constexpr double kBaselineOutlierSigmas = 10;
inline constexpr double kBaselineDriftAlpha = 1e-3;  // two-sided, per chart

struct BaselineDrift {
  // Values to exclude, [first, last] (indices into the window's values).
  std::size_t first = 0, last = 0;
  bool at_start = false;  // a warm-up: the window drifts until `last`, steady after it
  double slope = 0;       // per value (the unit of the values)
  double t = 0;           // the slope in standard errors
};

struct BaselineEstimate {
  ChartReference reference;            // from the values kept (n: how many)
  std::vector<std::size_t> outliers;   // indices into the window's values, left out
  std::optional<BaselineDrift> drift;  // the window drifts: no reference
};

// The window's values in order (at least 3). `resolution`: sigma's floor.
BaselineEstimate EstimateBaseline(const std::vector<double>& values, double resolution);

}  // namespace smtcal
