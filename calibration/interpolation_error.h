// How far the robot's error may depart from the bilinear interpolation
// between an error table's nodes (docs/error-tables.md, "Between the nodes").
// The nodes are measured; the interpolation between them is an assumption,
// and on a coarse grid a large one. Per axis table and per cell of its grid,
// a bound on the largest departure (mm) from three kinds of evidence:
//
//   - curvature: second differences of the nodes along each axis give each
//     cell's departure of a bilinear fit of a locally quadratic field,
//     d(s, t) = A p(s) + B q(t) with p = 4 s(1-s), q = 4 t(1-t),
//     |A| <= c_x = h_x^2/8 |f_xx|, |B| <= c_y = h_y^2/8 |f_yy| (|f''| the
//     largest at the cell's nodes). Without a check point: c_x + c_y, a
//     lower bound (it cannot see a departure the grid aliases).
//   - check points (readings off the nodes, kept in the table, kind =
//     check): a check point's residual r, measured minus interpolated, is an
//     unbiased estimate of the departure there (its noise has mean zero). At
//     a cell's centre it says A + B = r, so the quadratic model's largest
//     departure in the cell is max(|r|, min(c_x, |r| + c_y), min(c_y, |r| +
//     c_x)); off the centre (share phi = (p + q)/2 of the centre's) and
//     where r is more than the curvature allows, max(|r| / phi, c_x + c_y).
//     Times kCheckPointMargin for what the quadratic model misses. The
//     residual's noise (the check point's and its interpolated nodes'
//     standard errors, from the table's pooled reading scatter) is kept
//     apart as a standard deviation: the budget adds it to its random part,
//     never to the bound.
//   - declared roughness (when the cell declares its robot's accuracy A and
//     correlation length L): the mid-cell error a (1 - cos(pi h / 3L)), for
//     a cell of largest pitch h, of the largest wave of the shortest
//     wavelength the virtual cell's field has, 3 L, that the nodes' second
//     differences could still hide: amplitude a at most A, and at most what
//     the table's largest second differences allow given how much of such a
//     wave's phase the interior nodes of a line sample (none on a 3-node
//     line: a = A). What the nodes cannot rule out; a check point in the
//     cell replaces it.
//
// A cell's bound is its check-point figure when it has a check point, else
// the larger of its curvature and declared figures. The estimate of an axis
// table is its largest cell bound, with the largest noise of its check-point
// figures. It enters the placement budget as a bound plus a random part
// (calibration/placement_budget.h); the budget of a fixture target looks up
// the cells under each trip (AxisInterpolation::Over).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/error_table.h"

namespace smtcal {

// A check-point figure is the quadratic model's largest departure in its
// cell times this: what a smooth field's departure from the model (third
// and higher orders, a second difference that averages the curvature over
// two pitches) adds. The property test (random smooth fields whose shortest
// wavelength is 2.5 to 24 pitches, at 2, 5, 10 and 25 mm:
// tests/unit/calibration/interpolation_error_test.cpp) measures what it must
// cover; docs/error-tables.md gives the figures.
inline constexpr double kCheckPointMargin = 1.3;
// A check point whose share phi of its cell's centre error is below this is
// too close to a node to show the interpolation error (a tenth of a pitch
// along both axes from a node, or less): an error in the table file.
inline constexpr double kMinCheckPointShare = 0.25;
// The declared roughness's shortest wavelength, in correlation lengths: the
// virtual cell's field outside the tables has wavelengths of 3 L to 6 L
// (simulation/true_field.h).
inline constexpr double kRoughnessWavelengthPerCorrelation = 3;
// Grid advice: an estimate above this share of the region's tolerance gets
// the pitch to measure at next.
inline constexpr double kInterpolationShareOfTolerance = 0.1;

// The tolerance the table commands (`table check`, `table stats`) take the
// interpolation error as a share of when not told (--tolerance): the paper's
// placing accuracy.
inline constexpr double kDefaultTableToleranceMm = 0.1;

enum class InterpolationKind { kCheckPoints, kCurvature, kDeclared };
// "check_points", "curvature", "declared_roughness"
std::string_view InterpolationKindName(InterpolationKind kind);
// Short: "check points", "curvature, a lower bound", "declared roughness".
std::string_view InterpolationKindShortName(InterpolationKind kind);
// For messages: "from check points", "from the table's curvature (a lower
// bound: it cannot see what the grid aliases)", ...
std::string_view InterpolationKindDescription(InterpolationKind kind);

// What the cell declares about how rough the robot's error is
// (robot.uncalibrated_accuracy_mm and uncalibrated_correlation_mm).
struct DeclaredRoughness {
  double accuracy_mm = 0;
  double correlation_mm = 0;
};

// Where a point lies in the cell of an axis table that holds it.
struct CellPlace {
  std::size_t i = 0, j = 0;  // the cell: xs[i]..xs[i+1], ys[j]..ys[j+1]
  double s = 0, t = 0;       // the point's position in it, 0..1
  // phi = 2 (s(1-s) + t(1-t)): 1 at the centre, 1/2 at an edge's midpoint,
  // 0 at a node: the share of the cell centre's error that a quadratic
  // field shows here.
  double CentreShare() const { return 2 * (s * (1 - s) + t * (1 - t)); }
};
// The point must lie within the table's grid rectangle (bounds included).
CellPlace PlaceInCell(const AxisTable& table, double x, double y);

// The bilinear interpolation of an axis table at a point of its rectangle.
double Interpolate(const AxisTable& table, double x, double y);

// The scatter of one reading of an axis table (mm), pooled over its nodes and
// check points that state a stddev and a count of 2 or more:
// sqrt(sum (n - 1) s^2 / sum (n - 1)). The readings of one table come from
// one measuring set-up, so one figure serves every point: a point of two
// readings whose two happened to agree has scatter 0 of its own, not the
// set-up's. nullopt when no point states one.
std::optional<double> PooledReadingScatterMm(const AxisTable& table);

// The bound and the noise of the departure over a part of a table.
struct LocalInterpolation {
  double bound_mm = 0;  // the largest cell bound there
  double noise_mm = 0;  // the largest standard deviation of those bounds' check points
};

struct AxisInterpolation {
  // The largest departure anywhere in the table: the largest cell bound
  // (as described above), with `noise_mm` the standard deviation of the
  // check-point figures (the largest over the checked cells; 0 without).
  double estimate_mm = 0;
  double noise_mm = 0;
  InterpolationKind kind = InterpolationKind::kCurvature;  // which figure the estimate is
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  // the cell centre (or check point) it comes from
  SourceRange origin;  // where that is written: the check point's row, or the cell's first node's
  double curvature_mm = 0;                   // the largest curvature figure c_x + c_y: a lower bound
  std::optional<double> check_points_mm;     // the largest check-point figure (when there are any)
  std::optional<double> declared_mm;         // the declared figure of the coarsest cell (when declared)
  std::size_t cells = 0, checked_cells = 0;  // cells, and cells with a check point
  std::size_t check_points = 0;
  double pitch_mm = 0;  // the table's largest pitch along either axis
  // The largest check-point residual |measured - interpolated| (no noise, no scaling).
  double largest_residual_mm = 0;
  // The margin the check-point figures were taken with (kCheckPointMargin).
  double margin = 0;
  // The reading scatter the noise comes from (PooledReadingScatterMm), when
  // the table states one.
  std::optional<double> reading_scatter_mm;
  // Per cell (j (nx - 1) + i of the grid lines xs, ys): its bound and noise.
  std::vector<double> xs, ys;
  std::vector<double> cell_bound_mm, cell_noise_mm;

  // The largest bound and noise of the cells that meet the rectangle
  // [x0, x1] x [y0, y1] (clipped to the grid; a rectangle outside it meets
  // the nearest cells).
  LocalInterpolation Over(const Rect& box) const;
};

struct InterpolationEstimate {
  std::array<AxisInterpolation, 2> axes;  // [X] of the Delta-x table, [Y] of the Delta-y table

  const AxisInterpolation& operator[](TableAxis axis) const { return axes[static_cast<int>(axis)]; }
  // Per axis (Delta-x, Delta-y): the bounds, and their noise's standard deviations.
  Eigen::Vector2d PerAxisMm() const { return {axes[0].estimate_mm, axes[1].estimate_mm}; }
  Eigen::Vector2d PerAxisNoiseMm() const { return {axes[0].noise_mm, axes[1].noise_mm}; }
  // The length of the largest departure vector: |(E_x, E_y)|.
  double NormMm() const { return PerAxisMm().norm(); }
  // The larger of the two noises: the departure's standard deviation in its worst direction.
  double NoiseMm() const { return std::max(axes[0].noise_mm, axes[1].noise_mm); }
  // The larger of the two tables' pitches.
  double PitchMm() const { return std::max(axes[0].pitch_mm, axes[1].pitch_mm); }
  // The kind and the origin of the axis with the larger estimate.
  InterpolationKind Kind() const { return Larger().kind; }
  const SourceRange& Origin() const { return Larger().origin; }
  const AxisInterpolation& Larger() const { return axes[1].estimate_mm > axes[0].estimate_mm ? axes[1] : axes[0]; }
  bool HasCheckPoints() const { return axes[0].check_points + axes[1].check_points > 0; }
};

// Requires HasUsableShape. `roughness`: nullopt when the cell declares none
// (or there is no cell); `unknown_noise_mm`: the noise of a node or check
// point that states no stddev and count.
InterpolationEstimate EstimateInterpolationError(const ErrorTable& table,
                                                 const std::optional<DeclaredRoughness>& roughness,
                                                 double unknown_noise_mm);

// The paper's rule made quantitative: start with the pitch as large as
// possible and decrease it until the result is satisfactory.
// The advice is about the departure (the bounds): the check points' noise is
// no matter of pitch (more repetitions narrow it).
struct GridAdvice {
  double share = 0;        // the estimate's norm as a share of the tolerance
  bool coarse = false;     // share > kInterpolationShareOfTolerance
  // When coarse: the largest pitch at which the estimate would be that share
  // (the error scales with the pitch squared), rounded down to 0.1 mm.
  double pitch_mm = 0;
  // When coarse: the estimate is the declared roughness's and the table's
  // own curvature is within the share, so check points at the cell centres
  // could show the grid is fine.
  bool check_points_would_settle = false;
};
GridAdvice AdviseGrid(const InterpolationEstimate& estimate, double tolerance_mm);

// The grid advice as a warning (InterpolationCoarse) when the estimate is
// more than kInterpolationShareOfTolerance of the tolerance: the pitch to
// measure at next, and whether check points would settle it. `subject` names
// the table ("the table", "region 'layer1''s table"); the warning is at
// `where`.
void ReportCoarseGrid(const InterpolationEstimate& estimate, double tolerance_mm, std::string_view subject,
                      const SourceRange& where, Diagnostics& diags);

// The estimate of a grid not measured yet, at pitch `pitch_mm`, in a cell
// that declares (or assumes) this roughness: its nodes can rule nothing out
// yet, so every cell carries the declared wave at its full amplitude A, per
// axis A (1 - cos(pi h / 3L)) (what EstimateInterpolationError gives a cell
// without a check point whose nodes hide the wave), and the estimate is the
// length of (E_x, E_y).
double PlannedInterpolationMm(const DeclaredRoughness& roughness, double pitch_mm);

// The grid advice before the first measurement (`measure plan`'s default
// pitch): the largest pitch at which PlannedInterpolationMm is within
// kInterpolationShareOfTolerance of `tolerance_mm`, rounded down to 0.1 mm;
// infinity when no pitch can exceed it (the whole declared range fits).
double PlannedPitchMm(const DeclaredRoughness& roughness, double tolerance_mm);

// The pitch at which an interpolation part of `part_mm` (at pitch
// `pitch_mm`) would shrink to `allowed_mm`, rounded down to 0.1 mm (the
// error scales with the pitch squared); 0 when nothing is allowed.
double PitchForShare(double pitch_mm, double part_mm, double allowed_mm);

}  // namespace smtcal
