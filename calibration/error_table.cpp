// Error tables: assembling grids from nodes, evaluating Delta, statistics.
// Assumes nothing about the nodes' order; guarantees that an assembled table
// has strictly increasing lines at least kMinGridLineSpacingMm apart, exactly
// one finite value per node, at least 2 x 2 nodes per axis, and overlapping
// grids (HasUsableShape).
#include "calibration/error_table.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/limits.h"
#include "calibration/interpolation_error.h"
#include "calibration/tolerances.h"

namespace smtcal {

std::string_view AxisName(TableAxis axis) { return axis == TableAxis::X ? "x" : "y"; }

std::string_view ReadingKindName(ReadingKind kind) { return kind == ReadingKind::kNode ? "node" : "check"; }

std::string FormatMm(double mm) {
  if (mm == 0) mm = 0;  // no "-0.000"
  for (const char* format : {"{:.3f}", "{:.6f}"}) {
    std::string text = fmt::format(fmt::runtime(format), mm);
    double back = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), back);
    if (ec == std::errc() && end == text.data() + text.size() && back == mm) return text;
  }
  return fmt::format("{}", mm);
}

std::string FormatComputedMm(double mm) { return FormatMm(std::round(mm * 1e6) / 1e6); }

SourceRange AxisTable::Origin(std::size_t i, std::size_t j) const {
  return origin.empty() ? SourceRange() : origin[Index(i, j)];
}

std::optional<double> AxisTable::StandardErrorMm(std::size_t node) const {
  if (node >= stddev_mm.size() || node >= count.size() || !stddev_mm[node] || count[node] <= 0) return std::nullopt;
  return *stddev_mm[node] / std::sqrt(static_cast<double>(count[node]));
}

// ------------------------------------------------------------------ assembly

namespace {

std::uint32_t LineOf(const SourceRange& range) { return range.begin.line; }

// The distinct values of one coordinate with the nodes that use each.
using LineMap = std::map<double, std::vector<std::size_t>>;

std::size_t MaxUse(const LineMap& lines) {
  std::size_t most = 0;
  for (const auto& [value, users] : lines) most = std::max(most, users.size());
  return most;
}

// A line used by very few rows while the others are used by many is a typo
// in a coordinate, not a grid line (docs/error-tables.md, "Validation").
bool IsStray(std::size_t uses, std::size_t most) {
  return most >= 3 && uses <= std::max<std::size_t>(1, most / 4);
}

struct AxisAssembly {
  TableAxis axis;
  const std::vector<TableNode>& nodes;
  std::vector<std::size_t> members;  // indices into nodes
  Diagnostics& diags;

  std::optional<AxisTable> Run();
};

std::optional<AxisTable> AxisAssembly::Run() {
  const std::string_view name = AxisName(axis);
  std::size_t errors_before = diags.error_count();
  LineMap x_lines, y_lines;
  for (std::size_t k : members) {
    x_lines[nodes[k].x_mm].push_back(k);
    y_lines[nodes[k].y_mm].push_back(k);
  }
  std::size_t most_x = MaxUse(x_lines), most_y = MaxUse(y_lines);
  std::vector<double> xs, ys;
  for (const auto& [x, users] : x_lines) {
    if (!IsStray(users.size(), most_x)) xs.push_back(x);
  }
  for (const auto& [y, users] : y_lines) {
    if (!IsStray(users.size(), most_y)) ys.push_back(y);
  }
  auto index_of = [](const std::vector<double>& lines, double v) -> std::optional<std::size_t> {
    auto it = std::lower_bound(lines.begin(), lines.end(), v);
    if (it == lines.end() || *it != v) return std::nullopt;
    return static_cast<std::size_t>(it - lines.begin());
  };

  // A table's lines are crossed into nx x ny nodes, each with a row: far
  // fewer rows than that is not a grid with holes but no grid at all (rows
  // on a diagonal make n^2 nodes of n rows). Said once, before the nodes are
  // laid out, so the work stays in proportion to the rows (calibration/limits.h).
  const std::size_t nx = xs.size(), ny = ys.size();
  const double nodes_needed = static_cast<double>(nx) * static_cast<double>(ny);
  const double rows_given = static_cast<double>(members.size());
  if (nodes_needed - rows_given > static_cast<double>(limits::kMaxMissingNodesListed)) {
    diags.Report(DiagKind::TableGridIncomplete, nodes[members.front()].x_field, name, nx, ny,
                 fmt::format("{:.0f}", nodes_needed), members.size(), fmt::format("{:.0f}", nodes_needed - rows_given));
    return std::nullopt;
  }

  // Which grid nodes have a row (first row wins; later ones are duplicates).
  std::vector<std::optional<std::size_t>> at(nx * ny);
  std::vector<std::size_t> strays;
  for (std::size_t k : members) {
    auto i = index_of(xs, nodes[k].x_mm);
    auto j = index_of(ys, nodes[k].y_mm);
    if (!i || !j) {
      strays.push_back(k);
      continue;
    }
    std::optional<std::size_t>& slot = at[*j * nx + *i];
    if (slot) {
      Diagnostic* diag = diags.Report(DiagKind::TableDuplicateNode, nodes[k].x_field,
                                      FormatMm(nodes[k].x_mm), FormatMm(nodes[k].y_mm), name,
                                      LineOf(nodes[*slot].x_field));
      Diagnostics::AddNote(diag, nodes[*slot].x_field, "first given here");
    } else {
      slot = k;
    }
  }

  // Strays: say which coordinate is off, and when exactly one node of the
  // stray's other line has no row, suggest it (that node is then explained).
  std::vector<bool> explained(nx * ny, false);
  for (std::size_t k : strays) {
    const TableNode& node = nodes[k];
    bool x_off = !index_of(xs, node.x_mm).has_value();
    std::string suggestion;
    if (x_off != !index_of(ys, node.y_mm).has_value()) {  // exactly one coordinate is off
      std::vector<std::size_t> candidates;
      if (x_off) {
        std::size_t j = *index_of(ys, node.y_mm);
        for (std::size_t i = 0; i < nx; ++i) {
          if (!at[j * nx + i]) candidates.push_back(j * nx + i);
        }
      } else {
        std::size_t i = *index_of(xs, node.x_mm);
        for (std::size_t j = 0; j < ny; ++j) {
          if (!at[j * nx + i]) candidates.push_back(j * nx + i);
        }
      }
      if (candidates.size() == 1 && !explained[candidates[0]]) {
        std::size_t c = candidates[0];
        explained[c] = true;
        suggestion = fmt::format("; did you mean {} = {}? node ({}, {}) has no row", x_off ? "x_mm" : "y_mm",
                                 FormatMm(x_off ? xs[c % nx] : ys[c / nx]), FormatMm(xs[c % nx]),
                                 FormatMm(ys[c / nx]));
      }
    }
    const char* column = x_off ? "x_mm" : "y_mm";
    double value = x_off ? node.x_mm : node.y_mm;
    diags.Report(DiagKind::TableStrayGridLine, x_off ? node.x_field : node.y_field, column,
                 FormatMm(value), name, column, FormatMm(value), suggestion);
  }

  // Lines closer than the minimum spacing: one line written two ways. The
  // missing-node check would only repeat this, so it is skipped.
  bool too_close = false;
  auto check_spacing = [&](const std::vector<double>& lines, const LineMap& users, const char* coord) {
    for (std::size_t i = 1; i < lines.size(); ++i) {
      double gap = lines[i] - lines[i - 1];
      if (gap >= kMinGridLineSpacingMm) continue;
      too_close = true;
      const TableNode& later = nodes[users.at(lines[i]).front()];
      const TableNode& earlier = nodes[users.at(lines[i - 1]).front()];
      bool is_x = coord[0] == 'x';
      Diagnostic* diag = diags.Report(
          DiagKind::TableGridLinesTooClose, is_x ? later.x_field : later.y_field, coord,
          FormatMm(lines[i - 1]), FormatMm(lines[i]), name, fmt::format("{:.6f}", gap),
          FormatMm(kMinGridLineSpacingMm));
      Diagnostics::AddNote(diag, is_x ? earlier.x_field : earlier.y_field,
                           fmt::format("a row on the {} line {}", coord, FormatMm(lines[i - 1])));
    }
  };
  check_spacing(xs, x_lines, "x");
  check_spacing(ys, y_lines, "y");

  if (!too_close && (nx < 2 || ny < 2)) {
    auto lines = [](std::size_t n, const char* coord) {
      return fmt::format("{} {} {}", n, coord, n == 1 ? "line" : "lines");
    };
    diags.Report(DiagKind::TableGridTooSmall, nodes[members.front()].error_field, name, lines(nx, "x"),
                 lines(ny, "y"));
  }

  if (!too_close && nx >= 2 && ny >= 2) {
    for (std::size_t j = 0; j < ny; ++j) {
      for (std::size_t i = 0; i < nx; ++i) {
        if (at[j * nx + i] || explained[j * nx + i]) continue;
        // Show the nearest node with a row on the same y line, else on the same x line.
        std::optional<std::size_t> neighbour;
        for (std::size_t d = 1; d < std::max(nx, ny) && !neighbour; ++d) {
          if (i >= d && at[j * nx + i - d]) neighbour = at[j * nx + i - d];
          else if (i + d < nx && at[j * nx + i + d]) neighbour = at[j * nx + i + d];
          else if (j >= d && at[(j - d) * nx + i]) neighbour = at[(j - d) * nx + i];
          else if (j + d < ny && at[(j + d) * nx + i]) neighbour = at[(j + d) * nx + i];
        }
        SMTCAL_CHECK(neighbour.has_value(), "every grid line has at least one node");
        const TableNode& shown = nodes[*neighbour];
        diags.Report(DiagKind::TableMissingNode, shown.x_field, FormatMm(xs[i]), FormatMm(ys[j]), name,
                     nx, ny, nx * ny, FormatMm(shown.x_mm), FormatMm(shown.y_mm));
      }
    }
  }
  if (diags.error_count() != errors_before || diags.limit_reached()) return std::nullopt;

  AxisTable table;
  table.xs = xs;
  table.ys = ys;
  bool any_stddev = false, any_count = false, any_u = false, any_reversal = false;
  for (const auto& slot : at) {
    any_stddev = any_stddev || nodes[*slot].stddev_mm.has_value();
    any_count = any_count || nodes[*slot].count > 0;
    any_u = any_u || nodes[*slot].u_mm.has_value();
    any_reversal = any_reversal || nodes[*slot].reversal_mm.has_value();
  }
  for (const auto& slot : at) {
    const TableNode& node = nodes[*slot];
    table.error_mm.push_back(node.error_mm);
    table.origin.push_back(node.error_field);
    if (any_stddev) table.stddev_mm.push_back(node.stddev_mm);
    if (any_count) table.count.push_back(node.count);
    if (any_u) table.u_mm.push_back(node.u_mm);
    if (any_reversal) table.reversal_mm.push_back(node.reversal_mm);
  }
  return table;
}

// The check points of an assembled axis table: inside its grid's rectangle,
// away from the nodes, one per position; sorted by y, then x.
bool AddCheckPoints(AxisTable& table, TableAxis axis, const std::vector<TableNode>& nodes,
                    const std::vector<std::size_t>& checks, Diagnostics& diags) {
  const std::string_view name = AxisName(axis);
  const std::size_t errors_before = diags.error_count();
  std::map<std::pair<double, double>, std::size_t> seen;  // (y, x) -> index into nodes
  for (std::size_t k : checks) {
    const TableNode& check = nodes[k];
    const double x0 = table.xs.front(), x1 = table.xs.back(), y0 = table.ys.front(), y1 = table.ys.back();
    if (check.x_mm < x0 || check.x_mm > x1 || check.y_mm < y0 || check.y_mm > y1) {
      diags.Report(DiagKind::TableCheckOutsideGrid, check.x_field, FormatMm(check.x_mm), FormatMm(check.y_mm), name,
                   FormatMm(x0), FormatMm(x1), FormatMm(y0), FormatMm(y1));
      continue;
    }
    const CellPlace place = PlaceInCell(table, check.x_mm, check.y_mm);
    if (place.CentreShare() < kMinCheckPointShare) {
      const std::size_t i = place.i + (place.s > 0.5 ? 1 : 0), j = place.j + (place.t > 0.5 ? 1 : 0);
      const bool on = table.xs[i] == check.x_mm && table.ys[j] == check.y_mm;
      diags.Report(DiagKind::TableCheckNearNode, check.x_field, FormatMm(check.x_mm), FormatMm(check.y_mm), name,
                   on ? "on" : "too near", FormatMm(table.xs[i]), FormatMm(table.ys[j]),
                   fmt::format("{:.0f}", 100 * place.CentreShare()), fmt::format("{:.0f}", 100 * kMinCheckPointShare),
                   FormatComputedMm(0.5 * (table.xs[place.i] + table.xs[place.i + 1])),
                   FormatComputedMm(0.5 * (table.ys[place.j] + table.ys[place.j + 1])));
      continue;
    }
    auto [it, inserted] = seen.emplace(std::make_pair(check.y_mm, check.x_mm), k);
    if (!inserted) {
      const TableNode& first = nodes[it->second];
      Diagnostic* diag = diags.Report(DiagKind::TableDuplicateCheck, check.x_field, FormatMm(check.x_mm),
                                      FormatMm(check.y_mm), name, LineOf(first.x_field));
      Diagnostics::AddNote(diag, first.x_field, "first given here");
    }
  }
  if (diags.error_count() != errors_before) return false;
  for (const auto& [position, k] : seen) table.checks.push_back(nodes[k]);
  return true;
}

}  // namespace

std::optional<ErrorTable> AssembleErrorTable(std::string name, const std::vector<TableNode>& nodes,
                                             SourceLoc file, Diagnostics& diags) {
  ErrorTable table;
  table.name = std::move(name);
  bool ok = true;
  for (TableAxis axis : kTableAxes) {
    AxisAssembly assembly{axis, nodes, {}, diags};
    std::vector<std::size_t> checks;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      if (nodes[k].axis != axis) continue;
      (nodes[k].kind == ReadingKind::kNode ? assembly.members : checks).push_back(k);
    }
    if (assembly.members.empty()) {
      diags.Report(DiagKind::TableMissingAxis, SourceRange(SourceLoc{file.file, 0, 0}), AxisName(axis));
      ok = false;
      continue;
    }
    std::optional<AxisTable> axis_table = assembly.Run();
    if (!axis_table || !AddCheckPoints(*axis_table, axis, nodes, checks, diags)) {
      ok = false;
      continue;
    }
    table[axis] = std::move(*axis_table);
  }
  if (!ok) return std::nullopt;
  const AxisTable& tx = table[TableAxis::X];
  const AxisTable& ty = table[TableAxis::Y];
  Rect domain = TableDomain(table);
  if (!(domain.x0 < domain.x1 && domain.y0 < domain.y1)) {
    diags.Report(DiagKind::TableNoOverlap, ty.origin.front(), FormatMm(tx.xs.front()),
                 FormatMm(tx.xs.back()), FormatMm(tx.ys.front()), FormatMm(tx.ys.back()),
                 FormatMm(ty.xs.front()), FormatMm(ty.xs.back()), FormatMm(ty.ys.front()),
                 FormatMm(ty.ys.back()));
    return std::nullopt;
  }
  return table;
}

// ------------------------------------------------------------------ shape

bool HasUsableShape(const ErrorTable& table) {
  for (const AxisTable& t : table.axes) {
    if (t.nx() < 2 || t.ny() < 2) return false;
    if (t.error_mm.size() != t.nx() * t.ny()) return false;
    if (!t.stddev_mm.empty() && t.stddev_mm.size() != t.error_mm.size()) return false;
    if (!t.count.empty() && t.count.size() != t.error_mm.size()) return false;
    if (!t.u_mm.empty() && t.u_mm.size() != t.error_mm.size()) return false;
    if (!t.reversal_mm.empty() && t.reversal_mm.size() != t.error_mm.size()) return false;
    if (!t.origin.empty() && t.origin.size() != t.error_mm.size()) return false;
    // What keeps every slope, determinant and residual finite and accurate.
    auto length = [](double v) { return std::abs(v) <= kMaxLengthMm; };  // false for NaN
    for (const std::vector<double>* lines : {&t.xs, &t.ys}) {
      for (std::size_t i = 0; i < lines->size(); ++i) {
        if (!length((*lines)[i])) return false;
        if (i > 0 && !((*lines)[i] - (*lines)[i - 1] >= kMinGridLineSpacingMm)) return false;
      }
    }
    if (!std::all_of(t.error_mm.begin(), t.error_mm.end(), length)) return false;
  }
  Rect domain = TableDomain(table);
  return domain.x0 < domain.x1 && domain.y0 < domain.y1;
}

Rect TableDomain(const ErrorTable& table) {
  const AxisTable& tx = table[TableAxis::X];
  const AxisTable& ty = table[TableAxis::Y];
  SMTCAL_CHECK(!tx.xs.empty() && !tx.ys.empty() && !ty.xs.empty() && !ty.ys.empty(),
               "TableDomain of a table without grid lines");
  return Rect{std::max(tx.xs.front(), ty.xs.front()), std::min(tx.xs.back(), ty.xs.back()),
              std::max(tx.ys.front(), ty.ys.front()), std::min(tx.ys.back(), ty.ys.back())};
}

// ------------------------------------------------------------------ evaluation

int CalibrationMap::Lines::Cell(double v) const {
  // O(1) on (nearly) uniform grids: the mean pitch gives the cell or its
  // neighbour. Otherwise a binary search: O(log n).
  double guess = (v - origin) * cells_per_mm;
  int i = guess <= 0 ? 0 : guess >= last_cell ? last_cell : static_cast<int>(guess);
  if (i > 0 && v < lines[i]) --i;
  if (i < last_cell && v >= lines[i + 1]) ++i;
  if ((i > 0 && v < lines[i]) || (i < last_cell && v >= lines[i + 1])) {
    auto above = std::upper_bound(lines.begin() + 1, lines.end() - 1, v);
    i = static_cast<int>(above - lines.begin()) - 1;
  }
  return i;
}

CalibrationMap::CalibrationMap(const ErrorTable& table) {
  SMTCAL_CHECK(HasUsableShape(table), "CalibrationMap of a table that is not usable");
  auto make_lines = [](const std::vector<double>& lines) {
    Lines result;
    result.lines = lines;
    result.origin = lines.front();
    result.last_cell = static_cast<int>(lines.size()) - 2;
    result.cells_per_mm = static_cast<double>(lines.size() - 1) / (lines.back() - lines.front());
    return result;
  };
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    Axis& a = axes_[static_cast<int>(axis)];
    a.x = make_lines(t.xs);
    a.y = make_lines(t.ys);
    a.values = t.error_mm;
  }
  domain_ = TableDomain(table);
}

bool CalibrationMap::Inside(const Eigen::Vector2d& n) const {
  return n.x() >= domain_.x0 - kTableEdgeTolMm && n.x() <= domain_.x1 + kTableEdgeTolMm &&
         n.y() >= domain_.y0 - kTableEdgeTolMm && n.y() <= domain_.y1 + kTableEdgeTolMm;
}

Eigen::Vector2d CalibrationMap::ClampToDomain(const Eigen::Vector2d& n) const {
  return {std::clamp(n.x(), domain_.x0, domain_.x1), std::clamp(n.y(), domain_.y0, domain_.y1)};
}

double CalibrationMap::Evaluate(const Axis& a, double x, double y, double* ddx, double* ddy) {
  const int i = a.x.Cell(x);
  const int j = a.y.Cell(y);
  const double x0 = a.x.lines[i], hx = a.x.lines[i + 1] - x0;
  const double y0 = a.y.lines[j], hy = a.y.lines[j + 1] - y0;
  // Divisions, not multiplications by a stored inverse: s is exactly 0 or 1
  // on the cell's own lines, so every node's value comes back exactly.
  const double s = (x - x0) / hx;
  const double t = (y - y0) / hy;
  const std::size_t nx = a.x.lines.size();
  const double* row0 = &a.values[static_cast<std::size_t>(j) * nx + static_cast<std::size_t>(i)];
  const double* row1 = row0 + nx;
  const double v00 = row0[0], v10 = row0[1], v01 = row1[0], v11 = row1[1];
  const double bottom = (1 - s) * v00 + s * v10;
  const double top = (1 - s) * v01 + s * v11;
  if (ddx != nullptr) {
    *ddx = ((1 - t) * (v10 - v00) + t * (v11 - v01)) / hx;
    *ddy = (top - bottom) / hy;
  }
  return (1 - t) * bottom + t * top;
}

Eigen::Vector2d CalibrationMap::Delta(const Eigen::Vector2d& n) const {
  Eigen::Vector2d p = ClampToDomain(n);
  return {Evaluate(axes_[0], p.x(), p.y(), nullptr, nullptr),
          Evaluate(axes_[1], p.x(), p.y(), nullptr, nullptr)};
}

void CalibrationMap::DeltaAndJacobian(const Eigen::Vector2d& n, Eigen::Vector2d& delta,
                                      Eigen::Matrix2d& jacobian) const {
  Eigen::Vector2d p = ClampToDomain(n);
  double xx = 0, xy = 0, yx = 0, yy = 0;
  delta.x() = Evaluate(axes_[0], p.x(), p.y(), &xx, &xy);
  delta.y() = Evaluate(axes_[1], p.x(), p.y(), &yx, &yy);
  if (p.x() != n.x()) xx = yx = 0;
  if (p.y() != n.y()) xy = yy = 0;
  jacobian << xx, xy, yx, yy;
}

double CalibrationMap::AxisDelta(TableAxis axis, double x, double y) const {
  const Axis& a = axes_[static_cast<int>(axis)];
  x = std::clamp(x, a.x.lines.front(), a.x.lines.back());
  y = std::clamp(y, a.y.lines.front(), a.y.lines.back());
  return Evaluate(a, x, y, nullptr, nullptr);
}

double CalibrationMap::Node(TableAxis axis, std::size_t i, std::size_t j) const {
  const Axis& a = axes_[static_cast<int>(axis)];
  return a.values[j * a.x.lines.size() + i];
}

// ------------------------------------------------------------------ statistics

TableStats ComputeTableStats(const ErrorTable& table) {
  SMTCAL_CHECK(HasUsableShape(table), "statistics of a table that is not usable");
  TableStats stats;
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    AxisStats& s = stats.axes[static_cast<int>(axis)];
    s.nx = t.nx();
    s.ny = t.ny();
    s.min_mm = s.max_mm = t.At(0, 0);
    s.min_x = s.max_x = t.xs[0];
    s.min_y = s.max_y = t.ys[0];
    double sum = 0;
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) {
        double v = t.At(i, j);
        sum += v;
        if (v < s.min_mm) {
          s.min_mm = v;
          s.min_x = t.xs[i];
          s.min_y = t.ys[j];
        }
        if (v > s.max_mm) {
          s.max_mm = v;
          s.max_x = t.xs[i];
          s.max_y = t.ys[j];
        }
      }
    }
    s.mean_mm = sum / static_cast<double>(t.error_mm.size());
    s.abs_max_after_shift_mm = std::max(s.max_mm - s.mean_mm, s.mean_mm - s.min_mm);
    double stddev_sum = 0;
    for (const std::optional<double>& sd : t.stddev_mm) {
      if (!sd) continue;
      ++s.stddev_nodes;
      stddev_sum += *sd;
      s.stddev_max_mm = std::max(s.stddev_max_mm, *sd);
    }
    if (s.stddev_nodes > 0) s.stddev_mean_mm = stddev_sum / static_cast<double>(s.stddev_nodes);
    bool first = true;
    for (int n : t.count) {
      if (n <= 0) continue;
      s.count_min = first ? n : std::min(s.count_min, n);
      s.count_max = first ? n : std::max(s.count_max, n);
      first = false;
    }
  }
  stats.shift_x_mm = stats.axes[0].mean_mm;
  stats.shift_y_mm = stats.axes[1].mean_mm;
  return stats;
}

}  // namespace smtcal
