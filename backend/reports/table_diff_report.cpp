// Outputs of `smtcal table diff` (backend/reports/table_diff_report.h).
#include "backend/reports/table_diff_report.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "backend/reports/table_plot.h"
#include "base/field_text.h"
#include "base/json_text.h"

namespace smtcal {
namespace {

// No "-0.0": a change that rounds to zero has no sign.
double Rounded(double value, double resolution) {
  const double rounded = std::round(value / resolution) * resolution;
  return rounded == 0 ? 0.0 : rounded;
}
std::string Um(double um) { return fmt::format("{:.1f}", Rounded(um, 0.1)); }
std::string SignedUm(double um) { return fmt::format("{:+.1f}", Rounded(um, 0.1)); }

std::string Stats(const ChangeStats& s, double threshold_um) {
  if (s.nodes == 0) return "no nodes";
  std::string text = fmt::format("max |change| {} µm, mean {} µm, rms {} µm", Um(s.max_abs_um), SignedUm(s.mean_um),
                                 Um(s.rms_um));
  if (s.beyond > 0) text += fmt::format(", {} by more than {} µm", s.beyond, Um(threshold_um));
  return text;
}

std::string NodeText(const NodeChange& node) {
  return fmt::format("Δ{} at x {}, y {} mm: {:.6f} -> {:.6f} mm ({} µm)", AxisName(node.axis), FormatMm(node.x_mm),
                     FormatMm(node.y_mm), node.old_mm, node.new_mm, SignedUm(node.change_um));
}

}  // namespace

bool TableDiffPasses(const TableChanges& changes) {
  return changes.beyond() == 0 && changes.axes[0].overlap && changes.axes[1].overlap;
}

std::string FormatTableDiffText(const TableChanges& changes, const TableDiffNames& names) {
  std::string text = fmt::format("table diff {} -> {} (threshold {} µm)\n", names.old_table, names.new_table,
                                 Um(changes.threshold_um));
  for (TableAxis axis : kTableAxes) {
    const AxisComparison& c = changes.axes[static_cast<int>(axis)];
    if (!c.overlap) {
      text += fmt::format("Δ{}: the two grids share no area: nothing to compare\n", AxisName(axis));
      continue;
    }
    const std::string area = fmt::format("x {}..{}, y {}..{} mm", FormatMm(c.common.x0), FormatMm(c.common.x1),
                                         FormatMm(c.common.y0), FormatMm(c.common.y1));
    std::string how = c.same_grid ? fmt::format("{} nodes of the same grid ({})", c.stats.nodes, area)
                                  : fmt::format("{} nodes of the two grids, each against the other table's "
                                                "interpolation, on their common area {}",
                                                c.stats.nodes, area);
    if (c.old_nodes_outside + c.new_nodes_outside > 0) {
      how += fmt::format(" ({} of the old grid's nodes and {} of the new's lie outside it: not compared)",
                         c.old_nodes_outside, c.new_nodes_outside);
    }
    std::string what;
    if (Rounded(c.stats.max_abs_um, 0.1) == 0) {
      what = "no change (all below 0.1 µm)";
    } else if (c.stats.uniform()) {  // no node changed more than another
      what = fmt::format("a uniform change: every node {} µm", SignedUm(c.stats.mean_um));
      if (c.stats.beyond > 0) what += fmt::format(", more than {} µm", Um(changes.threshold_um));
    } else {
      what = Stats(c.stats, changes.threshold_um);
    }
    text += fmt::format("Δ{}: {}: {}\n", AxisName(axis), how, what);
  }
  const std::vector<std::size_t> largest = LargestChanges(changes, kTableDiffLargest);
  if (!largest.empty() && Rounded(changes.nodes[largest.front()].change_um, 0.1) != 0) {
    text += "the nodes that changed most:\n";
    for (std::size_t n : largest) {
      if (Rounded(changes.nodes[n].change_um, 0.1) == 0) break;
      text += "  " + NodeText(changes.nodes[n]) + "\n";
    }
    // Nodes left out that changed as much as the last one listed: the list
    // is not a ranking beyond it.
    const double last = std::fabs(changes.nodes[largest.back()].change_um);
    std::size_t tied = 0;
    for (std::size_t n = 0; n < changes.nodes.size(); ++n) {
      const bool listed = std::find(largest.begin(), largest.end(), n) != largest.end();
      if (!listed && !changes.axes[static_cast<int>(changes.nodes[n].axis)].stats.uniform() &&
          std::fabs(changes.nodes[n].change_um) > last - kTableDiffUniformUm) {
        ++tied;
      }
    }
    if (tied > 0 && largest.size() == kTableDiffLargest) {
      text += fmt::format("  ... and {} more node{} by as much ({} µm)\n", tied, tied == 1 ? "" : "s",
                          Um(last));
    }
  }
  for (const TableChanges::RegionChanges& region : changes.regions) {
    std::vector<std::string> axes;
    for (TableAxis axis : kTableAxes) {
      const ChangeStats& s = region.axes[static_cast<int>(axis)];
      axes.push_back(fmt::format("Δ{} {} nodes, {}", AxisName(axis), s.nodes, Stats(s, changes.threshold_um)));
    }
    text += fmt::format("region {} ({}): {}\n", region.name, names.cell, fmt::join(axes, "; "));
  }
  if (TableDiffPasses(changes)) {
    text += fmt::format("gate: passed: no node changed by more than {} µm\n", Um(changes.threshold_um));
  } else if (changes.beyond() > 0) {
    text += fmt::format("gate: failed: {} node{} changed by more than {} µm\n", changes.beyond(),
                        changes.beyond() == 1 ? "" : "s", Um(changes.threshold_um));
  } else {
    text += "gate: failed: the tables share no area to compare\n";
  }
  return text;
}

std::string FormatTableDiffJson(const TableChanges& changes, const TableDiffNames& names) {
  using nlohmann::ordered_json;
  auto stats = [](const ChangeStats& s) {
    ordered_json j;
    j["nodes"] = s.nodes;
    j["max_abs_um"] = RoundedToDecimals(s.max_abs_um, 4);
    j["mean_um"] = RoundedToDecimals(s.mean_um, 4);
    j["rms_um"] = RoundedToDecimals(s.rms_um, 4);
    j["uniform"] = s.uniform();
    j["beyond_threshold"] = s.beyond;
    return j;
  };
  auto node = [](const NodeChange& n) {
    ordered_json j;
    j["axis"] = AxisName(n.axis);
    j["x_mm"] = n.x_mm;
    j["y_mm"] = n.y_mm;
    j["old_mm"] = RoundedToDecimals(n.old_mm, 9);
    j["new_mm"] = RoundedToDecimals(n.new_mm, 9);
    j["change_um"] = RoundedToDecimals(n.change_um, 4);
    return j;
  };
  ordered_json root;
  root["schema"] = "smtcal-table-diff/1";
  root["old"] = names.old_table;
  root["new"] = names.new_table;
  root["threshold_um"] = RoundedToDecimals(changes.threshold_um, 4);
  ordered_json axes;
  for (TableAxis axis : kTableAxes) {
    const AxisComparison& c = changes.axes[static_cast<int>(axis)];
    ordered_json j = stats(c.stats);
    j["same_grid"] = c.same_grid;
    j["common"] = c.overlap ? ordered_json{{"x0_mm", c.common.x0}, {"x1_mm", c.common.x1}, {"y0_mm", c.common.y0},
                                           {"y1_mm", c.common.y1}}
                            : ordered_json();
    j["old_nodes_outside"] = c.old_nodes_outside;
    j["new_nodes_outside"] = c.new_nodes_outside;
    axes[std::string(AxisName(axis))] = j;
  }
  root["axes"] = axes;
  ordered_json largest = ordered_json::array();
  for (std::size_t n : LargestChanges(changes, kTableDiffLargest)) largest.push_back(node(changes.nodes[n]));
  root["largest"] = largest;
  ordered_json regions = ordered_json::array();
  for (const TableChanges::RegionChanges& region : changes.regions) {
    regions.push_back({{"name", region.name}, {"x", stats(region.axes[0])}, {"y", stats(region.axes[1])}});
  }
  root["regions"] = regions;
  root["gate"] = TableDiffPasses(changes) ? "passed" : "failed";
  return JsonText(root);
}

std::string PlotTableDiffSvg(const ErrorTable& old_table, const ErrorTable& new_table, const TableDiffNames& names) {
  std::optional<ErrorTable> change = ChangeTable(old_table, new_table);
  if (!change) return "";
  TablePlotWords words;
  words.heading = fmt::format("How the error tables changed: {} -> {}", names.old_table, names.new_table);
  words.field = "the change of the error, new - old";
  words.arrows = "the panel's own component of the change (along x in the Δx panel, along y in the Δy one)";
  words.panel = "change of Δ{0}";
  words.state_arrow_fill = true;
  words.own_component = true;
  return PlotTableSvg(*change, words);
}

}  // namespace smtcal
