// How far the robot's error may depart from the bilinear interpolation
// between an error table's nodes (docs/error-tables.md, "Between the nodes").
// The nodes are measured; the interpolation between them is an assumption,
// and on a coarse grid a large one. Per axis table, three figures of the
// largest departure anywhere in the table (mm):
//
//   - check points (readings off the nodes, kept in the table, kind = check):
//     each check point's residual, measured minus interpolated, plus 4 sigma
//     of its noise (its own readings and the interpolated nodes'), scaled to
//     its cell's centre (a check point at (s, t) of its cell sees the share
//     phi = 2 (s(1-s) + t(1-t)) of the centre's error of a quadratic field)
//     and by kCheckPointMargin for what lies between it and the nodes. The
//     measured figure of every cell that has one.
//   - curvature: second differences of the nodes along each axis give each
//     cell's mid-cell error of a bilinear fit of a smooth field,
//     h_x^2/8 |f_xx| + h_y^2/8 |f_yy|. A lower bound: it cannot see a
//     departure the grid aliases (a wave shorter than a few pitches). The
//     node noise is left in the second differences (pessimistic).
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
// The estimate of an axis table is the largest of: the curvature figure
// (everywhere), the check-point figure of every cell with a check point, and
// the declared figure of every cell without one. It enters the placement
// budget as a bound (calibration/placement_budget.h).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

#include <Eigen/Core>

#include "base/diagnostics.h"
#include "calibration/error_table.h"

namespace smtcal {

// A check point's figure is its residual (plus noise) scaled to its cell's
// centre and then by this: between a check point and the nodes the field can
// depart a little more than at the check point itself. 1.25 covers every
// random smooth field of the property test whose shortest wavelength is 2.5
// pitches (without it: up to 1.24 x the figure, seed 7 of 1..40 and 19940101,
// so little slack; tests/unit/calibration/interpolation_error_test.cpp).
inline constexpr double kCheckPointMargin = 1.25;
// The noise of a check point's residual is taken at this many standard
// deviations (the budget's 4 sigma).
inline constexpr double kCheckPointSigmas = 4;
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

// The bilinear interpolation of an axis table at a point of its rectangle,
// and the standard deviation of that value from the nodes' noise
// (sum of w_k^2 se_k^2; a node without stddev and count counts as
// `unknown_noise_mm`).
double Interpolate(const AxisTable& table, double x, double y);
double InterpolatedNoiseMm(const AxisTable& table, double x, double y, double unknown_noise_mm);

struct AxisInterpolation {
  double estimate_mm = 0;  // the largest of the figures below, as described above
  InterpolationKind kind = InterpolationKind::kCurvature;  // which figure it is
  Eigen::Vector2d at = Eigen::Vector2d::Zero();  // the cell centre (or check point) it comes from
  SourceRange origin;  // where that is written: the check point's row, or the cell's first node's
  double curvature_mm = 0;                   // the curvature figure: a lower bound
  std::optional<double> check_points_mm;     // the largest check-point figure (when there are any)
  std::optional<double> declared_mm;         // the declared figure of the coarsest cell (when declared)
  std::size_t cells = 0, checked_cells = 0;  // cells, and cells with a check point
  std::size_t check_points = 0;
  double pitch_mm = 0;  // the table's largest pitch along either axis
  // The largest check-point residual |measured - interpolated| (no noise, no scaling).
  double largest_residual_mm = 0;
};

struct InterpolationEstimate {
  std::array<AxisInterpolation, 2> axes;  // [X] of the Delta-x table, [Y] of the Delta-y table

  const AxisInterpolation& operator[](TableAxis axis) const { return axes[static_cast<int>(axis)]; }
  // Per axis (Delta-x, Delta-y).
  Eigen::Vector2d PerAxisMm() const { return {axes[0].estimate_mm, axes[1].estimate_mm}; }
  // The length of the largest departure vector: |(E_x, E_y)|.
  double NormMm() const { return PerAxisMm().norm(); }
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
