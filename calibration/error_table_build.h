// Building an error table from raw measurements (`smtcal table build`): the
// paper averaged two sets of ten measurements per node and axis. Every
// node's readings are screened first (a slipped reading or set is an error
// naming its lines); every node's mean is stored with the stddev and the
// count of its measurements; nodes whose scatter is far above the rest of
// their axis, and nodes whose sets disagree, are reported instead of being
// averaged silently.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "calibration/error_table.h"

namespace smtcal {

// One row of a raw measurement file: axis,x_mm,y_mm,set,repetition,error_mm
// and the optional kind (node, the default, or check: a reading off the grid
// nodes, averaged per position like a node and kept in the table as a check
// point).
struct RawMeasurement {
  ReadingKind kind = ReadingKind::kNode;
  TableAxis axis = TableAxis::X;
  double x_mm = 0;
  double y_mm = 0;
  long long set = 0;
  long long repetition = 0;
  double error_mm = 0;
  // The optional u_mm column: the reading's standard uncertainty from
  // everything but the scatter (measure read's budget; TableNode::u_mm).
  std::optional<double> u_mm;
  // The optional approach column: '-' for a reading approached against the
  // final approach (a bidirectional plan: its difference is the reversal).
  bool reverse = false;
  SourceRange x_field;  // for "node ... is here"
  SourceRange y_field;
  SourceRange repetition_field;
  SourceRange error_field;
};

// The statistics of one node's (or check point's) measurements.
struct NodeSummary {
  ReadingKind kind = ReadingKind::kNode;
  TableAxis axis = TableAxis::X;
  double x_mm = 0, y_mm = 0;
  std::vector<std::size_t> rows;  // indices into the measurements, in file order
  double mean_mm = 0;
  std::optional<double> stddev_mm;         // sample stddev of all measurements (n >= 2)
  std::optional<double> pooled_stddev_mm;  // pooled within-set stddev (repetition scatter)
  double set_mean_spread_mm = 0;           // largest minus smallest set mean (sets of 2 or more)
  // sqrt(1/n_low + 1/n_high): the spread's standard error per unit of
  // repetition scatter (given when there are two such sets and a pooled stddev).
  std::optional<double> set_spread_weight;
  std::optional<double> u_mm;         // the largest of its readings'
  std::optional<double> reversal_mm;  // mean of the reversed readings less the mean of the others
};

// Groups measurements by node (check points by position) and summarizes each
// (sorted by kind, axis, x, y: the nodes first).
// Reports a repetition given twice.
std::vector<NodeSummary> SummarizeNodes(const std::vector<RawMeasurement>& measurements,
                                        Diagnostics& diags);

struct BuildOptions {
  // Leave readings (and whole sets) far from their node's others out of the
  // means, each reported as a warning, instead of stopping at them.
  bool drop_outlier_readings = false;
};

// The whole build: summaries; every node's readings screened
// (calibration/reading_screen.h: a reading far from its node's others, a set
// slipped by a decimal point or a unit, each an error naming its file lines,
// or a warning when `options` leaves them out); warnings for noisy nodes and
// set shifts among the readings kept; and the table assembled from the means
// of the readings kept (AssembleErrorTable's checks). With screening errors
// the table is still returned (averaged without the readings in question)
// so that its validation reports only other problems; it must not be
// written. Validation (ValidateErrorTable) is the caller's next step.
// nullopt on other errors (two sets of a node that disagree with nothing to
// tell which slipped among them).
std::optional<ErrorTable> BuildErrorTable(std::string name, const std::vector<RawMeasurement>& measurements,
                                          SourceLoc file, Diagnostics& diags, const BuildOptions& options = {});

}  // namespace smtcal
