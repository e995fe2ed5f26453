// Validation of an assembled error table (see error_table_check.h for the
// math). Assumes HasUsableShape; guarantees, when it returns true, that
// det(I + grad Delta) >= kMinJacobianDet and |grad Delta|_inf <= kMaxErrorSlope
// everywhere in the domain, which is what the inverse solvers rely on.
#include "calibration/error_table_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/table_outliers.h"
#include "calibration/tolerances.h"

namespace smtcal {
namespace {

// The cell of `lines` that holds v (cells are [lines[i], lines[i+1]]).
std::size_t CellIndex(const std::vector<double>& lines, double v) {
  auto it = std::upper_bound(lines.begin(), lines.end(), v);
  std::size_t i = it == lines.begin() ? 0 : static_cast<std::size_t>(it - lines.begin()) - 1;
  return std::min(i, lines.size() - 2);
}

// grad of one axis table's bilinear piece of cell (i, j), at (x, y) on or in
// that cell: (d/dx, d/dy).
Eigen::Vector2d CellGradient(const AxisTable& t, std::size_t i, std::size_t j, double x, double y) {
  const double hx = t.xs[i + 1] - t.xs[i], hy = t.ys[j + 1] - t.ys[j];
  const double s = (x - t.xs[i]) / hx, u = (y - t.ys[j]) / hy;
  const double v00 = t.At(i, j), v10 = t.At(i + 1, j), v01 = t.At(i, j + 1), v11 = t.At(i + 1, j + 1);
  return {((1 - u) * (v10 - v00) + u * (v11 - v01)) / hx, ((1 - s) * (v01 - v00) + s * (v11 - v10)) / hy};
}

// The union of both tables' lines along one coordinate, clipped to [lo, hi].
std::vector<double> UnionLines(const std::vector<double>& a, const std::vector<double>& b, double lo,
                               double hi) {
  std::vector<double> lines = {lo, hi};
  for (const std::vector<double>* source : {&a, &b}) {
    for (double v : *source) {
      if (v > lo && v < hi) lines.push_back(v);
    }
  }
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  return lines;
}

std::string Fixed(double v, int decimals) {
  if (std::abs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0;  // no "-0.0000"
  return fmt::format("{:.{}f}", v, decimals);
}
// An error value in mm, as the tables write it (6 decimals), with its sign.
std::string Signed(double mm) { return (mm >= 0 ? "+" : "") + Fixed(mm, 6); }

// The node (of either axis table) among the piece's cells with the largest
// |value|: where a unit blunder most likely is.
SourceRange SuspectNode(const ErrorTable& table, const PieceBound& piece) {
  SourceRange best;
  double largest = -1;
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    int a = static_cast<int>(axis);
    for (std::size_t dj = 0; dj < 2; ++dj) {
      for (std::size_t di = 0; di < 2; ++di) {
        std::size_t i = piece.cell_i[a] + di, j = piece.cell_j[a] + dj;
        if (std::abs(t.At(i, j)) > largest) {
          largest = std::abs(t.At(i, j));
          best = t.Origin(i, j);
        }
      }
    }
  }
  return best;
}

// "3 more cells fold or nearly fold", as a note at the file's name.
void AddMoreCellsNote(Diagnostic* diag, const SourceRange& suspect, std::size_t more, const char* one,
                      const char* many) {
  if (more == 0) return;
  Diagnostics::AddNote(diag, SourceRange(SourceLoc{suspect.begin.file, 0, 0}),
                       fmt::format("{} more {} {}", more, more == 1 ? "cell" : "cells", more == 1 ? one : many));
}

void ReportFolds(const ErrorTable& table, const TableAnalysis& analysis, Diagnostics& diags) {
  const PieceBound* worst = nullptr;
  std::size_t failing = 0;
  for (const PieceBound& piece : analysis.pieces) {
    if (piece.min_det >= kMinJacobianDet) continue;
    ++failing;
    if (worst == nullptr || piece.min_det < worst->min_det) worst = &piece;
  }
  if (worst == nullptr) return;
  const Eigen::Matrix2d& g = worst->slopes_at_min_det;
  const SourceRange suspect = SuspectNode(table, *worst);
  Diagnostic* diag = diags.Report(
      DiagKind::TableFolds, suspect, worst->min_det <= 0 ? "folds" : "nearly folds",
      FormatMm(worst->piece.x0), FormatMm(worst->piece.x1), FormatMm(worst->piece.y0),
      FormatMm(worst->piece.y1), Fixed(worst->min_det, 3), FormatMm(worst->min_det_at.x()),
      FormatMm(worst->min_det_at.y()), Fixed(kMinJacobianDet, 1), Fixed(g(0, 0), 4), Fixed(g(0, 1), 4),
      Fixed(g(1, 0), 4), Fixed(g(1, 1), 4));
  AddMoreCellsNote(diag, suspect, failing - 1, "folds or nearly folds", "fold or nearly fold");
}

void ReportSteep(const ErrorTable& table, const TableAnalysis& analysis, Diagnostics& diags) {
  const PieceBound* worst = nullptr;
  std::size_t failing = 0;
  for (const PieceBound& piece : analysis.pieces) {
    if (piece.max_row_slope <= kMaxErrorSlope) continue;
    ++failing;
    if (worst == nullptr || piece.max_row_slope > worst->max_row_slope) worst = &piece;
  }
  if (worst == nullptr) return;
  const Eigen::Matrix2d& g = worst->slopes_at_max;
  std::string_view axis = AxisName(static_cast<TableAxis>(worst->steepest_axis));
  const SourceRange suspect = SuspectNode(table, *worst);
  Diagnostic* diag = diags.Report(
      DiagKind::TableTooSteep, suspect, axis, FormatMm(worst->piece.x0),
      FormatMm(worst->piece.x1), FormatMm(worst->piece.y0), FormatMm(worst->piece.y1), axis, axis,
      Fixed(worst->max_row_slope, 4), Fixed(kMaxErrorSlope, 1), Fixed(g(0, 0), 4), Fixed(g(0, 1), 4),
      Fixed(g(1, 0), 4), Fixed(g(1, 1), 4));
  AddMoreCellsNote(diag, suspect, failing - 1, "is too steep", "are too steep");
}

void WarnSignChanges(const ErrorTable& table, const std::vector<SignChangeFinding>& findings, Diagnostics& diags) {
  for (const SignChangeFinding& f : findings) {
    const AxisTable& t = table[f.axis];
    Diagnostic* diag = diags.Report(
        DiagKind::TableSignChange, t.Origin(f.i, f.j), AxisName(f.axis),
        fmt::format("{} {}", f.pairs, f.pairs == 1 ? "pair" : "pairs"), Signed(t.At(f.i, f.j)), FormatMm(t.xs[f.i]),
        FormatMm(t.ys[f.j]), Signed(t.At(f.i2, f.j2)), FormatMm(t.xs[f.i2]), FormatMm(t.ys[f.j2]));
    Diagnostics::AddNote(diag, t.Origin(f.i2, f.j2), "the neighbouring node");
  }
}

std::string MoreNodes(std::size_t count) {
  return count > 1 ? fmt::format(" (and {} more {} of this table)", count - 1, count == 2 ? "node" : "nodes") : "";
}

void WarnOverHalfPitch(const ErrorTable& table, const std::vector<OverHalfPitchFinding>& findings,
                       Diagnostics& diags) {
  for (const OverHalfPitchFinding& f : findings) {
    const AxisTable& t = table[f.axis];
    diags.Report(DiagKind::TableErrorOverHalfPitch, t.Origin(f.i, f.j), AxisName(f.axis), Signed(t.At(f.i, f.j)),
                 FormatMm(t.xs[f.i]), FormatMm(t.ys[f.j]), FormatMm(f.pitch_mm), MoreNodes(f.count));
  }
}

void ReportOutliers(const ErrorTable& table, const std::vector<TableOutlier>& outliers, Diagnostics& diags) {
  for (const TableOutlier& outlier : outliers) {
    const AxisTable& t = table[outlier.axis];
    diags.Report(DiagKind::TableOutlierNode, t.Origin(outlier.i, outlier.j), AxisName(outlier.axis),
                 Signed(outlier.value_mm), FormatMm(t.xs[outlier.i]), FormatMm(t.ys[outlier.j]),
                 Signed(outlier.predicted_mm), fmt::format("{:.4f}", outlier.scatter_mm),
                 outlier.likely_slip.empty() ? std::string("a typo or a bad measurement") : outlier.likely_slip);
  }
}

}  // namespace

TableWarningFindings FindTableWarnings(const ErrorTable& table, const std::vector<TableOutlier>& outliers) {
  TableWarningFindings findings;
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    // A node reported as an outlier is left out: its slip is reported once,
    // as what it is, and never again as a sign change or a large error.
    std::vector<bool> skip(t.error_mm.size(), false);
    for (const TableOutlier& o : outliers) {
      if (o.axis == axis) skip[t.Index(o.i, o.j)] = true;
    }
    // A node's value is "clearly of its sign" when it is farther from zero
    // than kSignChangeMinMm and three of its standard errors: smaller values
    // are noise around zero, where the paper's condition says nothing.
    auto clear = [&](std::size_t i, std::size_t j) {
      const double se = t.StandardErrorMm(t.Index(i, j)).value_or(0.0);
      return std::abs(t.At(i, j)) > std::max(kSignChangeMinMm, 3 * se);
    };
    SignChangeFinding sign{axis};
    auto visit = [&](std::size_t i, std::size_t j, std::size_t i2, std::size_t j2) {
      if (skip[t.Index(i, j)] || skip[t.Index(i2, j2)]) return;
      if (!(t.At(i, j) * t.At(i2, j2) < 0) || !clear(i, j) || !clear(i2, j2)) return;
      if (sign.pairs++ == 0) sign.i = i, sign.j = j, sign.i2 = i2, sign.j2 = j2;
    };
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) {
        if (i + 1 < t.nx()) visit(i, j, i + 1, j);
        if (j + 1 < t.ny()) visit(i, j, i, j + 1);
      }
    }
    if (sign.pairs > 0) findings.sign_changes.push_back(sign);

    OverHalfPitchFinding over{axis};
    double worst_ratio = 0;
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) {
        if (skip[t.Index(i, j)]) continue;
        double pitch = std::numeric_limits<double>::infinity();
        if (i > 0) pitch = std::min(pitch, t.xs[i] - t.xs[i - 1]);
        if (i + 1 < t.nx()) pitch = std::min(pitch, t.xs[i + 1] - t.xs[i]);
        if (j > 0) pitch = std::min(pitch, t.ys[j] - t.ys[j - 1]);
        if (j + 1 < t.ny()) pitch = std::min(pitch, t.ys[j + 1] - t.ys[j]);
        double ratio = std::abs(t.At(i, j)) / pitch;
        if (ratio <= kMaxErrorPitchFraction) continue;
        ++over.count;
        if (ratio > worst_ratio) worst_ratio = ratio, over.pitch_mm = pitch, over.i = i, over.j = j;
      }
    }
    if (over.count > 0) findings.over_half_pitch.push_back(over);
  }
  return findings;
}

std::vector<std::string> SummarizeTableWarnings(const ErrorTable& table) {
  const TableWarningFindings findings = FindTableWarnings(table);
  std::vector<std::string> lines;
  for (const SignChangeFinding& f : findings.sign_changes) {
    const AxisTable& t = table[f.axis];
    lines.push_back(fmt::format("Δ{} changes sign between {} {} of neighbouring nodes (first at ({}, {}))",
                                AxisName(f.axis), f.pairs, f.pairs == 1 ? "pair" : "pairs", FormatMm(t.xs[f.i]),
                                FormatMm(t.ys[f.j])));
  }
  for (const OverHalfPitchFinding& f : findings.over_half_pitch) {
    const AxisTable& t = table[f.axis];
    lines.push_back(fmt::format("Δ{} = {} mm at ({}, {}) is more than half the grid pitch{}", AxisName(f.axis),
                                Signed(t.At(f.i, f.j)), FormatMm(t.xs[f.i]), FormatMm(t.ys[f.j]), MoreNodes(f.count)));
  }
  return lines;
}

TableAnalysis AnalyzeTable(const ErrorTable& table) {
  SMTCAL_CHECK(HasUsableShape(table), "AnalyzeTable of a table that is not usable");
  TableAnalysis analysis;
  const AxisTable& tx = table[TableAxis::X];
  const AxisTable& ty = table[TableAxis::Y];
  for (const AxisTable* t : {&tx, &ty}) {
    for (double v : t->error_mm) analysis.max_abs_error_mm = std::max(analysis.max_abs_error_mm, std::abs(v));
  }
  Rect domain = TableDomain(table);
  std::vector<double> xs = UnionLines(tx.xs, ty.xs, domain.x0, domain.x1);
  std::vector<double> ys = UnionLines(tx.ys, ty.ys, domain.y0, domain.y1);
  analysis.min_jacobian_det = std::numeric_limits<double>::infinity();
  for (std::size_t b = 0; b + 1 < ys.size(); ++b) {
    for (std::size_t a = 0; a + 1 < xs.size(); ++a) {
      PieceBound piece;
      piece.piece = Rect{xs[a], xs[a + 1], ys[b], ys[b + 1]};
      const double xm = 0.5 * (xs[a] + xs[a + 1]), ym = 0.5 * (ys[b] + ys[b + 1]);
      for (TableAxis axis : kTableAxes) {
        int k = static_cast<int>(axis);
        piece.cell_i[k] = CellIndex(table[axis].xs, xm);
        piece.cell_j[k] = CellIndex(table[axis].ys, ym);
      }
      piece.min_det = std::numeric_limits<double>::infinity();
      piece.max_row_slope = -1;
      for (double y : {ys[b], ys[b + 1]}) {
        for (double x : {xs[a], xs[a + 1]}) {
          Eigen::Vector2d gx = CellGradient(tx, piece.cell_i[0], piece.cell_j[0], x, y);
          Eigen::Vector2d gy = CellGradient(ty, piece.cell_i[1], piece.cell_j[1], x, y);
          Eigen::Matrix2d g;
          g << gx.x(), gx.y(), gy.x(), gy.y();
          double det = (1 + g(0, 0)) * (1 + g(1, 1)) - g(0, 1) * g(1, 0);
          if (det < piece.min_det) {
            piece.min_det = det;
            piece.min_det_at = {x, y};
            piece.slopes_at_min_det = g;
          }
          for (int row = 0; row < 2; ++row) {
            double slope = std::abs(g(row, 0)) + std::abs(g(row, 1));
            if (slope > piece.max_row_slope) {
              piece.max_row_slope = slope;
              piece.steepest_axis = row;
              piece.slopes_at_max = g;
            }
          }
        }
      }
      analysis.min_jacobian_det = std::min(analysis.min_jacobian_det, piece.min_det);
      analysis.contraction = std::max(analysis.contraction, piece.max_row_slope);
      analysis.pieces.push_back(piece);
    }
  }
  return analysis;
}

bool ValidateErrorTable(const ErrorTable& table, Diagnostics& diags, TableWarnings warnings,
                        TableAnalysis* analysis_out) {
  std::size_t errors_before = diags.error_count();
  const std::vector<TableOutlier> outliers = FindTableOutliers(table);
  ReportOutliers(table, outliers, diags);
  // The fold and slope checks look at the table with its outliers repaired:
  // a slipped node folds the map around it, and that is the slip, reported
  // once above. A fold that remains is a problem of its own.
  const ErrorTable repaired = outliers.empty() ? ErrorTable() : WithOutliersRepaired(table, outliers);
  const ErrorTable& checked = outliers.empty() ? table : repaired;
  TableAnalysis analysis = AnalyzeTable(checked);
  const std::size_t before_folds = diags.error_count();
  ReportFolds(checked, analysis, diags);
  // A folding table is also steep; its fold is the message that matters.
  if (diags.error_count() == before_folds) ReportSteep(checked, analysis, diags);
  if (warnings == TableWarnings::kReport) {
    const TableWarningFindings findings = FindTableWarnings(table, outliers);
    WarnSignChanges(table, findings.sign_changes, diags);
    WarnOverHalfPitch(table, findings.over_half_pitch, diags);
  }
  bool ok = diags.error_count() == errors_before;
  if (analysis_out != nullptr) *analysis_out = std::move(analysis);
  return ok;
}

}  // namespace smtcal
