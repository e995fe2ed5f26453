// Fixed-format text outputs of the error-table commands (see table_report.h).
#include "backend/reports/table_report.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "base/field_text.h"
#include "base/json_text.h"

namespace smtcal {
namespace {

constexpr double kUmPerMm = 1000.0;

// Fixed decimals without a "-0.000...".
std::string Fixed(double v, int decimals) {
  std::string text = fmt::format("{:.{}f}", v, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos && text.front() == '-') text.erase(0, 1);
  return text;
}
std::string SignedFixed(double v, int decimals) {
  std::string text = Fixed(v, decimals);
  return text.front() == '-' ? text : "+" + text;
}

// JSON numbers: rounded to a nanometre (or 1e-6 for ratios) so they print
// short and the same everywhere.
double Round6(double v) { return RoundedToDecimals(v, 6); }

std::string Range(const std::vector<double>& lines) {
  return fmt::format("{}..{}", FormatMm(lines.front()), FormatMm(lines.back()));
}

}  // namespace

std::string FormatTableCsv(const ErrorTable& table, const std::vector<std::string>& comment) {
  std::string out;
  for (const std::string& line : comment) out += "# " + line + "\n";
  bool stddev = false, count = false, checks = false, uncertainty = false, reversal = false;
  for (const AxisTable& t : table.axes) {
    for (const auto& sd : t.stddev_mm) stddev = stddev || sd.has_value();
    for (int n : t.count) count = count || n > 0;
    for (const auto& u : t.u_mm) uncertainty = uncertainty || u.has_value();
    for (const auto& r : t.reversal_mm) reversal = reversal || r.has_value();
    for (const TableNode& check : t.checks) {
      stddev = stddev || check.stddev_mm.has_value();
      count = count || check.count > 0;
      uncertainty = uncertainty || check.u_mm.has_value();
      reversal = reversal || check.reversal_mm.has_value();
    }
    checks = checks || !t.checks.empty();
  }
  out += "axis,x_mm,y_mm,error_mm";
  if (stddev) out += ",stddev_mm";
  if (count) out += ",n";
  if (uncertainty) out += ",u_mm";
  if (reversal) out += ",reversal_mm";
  if (checks) out += ",kind";
  out += "\n";
  auto optional = [](const std::optional<double>& v) { return v ? Fixed(*v, 6) : std::string(); };
  auto row = [&](TableAxis axis, ReadingKind kind, double x, double y, double error, std::optional<double> sd, int n,
                 std::optional<double> u, std::optional<double> r) {
    out += fmt::format("{},{},{},{}", AxisName(axis), FormatMm(x), FormatMm(y), Fixed(error, 6));
    if (stddev) out += "," + optional(sd);
    if (count) out += "," + (n > 0 ? fmt::format("{}", n) : std::string());
    if (uncertainty) out += "," + optional(u);
    if (reversal) out += "," + optional(r);
    if (checks) out += fmt::format(",{}", ReadingKindName(kind));
    out += "\n";
  };
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) {
        std::size_t k = t.Index(i, j);
        row(axis, ReadingKind::kNode, t.xs[i], t.ys[j], t.error_mm[k],
            t.stddev_mm.empty() ? std::nullopt : t.stddev_mm[k], t.count.empty() ? 0 : t.count[k],
            t.u_mm.empty() ? std::nullopt : t.u_mm[k], t.reversal_mm.empty() ? std::nullopt : t.reversal_mm[k]);
      }
    }
  }
  // The check points after every node, so a table's node rows stay where
  // they were when check points are added.
  for (TableAxis axis : kTableAxes) {
    for (const TableNode& check : table[axis].checks) {
      row(axis, ReadingKind::kCheck, check.x_mm, check.y_mm, check.error_mm, check.stddev_mm, check.count, check.u_mm,
          check.reversal_mm);
    }
  }
  return out;
}

std::vector<std::string> BuiltTableComment(std::string_view raw_name) {
  return {fmt::format("error table built by smtcal table build from {}", raw_name),
          "error_mm: the mean of the node's measurements; stddev_mm: their sample standard deviation; "
          "n: their count"};
}

std::string InterpolationText(const InterpolationEstimate& estimate, double tolerance_mm) {
  const GridAdvice advice = AdviseGrid(estimate, tolerance_mm);
  std::string text = fmt::format("{} mm (Δx {}, Δy {} mm), {} % of ±{} mm, {}", Fixed(estimate.NormMm(), 4),
                                 Fixed(estimate.axes[0].estimate_mm, 4), Fixed(estimate.axes[1].estimate_mm, 4),
                                 Fixed(100 * advice.share, 1), FormatMm(tolerance_mm),
                                 InterpolationKindDescription(estimate.Kind()));
  const std::size_t checked = estimate.axes[0].checked_cells + estimate.axes[1].checked_cells;
  const std::size_t cells = estimate.axes[0].cells + estimate.axes[1].cells;
  if (estimate.HasCheckPoints()) {
    const bool stated = estimate.axes[0].reading_scatter_mm || estimate.axes[1].reading_scatter_mm;
    text += fmt::format("; check points in {} of {} cells, largest residual {} mm, their noise σ {} mm{}", checked,
                        cells,
                        Fixed(std::max(estimate.axes[0].largest_residual_mm, estimate.axes[1].largest_residual_mm), 4),
                        Fixed(estimate.NoiseMm(), 4),
                        stated ? std::string(" (a random part)") : std::string(" (the table states no scatter)"));
  }
  if (advice.coarse) {
    text += fmt::format("; more than {} %: measure at a pitch of at most {} mm (it has {} mm){}",
                        Fixed(100 * kInterpolationShareOfTolerance, 0), Fixed(advice.pitch_mm, 1),
                        Fixed(estimate.PitchMm(), 1),
                        advice.check_points_would_settle ? ", or measure check points at the cell centres" : "");
  }
  return text;
}

nlohmann::ordered_json InterpolationJson(const InterpolationEstimate& estimate, double tolerance_mm) {
  using nlohmann::ordered_json;
  const GridAdvice advice = AdviseGrid(estimate, tolerance_mm);
  auto optional = [](const std::optional<double>& v) { return v ? ordered_json(Round6(*v)) : ordered_json(); };
  ordered_json axes;
  for (TableAxis axis : kTableAxes) {
    const AxisInterpolation& a = estimate[axis];
    axes[std::string(AxisName(axis))] = {{"estimate_mm", Round6(a.estimate_mm)},
                                         {"kind", InterpolationKindName(a.kind)},
                                         {"at_mm", {Round6(a.at.x()), Round6(a.at.y())}},
                                         {"curvature_mm", Round6(a.curvature_mm)},
                                         {"check_points_mm", optional(a.check_points_mm)},
                                         {"declared_mm", optional(a.declared_mm)},
                                         {"check_points", a.check_points},
                                         {"cells", a.cells},
                                         {"checked_cells", a.checked_cells},
                                         {"noise_mm", Round6(a.noise_mm)},
                                         {"reading_scatter_mm", optional(a.reading_scatter_mm)},
                                         {"pitch_mm", Round6(a.pitch_mm)}};
  }
  return {{"mm", Round6(estimate.NormMm())},
          {"x_mm", Round6(estimate.axes[0].estimate_mm)},
          {"y_mm", Round6(estimate.axes[1].estimate_mm)},
          {"noise_mm", Round6(estimate.NoiseMm())},
          {"kind", InterpolationKindName(estimate.Kind())},
          {"lower_bound", estimate.Kind() == InterpolationKind::kCurvature},
          {"tolerance_mm", tolerance_mm},
          {"share", Round6(advice.share)},
          {"coarse", advice.coarse},
          {"advice_pitch_mm", advice.coarse ? ordered_json(advice.pitch_mm) : ordered_json()},
          {"check_points_would_settle", advice.check_points_would_settle},
          {"axes", std::move(axes)}};
}

std::string FormatStatsText(const ErrorTable& table, const TableStats& stats, const TableAnalysis& analysis,
                            int iteration_bound, const InterpolationEstimate& interpolation, double tolerance_mm) {
  const AxisStats& sx = stats.axes[0];
  const AxisStats& sy = stats.axes[1];
  const AxisTable& tx = table[TableAxis::X];
  const AxisTable& ty = table[TableAxis::Y];
  Rect domain = TableDomain(table);
  std::string out;
  out += fmt::format("error table  {}\n", table.name);
  out += fmt::format("x table      {} x {} nodes, x {}, y {} mm\n", sx.nx, sx.ny, Range(tx.xs), Range(tx.ys));
  out += fmt::format("y table      {} x {} nodes, x {}, y {} mm\n", sy.nx, sy.ny, Range(ty.xs), Range(ty.ys));
  out += fmt::format("inside       x {}..{}, y {}..{} mm (where both tables are)\n", FormatMm(domain.x0),
                     FormatMm(domain.x1), FormatMm(domain.y0), FormatMm(domain.y1));
  out += "\n";
  out += fmt::format("{:<16}{:>20}{:>20}\n", "", "Δx", "Δy");
  out += fmt::format("{:<16}{:>10}{:>10}{:>10}{:>10}\n", "", "µm", "mm", "µm", "mm");
  auto row = [&](std::string_view label, double vx, double vy, bool sign) {
    auto um = [&](double v) { return sign ? SignedFixed(v * kUmPerMm, 1) : Fixed(v * kUmPerMm, 1); };
    auto mm = [&](double v) { return sign ? SignedFixed(v, 5) : Fixed(v, 5); };
    out += fmt::format("{:<16}{:>10}{:>10}{:>10}{:>10}\n", label, um(vx), mm(vx), um(vy), mm(vy));
  };
  row("max", sx.max_mm, sy.max_mm, true);
  row("min", sx.min_mm, sy.min_mm, true);
  row("mean", sx.mean_mm, sy.mean_mm, true);
  row("max - min", sx.max_mm - sx.min_mm, sy.max_mm - sy.min_mm, false);
  row("max |Δ - mean|", sx.abs_max_after_shift_mm, sy.abs_max_after_shift_mm, false);
  if (sx.stddev_nodes > 0 || sy.stddev_nodes > 0) {
    row("stddev mean", sx.stddev_mean_mm, sy.stddev_mean_mm, false);
    row("stddev max", sx.stddev_max_mm, sy.stddev_max_mm, false);
  }
  out += "\n";
  out += fmt::format("max Δx at ({}, {}), min Δx at ({}, {})\n", FormatMm(sx.max_x), FormatMm(sx.max_y),
                     FormatMm(sx.min_x), FormatMm(sx.min_y));
  out += fmt::format("max Δy at ({}, {}), min Δy at ({}, {})\n", FormatMm(sy.max_x), FormatMm(sy.max_y),
                     FormatMm(sy.min_x), FormatMm(sy.min_y));
  out += fmt::format("origin shift by the means: x {} mm, y {} mm\n", SignedFixed(stats.shift_x_mm, 6),
                     SignedFixed(stats.shift_y_mm, 6));
  auto counts = [](const AxisStats& s) {
    if (s.count_max == 0) return std::string("not given");
    if (s.count_min == s.count_max) return fmt::format("{}", s.count_min);
    return fmt::format("{} to {}", s.count_min, s.count_max);
  };
  out += fmt::format("measurements per node: x {}, y {}\n", counts(sx), counts(sy));
  out += fmt::format("inverse calibration: contraction factor L = {}, min det(I + ∇Δ) = {}, iteration bound {}\n",
                     Fixed(analysis.contraction, 6), Fixed(analysis.min_jacobian_det, 6), iteration_bound);
  out += fmt::format("between the nodes: {}\n", InterpolationText(interpolation, tolerance_mm));
  return out;
}

std::string FormatStatsJson(const ErrorTable& table, const TableStats& stats, const TableAnalysis& analysis,
                            int iteration_bound, const InterpolationEstimate& interpolation, double tolerance_mm) {
  using nlohmann::ordered_json;
  ordered_json root;
  root["file"] = table.name;
  Rect domain = TableDomain(table);
  root["inside_mm"] = {{"x", {Round6(domain.x0), Round6(domain.x1)}},
                       {"y", {Round6(domain.y0), Round6(domain.y1)}}};
  ordered_json axes;
  for (TableAxis axis : kTableAxes) {
    const AxisStats& s = stats.axes[static_cast<int>(axis)];
    const AxisTable& t = table[axis];
    ordered_json j;
    j["nodes"] = {s.nx, s.ny};
    j["x_range_mm"] = {Round6(t.xs.front()), Round6(t.xs.back())};
    j["y_range_mm"] = {Round6(t.ys.front()), Round6(t.ys.back())};
    j["max_mm"] = Round6(s.max_mm);
    j["max_at_mm"] = {Round6(s.max_x), Round6(s.max_y)};
    j["min_mm"] = Round6(s.min_mm);
    j["min_at_mm"] = {Round6(s.min_x), Round6(s.min_y)};
    j["mean_mm"] = Round6(s.mean_mm);
    j["range_mm"] = Round6(s.max_mm - s.min_mm);
    j["abs_max_after_shift_mm"] = Round6(s.abs_max_after_shift_mm);
    j["stddev_mean_mm"] = s.stddev_nodes > 0 ? ordered_json(Round6(s.stddev_mean_mm)) : ordered_json();
    j["stddev_max_mm"] = s.stddev_nodes > 0 ? ordered_json(Round6(s.stddev_max_mm)) : ordered_json();
    j["measurements_per_node"] =
        s.count_max > 0 ? ordered_json({s.count_min, s.count_max}) : ordered_json();
    axes[std::string(AxisName(axis))] = std::move(j);
  }
  root["axes"] = std::move(axes);
  root["origin_shift_mm"] = {{"x", Round6(stats.shift_x_mm)}, {"y", Round6(stats.shift_y_mm)}};
  root["inverse"] = {{"contraction", Round6(analysis.contraction)},
                     {"min_jacobian_det", Round6(analysis.min_jacobian_det)},
                     {"iteration_bound", iteration_bound},
                     {"residual_tolerance_mm", kInverseResidualTolMm}};
  root["interpolation"] = InterpolationJson(interpolation, tolerance_mm);
  return JsonText(root);
}

std::string FormatSolutionsCsv(const std::vector<Solution>& solutions) {
  std::string out = "x_mm,y_mm,residual_mm,iterations\n";
  for (const Solution& s : solutions) {
    out += fmt::format("{},{},{:.3e},{}\n", Fixed(s.point.x(), 6), Fixed(s.point.y(), 6), s.residual_mm,
                       s.iterations);
  }
  return out;
}

}  // namespace smtcal
