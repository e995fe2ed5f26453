// The interpolation error between an error table's nodes
// (calibration/interpolation_error.h). Assumes a table with
// HasUsableShape whose check points lie in their axis's grid rectangle
// (AssembleErrorTable's guarantee); guarantees finite, non-negative figures.
#include "calibration/interpolation_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "base/check.h"

namespace smtcal {
namespace {

// The cell index i with lines[i] <= v <= lines[i+1] (the last cell includes its end).
std::size_t CellOf(const std::vector<double>& lines, double v) {
  auto above = std::upper_bound(lines.begin(), lines.end(), v);
  std::size_t i = above == lines.begin() ? 0 : static_cast<std::size_t>(above - lines.begin()) - 1;
  return std::min(i, lines.size() - 2);
}

// The second derivative along one grid direction at an interior node, from
// its two neighbours (unequal pitches allowed); `at(k)` is the value at line k.
template <typename At>
double SecondDerivative(const std::vector<double>& lines, std::size_t k, At at) {
  const double left = lines[k] - lines[k - 1], right = lines[k + 1] - lines[k];
  return 2 * ((at(k + 1) - at(k)) / right - (at(k) - at(k - 1)) / left) / (left + right);
}

// The largest |f''| along x at the nodes of cell i..i+1 on row j (the
// interior ones; the nearest interior node when both are on the edge).
// 0 when the grid has only two lines along x: there is nothing to see.
double CurvatureAlong(const std::vector<double>& lines, std::size_t cell, const std::vector<double>& second) {
  if (lines.size() < 3) return 0;
  double largest = 0;
  for (std::size_t k : {cell, cell + 1}) {
    const std::size_t interior = std::clamp<std::size_t>(k, 1, lines.size() - 2);
    largest = std::max(largest, std::abs(second[interior]));
  }
  return largest;
}

// The amplitude of the largest wave of the declared roughness's wavelength
// (at most its accuracy A) that an axis table's nodes could still hide: along
// a line of n nodes at pitch h, a wave a cos(k x + phase) shows the second
// difference a 2 (1 - cos(k h)) |cos(phase at the node)| at each of the n - 2
// interior nodes, whose phases span W = (n - 3) k h; over that span the
// largest |cos| is at least sin(min(W, pi) / 2). A wave running diagonally
// shows in both directions with k^2 halved at most, hence the factor 2.
// `largest_second` is the table's largest |second difference| per direction
// (in mm, along its largest pitch `pitch`), `lines` its number of lines.
double HiddenAmplitude(const DeclaredRoughness& roughness, const std::array<double, 2>& largest_second,
                       const std::array<double, 2>& pitch, const std::array<std::size_t, 2>& lines) {
  const double k = 2 * std::numbers::pi / (kRoughnessWavelengthPerCorrelation * roughness.correlation_mm);
  double amplitude = 0;
  for (std::size_t d = 0; d < 2; ++d) {
    const double span = lines[d] >= 3 ? static_cast<double>(lines[d] - 3) * k * pitch[d] : 0;
    const double shown = 2 * (1 - std::cos(std::min(k * pitch[d], std::numbers::pi))) *
                         std::sin(std::min(span, std::numbers::pi) / 2);
    if (!(shown > 0)) return roughness.accuracy_mm;  // a wave along this direction may hide entirely
    amplitude = std::max(amplitude, 2 * largest_second[d] / shown);
  }
  return std::min(amplitude, roughness.accuracy_mm);
}

// A wave a cos(2 pi x / lambda) with its crest at a cell's centre departs
// from the line through the cell's ends by a (1 - cos(pi h / lambda)); at
// h >= lambda anything up to the whole range 2a.
double DeclaredFigure(const DeclaredRoughness& roughness, double amplitude_mm, double pitch_mm) {
  const double wavelength = kRoughnessWavelengthPerCorrelation * roughness.correlation_mm;
  const double phase = std::min(std::numbers::pi * pitch_mm / wavelength, std::numbers::pi);
  return amplitude_mm * (1 - std::cos(phase));
}

// The standard error of a point's mean: the pooled reading scatter over the
// square root of its count; a point that states no count is one reading (of
// the pooled scatter, else `unknown_noise_mm`).
double PointNoiseMm(int count, const std::optional<double>& pooled, double unknown_noise_mm) {
  if (!pooled) return unknown_noise_mm;
  return count > 0 ? *pooled / std::sqrt(static_cast<double>(count)) : *pooled;
}

// The noise of the bilinear interpolation at a point from its cell's nodes.
double InterpolationNoiseMm(const AxisTable& t, const CellPlace& p, const std::optional<double>& pooled,
                            double unknown_noise_mm) {
  double variance = 0;
  for (std::size_t b = 0; b < 2; ++b) {
    for (std::size_t a = 0; a < 2; ++a) {
      const double weight = (a == 1 ? p.s : 1 - p.s) * (b == 1 ? p.t : 1 - p.t);
      const std::size_t k = t.Index(p.i + a, p.j + b);
      const double se = PointNoiseMm(k < t.count.size() ? t.count[k] : 0, pooled, unknown_noise_mm);
      variance += weight * weight * se * se;
    }
  }
  return std::sqrt(variance);
}

// A check point within this of its cell's centre along both axes (p and q at
// least this) tells the centre's departure A + B.
constexpr double kCentreShare = 0.99;

// The quadratic model's largest departure in a cell, max(|A|, |B|, |A + B|),
// given a check point's residual r at shares p = 4 s(1-s), q = 4 t(1-t) and
// the curvature figures |A| <= cx, |B| <= cy (docs: "Between the nodes").
double CheckFigure(double residual, double p, double q, double cx, double cy) {
  const double phi = std::max(0.5 * (p + q), kMinCheckPointShare);
  const double centre = std::abs(residual) / phi;
  if (p >= kCentreShare && q >= kCentreShare && centre <= cx + cy) {
    return std::max({centre, std::min(cx, centre + cy), std::min(cy, centre + cx)});
  }
  return std::max(centre, cx + cy);
}

AxisInterpolation EstimateAxis(const AxisTable& t, const std::optional<DeclaredRoughness>& roughness,
                               double unknown_noise_mm) {
  AxisInterpolation result;
  const std::size_t nx = t.nx(), ny = t.ny();
  result.xs = t.xs;
  result.ys = t.ys;
  result.reading_scatter_mm = PooledReadingScatterMm(t);
  const std::optional<double>& pooled = result.reading_scatter_mm;
  // Second derivatives at interior nodes: along x per row, along y per column.
  std::vector<std::vector<double>> fxx(ny, std::vector<double>(nx, 0.0));
  std::vector<std::vector<double>> fyy(nx, std::vector<double>(ny, 0.0));
  for (std::size_t j = 0; j < ny; ++j) {
    for (std::size_t i = 1; i + 1 < nx; ++i) {
      fxx[j][i] = SecondDerivative(t.xs, i, [&](std::size_t k) { return t.At(k, j); });
    }
  }
  for (std::size_t i = 0; i < nx; ++i) {
    for (std::size_t j = 1; j + 1 < ny; ++j) {
      fyy[i][j] = SecondDerivative(t.ys, j, [&](std::size_t k) { return t.At(i, k); });
    }
  }
  // The largest |second difference| along each direction at its largest
  // pitch, for the declared roughness's hidden wave.
  std::array<double, 2> largest_second{0, 0}, largest_pitch{0, 0};
  for (std::size_t i = 0; i + 1 < nx; ++i) largest_pitch[0] = std::max(largest_pitch[0], t.xs[i + 1] - t.xs[i]);
  for (std::size_t j = 0; j + 1 < ny; ++j) largest_pitch[1] = std::max(largest_pitch[1], t.ys[j + 1] - t.ys[j]);
  for (const auto& row : fxx) {
    for (double f : row) largest_second[0] = std::max(largest_second[0], std::abs(f) * largest_pitch[0] * largest_pitch[0]);
  }
  for (const auto& column : fyy) {
    for (double f : column) largest_second[1] = std::max(largest_second[1], std::abs(f) * largest_pitch[1] * largest_pitch[1]);
  }
  const double hidden =
      roughness ? HiddenAmplitude(*roughness, largest_second, largest_pitch, {nx, ny}) : 0.0;
  // Each cell's curvature figures along x and y.
  const std::size_t cells = (nx - 1) * (ny - 1);
  std::vector<double> cx(cells), cy(cells);
  for (std::size_t j = 0; j + 1 < ny; ++j) {
    for (std::size_t i = 0; i + 1 < nx; ++i) {
      const double hx = t.xs[i + 1] - t.xs[i], hy = t.ys[j + 1] - t.ys[j];
      double cxx = 0, cyy = 0;
      for (std::size_t row : {j, j + 1}) cxx = std::max(cxx, CurvatureAlong(t.xs, i, fxx[row]));
      for (std::size_t column : {i, i + 1}) cyy = std::max(cyy, CurvatureAlong(t.ys, j, fyy[column]));
      cx[j * (nx - 1) + i] = hx * hx / 8 * cxx;
      cy[j * (nx - 1) + i] = hy * hy / 8 * cyy;
    }
  }
  // Each check point's residual, its noise (at the cell's centre) and its
  // quadratic-model figure.
  struct Check {
    const TableNode* node;
    std::size_t cell;
    double residual, noise, figure;
  };
  std::vector<Check> seen;
  for (const TableNode& check : t.checks) {
    const CellPlace place = PlaceInCell(t, check.x_mm, check.y_mm);
    const std::size_t c = place.j * (nx - 1) + place.i;
    const double residual = check.error_mm - Interpolate(t, check.x_mm, check.y_mm);
    const double own = PointNoiseMm(check.count, pooled, unknown_noise_mm);
    const double phi = std::max(place.CentreShare(), kMinCheckPointShare);
    const double noise = std::hypot(own, InterpolationNoiseMm(t, place, pooled, unknown_noise_mm)) / phi;
    const double p = 4 * place.s * (1 - place.s), q = 4 * place.t * (1 - place.t);
    seen.push_back({&check, c, residual, noise, CheckFigure(residual, p, q, cx[c], cy[c])});
  }
  result.margin = kCheckPointMargin;
  // The check-point figure of each cell that has one (the largest of its
  // check points') and its noise.
  std::vector<std::optional<double>> checked(cells);
  std::vector<double> checked_noise(cells, 0.0);
  std::vector<const TableNode*> checked_by(cells);
  for (const Check& check : seen) {
    const std::size_t c = check.cell;
    const double figure = result.margin * check.figure, figure_noise = result.margin * check.noise;
    if (!checked[c] || figure > *checked[c]) {
      checked[c] = figure;
      checked_by[c] = check.node;
    }
    checked_noise[c] = std::max(checked_noise[c], figure_noise);
    result.largest_residual_mm = std::max(result.largest_residual_mm, std::abs(check.residual));
    result.check_points_mm = std::max(result.check_points_mm.value_or(0.0), figure);
    result.noise_mm = std::max(result.noise_mm, figure_noise);
    ++result.check_points;
  }
  result.pitch_mm = std::max(largest_pitch[0], largest_pitch[1]);
  result.cell_bound_mm.assign(cells, 0.0);
  result.cell_noise_mm.assign(cells, 0.0);

  auto consider = [&](double figure, InterpolationKind kind, const Eigen::Vector2d& at, const SourceRange& origin) {
    if (figure > result.estimate_mm || result.cells == 0) {
      result.estimate_mm = figure;
      result.kind = kind;
      result.at = at;
      result.origin = origin;
    }
  };
  for (std::size_t j = 0; j + 1 < ny; ++j) {
    for (std::size_t i = 0; i + 1 < nx; ++i) {
      const std::size_t c = j * (nx - 1) + i;
      const double hx = t.xs[i + 1] - t.xs[i], hy = t.ys[j + 1] - t.ys[j];
      const Eigen::Vector2d centre(0.5 * (t.xs[i] + t.xs[i + 1]), 0.5 * (t.ys[j] + t.ys[j + 1]));
      const double curvature = cx[c] + cy[c];
      result.curvature_mm = std::max(result.curvature_mm, curvature);
      double& bound = result.cell_bound_mm[c];
      if (checked[c]) {
        const TableNode& by = *checked_by[c];
        ++result.checked_cells;
        bound = *checked[c];
        result.cell_noise_mm[c] = checked_noise[c];
        consider(bound, InterpolationKind::kCheckPoints, {by.x_mm, by.y_mm}, by.error_field);
      } else {
        bound = curvature;
        consider(curvature, InterpolationKind::kCurvature, centre, t.Origin(i, j));
        if (roughness) {
          const double declared = DeclaredFigure(*roughness, hidden, std::max(hx, hy));
          result.declared_mm = std::max(result.declared_mm.value_or(0.0), declared);
          bound = std::max(bound, declared);
          consider(declared, InterpolationKind::kDeclared, centre, t.Origin(i, j));
        }
      }
      ++result.cells;
    }
  }
  return result;
}

}  // namespace

std::string_view InterpolationKindName(InterpolationKind kind) {
  switch (kind) {
    case InterpolationKind::kCheckPoints: return "check_points";
    case InterpolationKind::kCurvature: return "curvature";
    case InterpolationKind::kDeclared: return "declared_roughness";
  }
  return "?";
}

std::string_view InterpolationKindShortName(InterpolationKind kind) {
  switch (kind) {
    case InterpolationKind::kCheckPoints: return "check points";
    case InterpolationKind::kCurvature: return "curvature, a lower bound";
    case InterpolationKind::kDeclared: return "declared roughness";
  }
  return "?";
}

std::string_view InterpolationKindDescription(InterpolationKind kind) {
  switch (kind) {
    case InterpolationKind::kCheckPoints: return "from check points";
    case InterpolationKind::kCurvature:
      return "from the table's curvature (a lower bound: it cannot see what the grid aliases)";
    case InterpolationKind::kDeclared:
      return "from the robot's declared roughness (robot.uncalibrated_accuracy_mm over 3 x "
             "uncalibrated_correlation_mm), which the nodes cannot rule out";
  }
  return "?";
}

CellPlace PlaceInCell(const AxisTable& table, double x, double y) {
  SMTCAL_CHECK(table.nx() >= 2 && table.ny() >= 2, "PlaceInCell of a table without cells");
  CellPlace place;
  place.i = CellOf(table.xs, x);
  place.j = CellOf(table.ys, y);
  place.s = std::clamp((x - table.xs[place.i]) / (table.xs[place.i + 1] - table.xs[place.i]), 0.0, 1.0);
  place.t = std::clamp((y - table.ys[place.j]) / (table.ys[place.j + 1] - table.ys[place.j]), 0.0, 1.0);
  return place;
}

double Interpolate(const AxisTable& table, double x, double y) {
  const CellPlace p = PlaceInCell(table, x, y);
  const double v00 = table.At(p.i, p.j), v10 = table.At(p.i + 1, p.j);
  const double v01 = table.At(p.i, p.j + 1), v11 = table.At(p.i + 1, p.j + 1);
  return (1 - p.t) * ((1 - p.s) * v00 + p.s * v10) + p.t * ((1 - p.s) * v01 + p.s * v11);
}

std::optional<double> PooledReadingScatterMm(const AxisTable& table) {
  double squares = 0, dof = 0;
  auto add = [&](const std::optional<double>& stddev, int count) {
    if (!stddev || count < 2) return;
    squares += (count - 1) * *stddev * *stddev;
    dof += count - 1;
  };
  for (std::size_t k = 0; k < table.error_mm.size(); ++k) {
    add(k < table.stddev_mm.size() ? table.stddev_mm[k] : std::nullopt, k < table.count.size() ? table.count[k] : 0);
  }
  for (const TableNode& check : table.checks) add(check.stddev_mm, check.count);
  if (!(dof > 0)) return std::nullopt;
  return std::sqrt(squares / dof);
}

LocalInterpolation AxisInterpolation::Over(const Rect& box) const {
  LocalInterpolation local;
  if (xs.size() < 2 || ys.size() < 2 || cell_bound_mm.empty()) return local;
  const std::size_t i0 = CellOf(xs, std::clamp(box.x0, xs.front(), xs.back()));
  const std::size_t i1 = CellOf(xs, std::clamp(box.x1, xs.front(), xs.back()));
  const std::size_t j0 = CellOf(ys, std::clamp(box.y0, ys.front(), ys.back()));
  const std::size_t j1 = CellOf(ys, std::clamp(box.y1, ys.front(), ys.back()));
  // And one ring of cells around them: on a grid that is coarse for the
  // field a cell's own evidence can miss a departure its neighbours see.
  const std::size_t nx = xs.size() - 1, ny = ys.size() - 1;
  const std::size_t ilo = std::min(i0, i1) > 0 ? std::min(i0, i1) - 1 : 0, ihi = std::min(std::max(i0, i1) + 1, nx - 1);
  const std::size_t jlo = std::min(j0, j1) > 0 ? std::min(j0, j1) - 1 : 0, jhi = std::min(std::max(j0, j1) + 1, ny - 1);
  for (std::size_t j = jlo; j <= jhi; ++j) {
    for (std::size_t i = ilo; i <= ihi; ++i) {
      const std::size_t c = j * nx + i;
      local.bound_mm = std::max(local.bound_mm, cell_bound_mm[c]);
      local.noise_mm = std::max(local.noise_mm, cell_noise_mm[c]);
    }
  }
  return local;
}

InterpolationEstimate EstimateInterpolationError(const ErrorTable& table,
                                                 const std::optional<DeclaredRoughness>& roughness,
                                                 double unknown_noise_mm) {
  SMTCAL_CHECK(HasUsableShape(table), "EstimateInterpolationError of a table that is not usable");
  InterpolationEstimate estimate;
  for (TableAxis axis : kTableAxes) {
    estimate.axes[static_cast<int>(axis)] = EstimateAxis(table[axis], roughness, unknown_noise_mm);
  }
  return estimate;
}

double PitchForShare(double pitch_mm, double part_mm, double allowed_mm) {
  if (!(allowed_mm > 0)) return 0;
  if (!(part_mm > allowed_mm)) return pitch_mm;
  return std::floor(10 * pitch_mm * std::sqrt(allowed_mm / part_mm)) / 10;
}

double PlannedInterpolationMm(const DeclaredRoughness& roughness, double pitch_mm) {
  return std::numbers::sqrt2 * DeclaredFigure(roughness, roughness.accuracy_mm, pitch_mm);
}

double PlannedPitchMm(const DeclaredRoughness& roughness, double tolerance_mm) {
  const double allowed = kInterpolationShareOfTolerance * tolerance_mm;
  // Per axis: A (1 - cos(pi h / 3L)) <= allowed / sqrt(2).
  const double cosine = 1 - allowed / (std::numbers::sqrt2 * roughness.accuracy_mm);
  if (!(cosine > -1)) return std::numeric_limits<double>::infinity();
  const double wavelength = kRoughnessWavelengthPerCorrelation * roughness.correlation_mm;
  return std::floor(10 * wavelength / std::numbers::pi * std::acos(cosine)) / 10;
}

GridAdvice AdviseGrid(const InterpolationEstimate& estimate, double tolerance_mm) {
  GridAdvice advice;
  const double norm = estimate.NormMm();
  advice.share = tolerance_mm > 0 ? norm / tolerance_mm : 0;
  advice.coarse = advice.share > kInterpolationShareOfTolerance;
  if (!advice.coarse) return advice;
  const double allowed = kInterpolationShareOfTolerance * tolerance_mm;
  advice.pitch_mm = PitchForShare(estimate.PitchMm(), norm, allowed);
  // Without the declared figure, would the table's own evidence fit?
  const Eigen::Vector2d evidence(std::max(estimate.axes[0].curvature_mm, estimate.axes[0].check_points_mm.value_or(0)),
                                 std::max(estimate.axes[1].curvature_mm, estimate.axes[1].check_points_mm.value_or(0)));
  advice.check_points_would_settle = estimate.Kind() == InterpolationKind::kDeclared && evidence.norm() <= allowed;
  return advice;
}

void ReportCoarseGrid(const InterpolationEstimate& estimate, double tolerance_mm, std::string_view subject,
                      const SourceRange& where, Diagnostics& diags) {
  const GridAdvice advice = AdviseGrid(estimate, tolerance_mm);
  if (!advice.coarse) return;
  std::string settle;
  if (advice.check_points_would_settle) {
    const double evidence = std::max({estimate.axes[0].curvature_mm, estimate.axes[1].curvature_mm,
                                      estimate.axes[0].check_points_mm.value_or(0.0),
                                      estimate.axes[1].check_points_mm.value_or(0.0)});
    settle = fmt::format(", or measure check points at its cell centres (its own nodes show {:.4f} mm)", evidence);
  } else if (estimate.Kind() == InterpolationKind::kCurvature && !estimate.HasCheckPoints()) {
    settle = "; check points at its cell centres would show whether it is even more";
  }
  diags.Report(DiagKind::InterpolationCoarse, where, subject, fmt::format("{:.4f}", estimate.NormMm()),
               fmt::format("{:.1f}", 100 * advice.share), FormatMm(tolerance_mm),
               fmt::format("{:.0f}", 100 * kInterpolationShareOfTolerance), InterpolationKindDescription(estimate.Kind()),
               fmt::format("{:.1f}", advice.pitch_mm), fmt::format("{:.1f}", estimate.PitchMm()), settle);
}

}  // namespace smtcal
