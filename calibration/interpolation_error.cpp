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

AxisInterpolation EstimateAxis(const AxisTable& t, const std::optional<DeclaredRoughness>& roughness,
                               double unknown_noise_mm) {
  AxisInterpolation result;
  const std::size_t nx = t.nx(), ny = t.ny();
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
  // The check-point figure of each cell.
  std::vector<std::optional<double>> checked((nx - 1) * (ny - 1));
  std::vector<const TableNode*> checked_by((nx - 1) * (ny - 1));
  for (const TableNode& check : t.checks) {
    const CellPlace place = PlaceInCell(t, check.x_mm, check.y_mm);
    const double residual = check.error_mm - Interpolate(t, check.x_mm, check.y_mm);
    double own = unknown_noise_mm;
    if (check.stddev_mm && check.count > 0) own = *check.stddev_mm / std::sqrt(static_cast<double>(check.count));
    const double noise = std::hypot(own, InterpolatedNoiseMm(t, check.x_mm, check.y_mm, unknown_noise_mm));
    const double share = std::max(place.CentreShare(), kMinCheckPointShare);
    const double figure = kCheckPointMargin * (std::abs(residual) + kCheckPointSigmas * noise) / share;
    std::optional<double>& cell = checked[place.j * (nx - 1) + place.i];
    if (!cell || figure > *cell) {
      cell = figure;
      checked_by[place.j * (nx - 1) + place.i] = &check;
    }
    result.largest_residual_mm = std::max(result.largest_residual_mm, std::abs(residual));
    result.check_points_mm = std::max(result.check_points_mm.value_or(0.0), figure);
    ++result.check_points;
  }
  result.pitch_mm = std::max(largest_pitch[0], largest_pitch[1]);

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
      const double hx = t.xs[i + 1] - t.xs[i], hy = t.ys[j + 1] - t.ys[j];
      const Eigen::Vector2d centre(0.5 * (t.xs[i] + t.xs[i + 1]), 0.5 * (t.ys[j] + t.ys[j + 1]));
      double cxx = 0, cyy = 0;
      for (std::size_t row : {j, j + 1}) cxx = std::max(cxx, CurvatureAlong(t.xs, i, fxx[row]));
      for (std::size_t column : {i, i + 1}) cyy = std::max(cyy, CurvatureAlong(t.ys, j, fyy[column]));
      const double curvature = hx * hx / 8 * cxx + hy * hy / 8 * cyy;
      result.curvature_mm = std::max(result.curvature_mm, curvature);
      consider(curvature, InterpolationKind::kCurvature, centre, t.Origin(i, j));
      ++result.cells;
      const std::optional<double>& check = checked[j * (nx - 1) + i];
      if (check) {
        const TableNode& by = *checked_by[j * (nx - 1) + i];
        ++result.checked_cells;
        consider(*check, InterpolationKind::kCheckPoints, {by.x_mm, by.y_mm}, by.error_field);
      } else if (roughness) {
        const double declared = DeclaredFigure(*roughness, hidden, std::max(hx, hy));
        result.declared_mm = std::max(result.declared_mm.value_or(0.0), declared);
        consider(declared, InterpolationKind::kDeclared, centre, t.Origin(i, j));
      }
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

double InterpolatedNoiseMm(const AxisTable& table, double x, double y, double unknown_noise_mm) {
  const CellPlace p = PlaceInCell(table, x, y);
  double variance = 0;
  for (int b = 0; b < 2; ++b) {
    for (int a = 0; a < 2; ++a) {
      const double weight = (a == 1 ? p.s : 1 - p.s) * (b == 1 ? p.t : 1 - p.t);
      const double se =
          table.StandardErrorMm(table.Index(p.i + static_cast<std::size_t>(a), p.j + static_cast<std::size_t>(b)))
              .value_or(unknown_noise_mm);
      variance += weight * weight * se * se;
    }
  }
  return std::sqrt(variance);
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
