// Averaging raw measurements into an error table. Assumes measurements with
// finite values (the CSV reader's job); guarantees one node per (axis, x, y)
// with the mean of its measurements, their stddev and count, and a warning for
// every node whose scatter or set-to-set difference is far from its axis's
// norm (the thresholds are in calibration/tolerances.h).
#include "calibration/error_table_build.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/tolerances.h"

namespace smtcal {
namespace {

constexpr double kMadToSigma = 1.4826;  // MAD of a normal distribution -> its sigma
constexpr double kUmPerMm = 1000.0;

double Median(std::vector<double> values) {
  SMTCAL_CHECK(!values.empty(), "median of nothing");
  std::sort(values.begin(), values.end());
  std::size_t mid = values.size() / 2;
  return values.size() % 2 == 1 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
}

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
    const double limit = median + std::max(kNoisyNodeMadFactor * kMadToSigma * mad, kNoisyNodeFloorMm);
    for (const NodeSummary& node : nodes) {
      if (node.axis != axis || !node.pooled_stddev_mm || *node.pooled_stddev_mm <= limit) continue;
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

// The repetition scatter a set shift is measured against: the node's own, but
// never less than the median of its axis. A node whose few repetitions happen
// to agree closely must not make an ordinary set difference look significant.
void WarnSetShifts(const std::vector<RawMeasurement>& measurements, const std::vector<NodeSummary>& nodes,
                   Diagnostics& diags) {
  std::array<double, 2> median{0, 0};
  for (TableAxis axis : kTableAxes) {
    std::vector<double> spreads;
    for (const NodeSummary& node : nodes) {
      if (node.axis == axis && node.pooled_stddev_mm) spreads.push_back(*node.pooled_stddev_mm);
    }
    if (!spreads.empty()) median[static_cast<int>(axis)] = Median(spreads);
  }
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

std::optional<ErrorTable> BuildErrorTable(std::string name, const std::vector<RawMeasurement>& measurements,
                                          SourceLoc file, Diagnostics& diags) {
  std::size_t errors_before = diags.error_count();
  std::vector<NodeSummary> summaries = SummarizeNodes(measurements, diags);
  if (diags.error_count() != errors_before) return std::nullopt;
  WarnNoisyNodes(measurements, summaries, diags);
  WarnSetShifts(measurements, summaries, diags);
  std::vector<TableNode> nodes;
  for (const NodeSummary& summary : summaries) {
    const RawMeasurement& first = measurements[summary.rows.front()];
    TableNode node;
    node.kind = summary.kind;
    node.axis = summary.axis;
    node.x_mm = summary.x_mm;
    node.y_mm = summary.y_mm;
    node.error_mm = summary.mean_mm;
    node.stddev_mm = summary.stddev_mm;
    node.count = static_cast<int>(summary.rows.size());
    node.x_field = first.x_field;
    node.y_field = first.y_field;
    node.error_field = first.error_field;
    nodes.push_back(node);
  }
  return AssembleErrorTable(std::move(name), nodes, file, diags);
}

}  // namespace smtcal
