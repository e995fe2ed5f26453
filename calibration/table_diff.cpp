// How an error table changed (calibration/table_diff.h).
#include "calibration/table_diff.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "calibration/tolerances.h"

namespace smtcal {
namespace {

constexpr double kUmPerMm = 1000;

Rect GridRect(const AxisTable& t) { return {t.xs.front(), t.xs.back(), t.ys.front(), t.ys.back()}; }

bool InRect(const Rect& r, double x, double y) {
  return x >= r.x0 - kTableEdgeTolMm && x <= r.x1 + kTableEdgeTolMm && y >= r.y0 - kTableEdgeTolMm &&
         y <= r.y1 + kTableEdgeTolMm;
}

void Add(ChangeStats& stats, const NodeChange& node, std::size_t index, double threshold_um) {
  const double magnitude = std::fabs(node.change_um);
  if (stats.nodes == 0 || magnitude > stats.max_abs_um) {
    stats.max_abs_um = magnitude;
    stats.largest = index;
  }
  stats.min_um = stats.nodes == 0 ? node.change_um : std::min(stats.min_um, node.change_um);
  stats.max_um = stats.nodes == 0 ? node.change_um : std::max(stats.max_um, node.change_um);
  ++stats.nodes;
  stats.mean_um += node.change_um;
  stats.rms_um += node.change_um * node.change_um;
  if (magnitude > threshold_um) ++stats.beyond;
}

void Finish(ChangeStats& stats) {
  if (stats.nodes == 0) return;
  stats.mean_um /= static_cast<double>(stats.nodes);
  stats.rms_um = std::sqrt(stats.rms_um / static_cast<double>(stats.nodes));
}

// The lines of `lines` within [lo, hi].
std::vector<double> Within(const std::vector<double>& lines, double lo, double hi) {
  std::vector<double> out;
  for (double v : lines) {
    if (v >= lo - kTableEdgeTolMm && v <= hi + kTableEdgeTolMm) out.push_back(v);
  }
  return out;
}

}  // namespace

bool ChangeStats::uniform() const { return nodes > 1 && max_um - min_um < kTableDiffUniformUm; }

TableChanges CompareTables(const ErrorTable& old_table, const ErrorTable& new_table, double threshold_um,
                           const std::vector<cell::Region>* regions) {
  TableChanges out;
  out.threshold_um = threshold_um;
  const CalibrationMap old_map(old_table), new_map(new_table);
  for (TableAxis axis : kTableAxes) {
    const AxisTable& a = old_table[axis];
    const AxisTable& b = new_table[axis];
    AxisComparison& comparison = out.axes[static_cast<int>(axis)];
    comparison.same_grid = a.xs == b.xs && a.ys == b.ys;
    const Rect ra = GridRect(a), rb = GridRect(b);
    comparison.common = {std::max(ra.x0, rb.x0), std::min(ra.x1, rb.x1), std::max(ra.y0, rb.y0), std::min(ra.y1, rb.y1)};
    comparison.overlap = comparison.common.x0 < comparison.common.x1 && comparison.common.y0 < comparison.common.y1;
    // Keyed by (y, x): the order of the report, and a node on both grids once.
    std::map<std::pair<double, double>, NodeChange> nodes;
    for (std::size_t j = 0; j < a.ny(); ++j) {
      for (std::size_t i = 0; i < a.nx(); ++i) {
        if (!InRect(rb, a.xs[i], a.ys[j])) {
          ++comparison.old_nodes_outside;
          continue;
        }
        NodeChange& node = nodes[{a.ys[j], a.xs[i]}];
        node.axis = axis;
        node.x_mm = a.xs[i];
        node.y_mm = a.ys[j];
        node.old_mm = a.At(i, j);
        node.new_mm = new_map.AxisDelta(axis, a.xs[i], a.ys[j]);
        node.on_old_grid = true;
      }
    }
    for (std::size_t j = 0; j < b.ny(); ++j) {
      for (std::size_t i = 0; i < b.nx(); ++i) {
        if (!InRect(ra, b.xs[i], b.ys[j])) {
          ++comparison.new_nodes_outside;
          continue;
        }
        auto [it, inserted] = nodes.try_emplace({b.ys[j], b.xs[i]});
        NodeChange& node = it->second;
        if (inserted) {
          node.axis = axis;
          node.x_mm = b.xs[i];
          node.y_mm = b.ys[j];
          node.old_mm = old_map.AxisDelta(axis, b.xs[i], b.ys[j]);
        }
        node.new_mm = b.At(i, j);
        node.on_new_grid = true;
      }
    }
    for (auto& [key, node] : nodes) {
      node.change_um = (node.new_mm - node.old_mm) * kUmPerMm;
      Add(comparison.stats, node, out.nodes.size(), threshold_um);
      out.nodes.push_back(node);
    }
    Finish(comparison.stats);
  }
  if (regions != nullptr) {
    for (const cell::Region& region : *regions) {
      TableChanges::RegionChanges changes;
      changes.name = region.name;
      for (std::size_t n = 0; n < out.nodes.size(); ++n) {
        const NodeChange& node = out.nodes[n];
        if (!region.Contains({node.x_mm, node.y_mm})) continue;
        Add(changes.axes[static_cast<int>(node.axis)], node, n, threshold_um);
      }
      if (changes.axes[0].nodes + changes.axes[1].nodes == 0) continue;
      for (ChangeStats& stats : changes.axes) Finish(stats);
      out.regions.push_back(std::move(changes));
    }
  }
  return out;
}

std::vector<std::size_t> LargestChanges(const TableChanges& changes, std::size_t count) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < changes.nodes.size(); ++i) {
    // A change printed as 0.0 µm is not a change that ranks.
    if (!changes.axes[static_cast<int>(changes.nodes[i].axis)].stats.uniform() &&
        std::fabs(changes.nodes[i].change_um) >= kTableDiffUniformUm) {
      order.push_back(i);
    }
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return std::fabs(changes.nodes[a].change_um) > std::fabs(changes.nodes[b].change_um);
  });
  if (order.size() > count) order.resize(count);
  return order;
}

std::optional<ErrorTable> ChangeTable(const ErrorTable& old_table, const ErrorTable& new_table) {
  const CalibrationMap old_map(old_table), new_map(new_table);
  ErrorTable change;
  change.name = "change";
  for (TableAxis axis : kTableAxes) {
    const AxisTable& a = old_table[axis];
    const AxisTable& b = new_table[axis];
    const Rect ra = GridRect(a), rb = GridRect(b);
    const double x0 = std::max(ra.x0, rb.x0), x1 = std::min(ra.x1, rb.x1);
    const double y0 = std::max(ra.y0, rb.y0), y1 = std::min(ra.y1, rb.y1);
    AxisTable& t = change[axis];
    t.xs = Within(a.xs, x0, x1);
    t.ys = Within(a.ys, y0, y1);
    if (t.xs.size() < 2 || t.ys.size() < 2) {
      t.xs = Within(b.xs, x0, x1);
      t.ys = Within(b.ys, y0, y1);
    }
    if (t.xs.size() < 2 || t.ys.size() < 2) return std::nullopt;
    for (double y : t.ys) {
      for (double x : t.xs) t.error_mm.push_back(new_map.AxisDelta(axis, x, y) - old_map.AxisDelta(axis, x, y));
    }
  }
  if (!HasUsableShape(change)) return std::nullopt;
  return change;
}

}  // namespace smtcal
