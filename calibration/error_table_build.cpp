// Averaging raw measurements into an error table. Assumes measurements with
// finite values (the CSV reader's job); guarantees one node per (axis, x, y)
// with the mean of its measurements, their stddev and count, and a warning for
// every node whose scatter or set-to-set difference is far from its axis's
// norm (the thresholds are in calibration/tolerances.h).
#include "calibration/error_table_build.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <tuple>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/reading_screen.h"
#include "calibration/sample_statistics.h"
#include "calibration/tolerances.h"

namespace smtcal {
namespace {

constexpr double kUmPerMm = 1000.0;

// "45-54, 166-175": the file lines of a node's measurements.
std::string LineRanges(const std::vector<RawMeasurement>& measurements, const std::vector<std::size_t>& rows) {
  std::vector<std::uint32_t> lines;
  for (std::size_t k : rows) lines.push_back(measurements[k].error_field.begin.line);
  std::sort(lines.begin(), lines.end());
  std::string text;
  for (std::size_t a = 0; a < lines.size();) {
    std::size_t b = a;
    while (b + 1 < lines.size() && lines[b + 1] == lines[b] + 1) ++b;
    if (!text.empty()) text += ", ";
    text += b == a ? fmt::format("{}", lines[a]) : fmt::format("{}-{}", lines[a], lines[b]);
    a = b + 1;
  }
  return text;
}

std::string Um(double mm) { return fmt::format("{:.1f}", mm * kUmPerMm); }

// How far above the axis's pooled scatter a node's sample stddev of `dof`
// degrees of freedom may lie by chance at kNoisyNodeMadFactor sigma: the
// square root of the chi-square quantile over its degrees of freedom
// (Wilson-Hilferty's approximation, a little above the exact quantile:
// 5.5 for one degree of freedom where the exact is 5.1, 1.9 for 19).
double ChiSquareScatterFactor(double dof) {
  const double c = 1 - 2 / (9 * dof) + kNoisyNodeMadFactor * std::sqrt(2 / (9 * dof));
  return std::sqrt(c * c * c);
}

void WarnNoisyNodes(const std::vector<RawMeasurement>& measurements, const std::vector<NodeSummary>& nodes,
                    Diagnostics& diags) {
  for (TableAxis axis : kTableAxes) {
    std::vector<double> spreads;
    for (const NodeSummary& node : nodes) {
      if (node.axis == axis && node.pooled_stddev_mm) spreads.push_back(*node.pooled_stddev_mm);
    }
    if (spreads.size() < 3) continue;  // no norm to compare with
    const double median = Median(spreads);
    std::vector<double> deviations;
    for (double s : spreads) deviations.push_back(std::abs(s - median));
    const double mad = Median(deviations);
    const double robust_limit = median + std::max(kNoisyNodeMadFactor * kMadToSigma * mad, kNoisyNodeFloorMm);
    // The median says little when a node has few readings: readings in a
    // device's steps (a probe latching a servo period's travel) with two
    // repetitions give most nodes no scatter at all and the rest one step.
    // A node is also held to the chi-square bound of its own readings
    // against the other nodes' pooled scatter, so one step apart is not
    // "noisy".
    double sum_squares = 0, sum_dof = 0;
    for (const NodeSummary& node : nodes) {
      if (node.axis != axis || !node.pooled_stddev_mm || node.rows.size() < 2) continue;
      const double dof = static_cast<double>(node.rows.size() - 1);
      sum_squares += dof * *node.pooled_stddev_mm * *node.pooled_stddev_mm;
      sum_dof += dof;
    }
    for (const NodeSummary& node : nodes) {
      if (node.axis != axis || !node.pooled_stddev_mm || node.rows.size() < 2) continue;
      // The pooled scatter of the other nodes: a noisy node must not widen
      // its own yardstick.
      const double dof = static_cast<double>(node.rows.size() - 1);
      const double others_dof = sum_dof - dof;
      const double others = others_dof > 0 ? std::sqrt(std::max(0.0, sum_squares - dof * *node.pooled_stddev_mm *
                                                                                    *node.pooled_stddev_mm) /
                                                       others_dof)
                                           : 0.0;
      const double limit = std::max(robust_limit, others * ChiSquareScatterFactor(dof));
      if (*node.pooled_stddev_mm <= limit) continue;
      const RawMeasurement& first = measurements[node.rows.front()];
      Diagnostic* diag = diags.Report(DiagKind::RawNoisyNode, first.error_field, FormatMm(node.x_mm),
                                      FormatMm(node.y_mm), AxisName(axis), Um(*node.pooled_stddev_mm),
                                      node.rows.size(), LineRanges(measurements, node.rows), Um(median),
                                      Um(limit));
      std::size_t farthest = node.rows.front();
      for (std::size_t k : node.rows) {
        if (std::abs(measurements[k].error_mm - node.mean_mm) >
            std::abs(measurements[farthest].error_mm - node.mean_mm)) {
          farthest = k;
        }
      }
      Diagnostics::AddNote(diag, measurements[farthest].error_field,
                           fmt::format("the measurement farthest from the mean, by {} µm",
                                       Um(std::abs(measurements[farthest].error_mm - node.mean_mm))));
    }
  }
}

// The repetition scatter typical of each axis: the median of its nodes'
// pooled within-set stddevs (0 when no node has one).
std::array<double, 2> TypicalScatter(const std::vector<NodeSummary>& nodes) {
  std::array<double, 2> median{0, 0};
  for (TableAxis axis : kTableAxes) {
    std::vector<double> spreads;
    for (const NodeSummary& node : nodes) {
      if (node.axis == axis && node.pooled_stddev_mm) spreads.push_back(*node.pooled_stddev_mm);
    }
    if (!spreads.empty()) median[static_cast<int>(axis)] = Median(spreads);
  }
  return median;
}

// The repetition scatter a set shift is measured against: the node's own, but
// never less than the median of its axis. A node whose few repetitions happen
// to agree closely must not make an ordinary set difference look significant.
void WarnSetShifts(const std::vector<RawMeasurement>& measurements, const std::vector<NodeSummary>& nodes,
                   Diagnostics& diags) {
  const std::array<double, 2> median = TypicalScatter(nodes);
  for (const NodeSummary& node : nodes) {
    if (!node.set_spread_weight) continue;
    const double scatter = std::max(*node.pooled_stddev_mm, median[static_cast<int>(node.axis)]);
    const double stderr_mm = scatter * *node.set_spread_weight;
    const double spread = node.set_mean_spread_mm;
    if (spread <= kSetShiftFloorMm || spread <= kSetShiftFactor * stderr_mm) continue;
    diags.Report(DiagKind::RawSetShift, measurements[node.rows.front()].error_field, FormatMm(node.x_mm),
                 FormatMm(node.y_mm), AxisName(node.axis), Um(spread), Um(scatter),
                 LineRanges(measurements, node.rows));
  }
}

// What a node's neighbours say it should read: the mean of the medians of
// the nodes next to it along its grid row and column (up to four). Only a
// set slipped by a decimal point needs it, to tell which of two sets holds
// the slip.
class NeighbourCentres {
 public:
  NeighbourCentres(const std::vector<RawMeasurement>& measurements, const std::vector<NodeSummary>& nodes) {
    for (const NodeSummary& node : nodes) {
      if (node.kind != ReadingKind::kNode) continue;  // check points lie off the grid lines
      std::vector<double> values;
      for (std::size_t k : node.rows) values.push_back(measurements[k].error_mm);
      const double centre = Median(values);
      const int axis = static_cast<int>(node.axis);
      rows_[{axis, node.y_mm}][node.x_mm] = centre;
      columns_[{axis, node.x_mm}][node.y_mm] = centre;
    }
  }

  std::optional<double> At(const NodeSummary& node) const {
    if (node.kind != ReadingKind::kNode) return std::nullopt;
    const int axis = static_cast<int>(node.axis);
    double sum = 0;
    int count = 0;
    auto add_beside = [&](const std::map<double, double>& line, double at) {
      auto it = line.find(at);
      if (it != line.begin()) sum += std::prev(it)->second, ++count;
      if (std::next(it) != line.end()) sum += std::next(it)->second, ++count;
    };
    add_beside(rows_.at({axis, node.y_mm}), node.x_mm);
    add_beside(columns_.at({axis, node.x_mm}), node.y_mm);
    if (count == 0) return std::nullopt;
    return sum / count;
  }

 private:
  std::map<std::pair<int, double>, std::map<double, double>> rows_, columns_;
};

std::string SlipOrBadReading(const LikelySlip& slip) {
  return slip.kind == SlipKind::kNone ? std::string("a typo or a bad measurement") : slip.Describe();
}

struct Screened {
  // The readings to leave out of the means, whether or not they are
  // dropped: the table is averaged without them either way, so a slip is
  // reported once, here, and not again by the table's own checks.
  std::vector<bool> left_out;
  // Two sets of a node disagree and nothing tells which slipped: no mean of
  // that node means anything, and the build stops.
  bool undecided = false;
};

// Screens every node's readings (calibration/reading_screen.h) and reports
// what is far off: errors, or warnings for what `drop` leaves out.
Screened ScreenNodes(const std::vector<RawMeasurement>& measurements, const std::vector<NodeSummary>& nodes,
                              bool drop, Diagnostics& diags) {
  const std::array<double, 2> typical = TypicalScatter(nodes);
  const NeighbourCentres neighbours(measurements, nodes);
  Screened screened;
  std::vector<bool>& left_out = screened.left_out;
  left_out.assign(measurements.size(), false);
  for (const NodeSummary& node : nodes) {
    std::vector<double> values;
    std::vector<long long> sets;
    for (std::size_t k : node.rows) {
      values.push_back(measurements[k].error_mm);
      sets.push_back(measurements[k].set);
    }
    const ReadingScreen screen =
        ScreenReadings(values, sets, typical[static_cast<int>(node.axis)], neighbours.At(node));
    const std::string_view what = node.kind == ReadingKind::kNode ? "node" : "check point";
    const std::string x = FormatMm(node.x_mm), y = FormatMm(node.y_mm);
    const std::string_view axis = AxisName(node.axis);
    for (const ReadingOutlier& outlier : screen.outliers) {
      const RawMeasurement& m = measurements[node.rows[outlier.index]];
      left_out[node.rows[outlier.index]] = true;
      const std::string value = fmt::format("{:.6g}", m.error_mm);
      if (drop) {
        diags.Report(DiagKind::RawReadingLeftOut, m.error_field,
                     fmt::format("reading {} mm (set {}, repetition {})", value, m.set, m.repetition), what, x, y,
                     axis, fmt::format("the other readings there have the median {:.6g} mm and scatter {} µm; {}?",
                                 outlier.centre_mm, Um(screen.scatter_mm), SlipOrBadReading(outlier.slip)));
      } else {
        diags.Report(DiagKind::RawReadingOutlier, m.error_field, value, m.set, m.repetition, what, x, y, axis,
                     fmt::format("{:.6g}", outlier.centre_mm), Um(screen.scatter_mm), SlipOrBadReading(outlier.slip));
      }
    }
    if (!screen.set_slip) continue;
    const SetSlip& slip = *screen.set_slip;
    std::vector<std::size_t> set_rows, other_rows;
    for (std::size_t k : node.rows) {
      if (measurements[k].set == slip.set) set_rows.push_back(k);
      if (measurements[k].set == slip.other) other_rows.push_back(k);
    }
    for (std::size_t k : set_rows) left_out[k] = true;
    if (!slip.decided) {
      screened.undecided = true;
      Diagnostic* diag = diags.Report(
          DiagKind::RawSetsDisagree, measurements[set_rows.front()].error_field, slip.set, slip.other, what, x, y, axis,
          slip.set, fmt::format("{:.6g}", slip.set_centre_mm), LineRanges(measurements, set_rows), slip.other,
          fmt::format("{:.6g}", slip.other_centre_mm), LineRanges(measurements, other_rows),
          SlipOrBadReading(slip.slip));
      Diagnostics::AddNote(diag, measurements[other_rows.front()].error_field,
                           fmt::format("set {} starts here", slip.other));
      continue;
    }
    const std::string lines = LineRanges(measurements, set_rows);
    if (drop) {
      diags.Report(DiagKind::RawReadingLeftOut, measurements[set_rows.front()].error_field,
                   fmt::format("set {} (lines {})", slip.set, lines), what, x, y, axis,
                   fmt::format("its median {:.6g} mm against set {}'s {:.6g} mm; {}?", slip.set_centre_mm, slip.other,
                               slip.other_centre_mm, SlipOrBadReading(slip.slip)));
    } else {
      diags.Report(DiagKind::RawSetSlip, measurements[set_rows.front()].error_field, slip.set, what, x, y, axis, lines,
                   fmt::format("{:.6g}", slip.set_centre_mm), slip.other, fmt::format("{:.6g}", slip.other_centre_mm),
                   LineRanges(measurements, other_rows), SlipOrBadReading(slip.slip));
    }
  }
  return screened;
}

}  // namespace

std::vector<NodeSummary> SummarizeNodes(const std::vector<RawMeasurement>& measurements,
                                        Diagnostics& diags) {
  // A check point is averaged per position like a node, and kept apart.
  std::map<std::tuple<int, int, double, double>, std::vector<std::size_t>> by_node;
  std::map<std::tuple<int, int, double, double, long long, long long>, std::size_t> seen;
  for (std::size_t k = 0; k < measurements.size(); ++k) {
    const RawMeasurement& m = measurements[k];
    auto [it, inserted] = seen.emplace(
        std::make_tuple(static_cast<int>(m.kind), static_cast<int>(m.axis), m.x_mm, m.y_mm, m.set, m.repetition), k);
    if (!inserted) {
      const RawMeasurement& first = measurements[it->second];
      Diagnostic* diag = diags.Report(DiagKind::RawDuplicateMeasurement, m.repetition_field, m.repetition,
                                      m.set, FormatMm(m.x_mm), FormatMm(m.y_mm), AxisName(m.axis),
                                      first.repetition_field.begin.line);
      Diagnostics::AddNote(diag, first.repetition_field, "first given here");
      continue;
    }
    by_node[{static_cast<int>(m.kind), static_cast<int>(m.axis), m.x_mm, m.y_mm}].push_back(k);
  }

  std::vector<NodeSummary> nodes;
  for (const auto& [key, rows] : by_node) {
    NodeSummary node;
    node.kind = static_cast<ReadingKind>(std::get<0>(key));
    node.axis = static_cast<TableAxis>(std::get<1>(key));
    node.x_mm = std::get<2>(key);
    node.y_mm = std::get<3>(key);
    node.rows = rows;
    const double n = static_cast<double>(rows.size());
    double sum = 0;
    std::map<long long, std::pair<double, int>> sets;  // set -> (sum, count)
    for (std::size_t k : rows) {
      sum += measurements[k].error_mm;
      auto& [set_sum, set_count] = sets[measurements[k].set];
      set_sum += measurements[k].error_mm;
      ++set_count;
    }
    node.mean_mm = sum / n;
    double total_ss = 0, within_ss = 0;
    for (std::size_t k : rows) {
      const auto& [set_sum, set_count] = sets[measurements[k].set];
      total_ss += std::pow(measurements[k].error_mm - node.mean_mm, 2);
      within_ss += std::pow(measurements[k].error_mm - set_sum / set_count, 2);
    }
    if (rows.size() >= 2) node.stddev_mm = std::sqrt(total_ss / (n - 1));
    const double within_dof = n - static_cast<double>(sets.size());
    if (within_dof >= 1) node.pooled_stddev_mm = std::sqrt(within_ss / within_dof);
    // The spread of the set means and its standard error (sets of 2 or more).
    const std::pair<double, int>* low = nullptr;
    const std::pair<double, int>* high = nullptr;
    for (const auto& [set, stats] : sets) {
      if (stats.second < 2) continue;
      double mean = stats.first / stats.second;
      if (low == nullptr || mean < low->first / low->second) low = &stats;
      if (high == nullptr || mean > high->first / high->second) high = &stats;
    }
    if (low != nullptr && low != high && node.pooled_stddev_mm) {
      node.set_mean_spread_mm = high->first / high->second - low->first / low->second;
      node.set_spread_weight = std::sqrt(1.0 / low->second + 1.0 / high->second);
    }
    nodes.push_back(std::move(node));
  }
  return nodes;
}

std::optional<ErrorTable> BuildErrorTable(std::string name, const std::vector<RawMeasurement>& all,
                                          SourceLoc file, Diagnostics& diags, const BuildOptions& options) {
  std::size_t errors_before = diags.error_count();
  // A bidirectional measurement: the table holds the errors approached as
  // production approaches its targets; the readings against the approach
  // give each node's reversal value (ISO 230-2), screened apart.
  std::vector<RawMeasurement> measurements, reversed;
  for (const RawMeasurement& m : all) (m.reverse ? reversed : measurements).push_back(m);
  std::map<std::tuple<int, int, double, double>, double> reversed_mean;
  if (!reversed.empty()) {
    std::vector<NodeSummary> back = SummarizeNodes(reversed, diags);
    if (diags.error_count() != errors_before) return std::nullopt;
    const Screened screened_back = ScreenNodes(reversed, back, options.drop_outlier_readings, diags);
    if (screened_back.undecided) return std::nullopt;
    std::vector<RawMeasurement> kept_back;
    for (std::size_t k = 0; k < reversed.size(); ++k) {
      if (!screened_back.left_out[k]) kept_back.push_back(reversed[k]);
    }
    for (const NodeSummary& node : SummarizeNodes(kept_back, diags)) {
      reversed_mean[{static_cast<int>(node.kind), static_cast<int>(node.axis), node.x_mm, node.y_mm}] = node.mean_mm;
    }
  }
  std::vector<NodeSummary> summaries = SummarizeNodes(measurements, diags);
  if (diags.error_count() != errors_before) return std::nullopt;
  const Screened screened = ScreenNodes(measurements, summaries, options.drop_outlier_readings, diags);
  if (screened.undecided) return std::nullopt;
  const std::vector<bool>& left_out = screened.left_out;
  // The rest of the build sees only the readings kept (a file line stays
  // with its reading).
  std::vector<RawMeasurement> kept;
  for (std::size_t k = 0; k < measurements.size(); ++k) {
    if (!left_out[k]) kept.push_back(measurements[k]);
  }
  if (kept.size() != measurements.size()) summaries = SummarizeNodes(kept, diags);
  WarnNoisyNodes(kept, summaries, diags);
  WarnSetShifts(kept, summaries, diags);
  std::vector<TableNode> nodes;
  for (const NodeSummary& summary : summaries) {
    const RawMeasurement& first = kept[summary.rows.front()];
    TableNode node;
    node.kind = summary.kind;
    node.axis = summary.axis;
    node.x_mm = summary.x_mm;
    node.y_mm = summary.y_mm;
    node.error_mm = summary.mean_mm;
    node.stddev_mm = summary.stddev_mm;
    node.count = static_cast<int>(summary.rows.size());
    for (std::size_t k : summary.rows) {
      if (kept[k].u_mm) node.u_mm = std::max(node.u_mm.value_or(0.0), *kept[k].u_mm);
    }
    auto back = reversed_mean.find({static_cast<int>(summary.kind), static_cast<int>(summary.axis), summary.x_mm,
                                    summary.y_mm});
    if (back != reversed_mean.end()) node.reversal_mm = back->second - summary.mean_mm;
    node.x_field = first.x_field;
    node.y_field = first.y_field;
    node.error_field = first.error_field;
    nodes.push_back(node);
  }
  return AssembleErrorTable(std::move(name), nodes, file, diags);
}

}  // namespace smtcal
