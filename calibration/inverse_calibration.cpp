// Direct and inverse calibration (see inverse_calibration.h for the contract
// and docs/error-tables.md for the derivations). Assumes a table that passed
// ValidateErrorTable; guarantees |F(n) - a| <= kInverseResidualTolMm within
// IterationBound() iterations for the default solver, and a named status (never
// a NaN) for every finite input point.
#include "calibration/inverse_calibration.h"

#include <algorithm>
#include <cmath>

#include "base/check.h"

namespace smtcal {

std::string_view StatusName(SolveStatus status) {
  switch (status) {
    case SolveStatus::kOk: return "ok";
    case SolveStatus::kClamped: return "clamped";
    case SolveStatus::kUncorrected: return "uncorrected";
    case SolveStatus::kOutside: return "outside";
    case SolveStatus::kNotConverged: return "not-converged";
  }
  return "ok";
}

namespace {

double InfNorm(const Eigen::Vector2d& v) { return std::max(std::abs(v.x()), std::abs(v.y())); }

void CheckSolvable(const TableAnalysis& analysis) {
  SMTCAL_CHECK(analysis.contraction <= kMaxErrorSlope && analysis.min_jacobian_det >= kMinJacobianDet,
               "an inverse solver needs a table that passed ValidateErrorTable");
}

// Applies the outside policy to a solved (or directly calibrated) point,
// whether or not the solver converged: a point outside is never corrected
// unless the policy says so.
Solution ApplyPolicy(const CalibrationMap& map, Solution solution, const Eigen::Vector2d& nominal,
                     const Eigen::Vector2d& input, OutsidePolicy policy) {
  if (map.Inside(nominal)) return solution;
  switch (policy) {
    case OutsidePolicy::kError:
      solution.status = SolveStatus::kOutside;
      break;
    case OutsidePolicy::kClamp:
      if (solution.status != SolveStatus::kNotConverged) solution.status = SolveStatus::kClamped;
      break;
    case OutsidePolicy::kNone:
      solution = Solution{input, 0, 0, SolveStatus::kUncorrected};
      break;
  }
  return solution;
}

}  // namespace

Solution DirectCalibrate(const CalibrationMap& map, const Eigen::Vector2d& n, OutsidePolicy policy) {
  SMTCAL_CHECK(std::isfinite(n.x()) && std::isfinite(n.y()), "calibrating a non-finite point");
  Solution solution{n + map.Delta(n), 0, 0, SolveStatus::kOk};
  return ApplyPolicy(map, solution, n, n, policy);
}

int IterationBound(double contraction, double max_abs_error_mm) {
  SMTCAL_CHECK(contraction >= 0 && contraction < 1 && max_abs_error_mm >= 0,
               "IterationBound needs a contraction factor below 1");
  const double target = kInverseResidualTolMm / 2;
  const double start = std::sqrt(2.0) * max_abs_error_mm;  // |r_0|_2 <= sqrt(2) |Delta|_inf
  if (start <= target) return 0;
  if (contraction == 0) return 1;  // a constant Delta: one step is exact
  return static_cast<int>(std::ceil(std::log(target / start) / std::log(contraction)));
}

int IterationBound(const ErrorTable& table) {
  TableAnalysis analysis = AnalyzeTable(table);
  CheckSolvable(analysis);
  return IterationBound(analysis.contraction, analysis.max_abs_error_mm);
}

// ------------------------------------------------------------------ default solver

InverseSolver::InverseSolver(const ErrorTable& table) : InverseSolver(table, AnalyzeTable(table)) {}

InverseSolver::InverseSolver(const ErrorTable& table, const TableAnalysis& analysis)
    : map_(table), contraction_(analysis.contraction) {
  CheckSolvable(analysis);
  iteration_bound_ = IterationBound(analysis.contraction, analysis.max_abs_error_mm);
}

// Every kept step has |r'|_inf <= L |r|_inf, hence |r'|_2 <= sqrt(2) L |r|_2:
// with sqrt(2) L < 1 the Euclidean residual shrinks too, which the solver's
// early stop relies on (docs/error-tables.md).
static_assert(kMaxErrorSlope * 1.4142135623730951 < 1, "the solver's early stop needs L < 1/sqrt(2)");

Solution InverseSolver::Solve(const Eigen::Vector2d& actual, OutsidePolicy policy) const {
  SMTCAL_CHECK(std::isfinite(actual.x()) && std::isfinite(actual.y()), "solving for a non-finite point");
  Eigen::Vector2d n = actual;
  Eigen::Vector2d delta;
  Eigen::Matrix2d jacobian;
  map_.DeltaAndJacobian(n, delta, jacobian);
  Eigen::Vector2d residual = n + delta - actual;
  double norm = residual.norm();
  int iterations = 0;
  // The bound guarantees kInverseResidualTolMm; the iterations it allows
  // beyond that polish the result to machine precision.
  while (norm > kInversePolishMm && iterations < iteration_bound_) {
    ++iterations;
    const Eigen::Vector2d previous_n = n, previous_delta = delta, previous_residual = residual;
    const Eigen::Matrix2d previous_jacobian = jacobian;
    // Newton: solve (I + J) step = residual. In a valid table det >= 1/2
    // inside and >= 1 - L outside (a clamped coordinate has zero slope).
    const double a = 1 + jacobian(0, 0), b = jacobian(0, 1), c = jacobian(1, 0), d = 1 + jacobian(1, 1);
    const double det = a * d - b * c;
    bool accepted = false;
    if (det > 0) {
      Eigen::Vector2d trial(n.x() - (d * residual.x() - b * residual.y()) / det,
                            n.y() - (a * residual.y() - c * residual.x()) / det);
      Eigen::Vector2d trial_delta;
      Eigen::Matrix2d trial_jacobian;
      map_.DeltaAndJacobian(trial, trial_delta, trial_jacobian);
      Eigen::Vector2d trial_residual = trial + trial_delta - actual;
      // Keep it only if it does at least as well as the fixed-point step is
      // guaranteed to (across a cell boundary the Jacobian jumps).
      if (InfNorm(trial_residual) <= contraction_ * InfNorm(residual)) {
        n = trial;
        delta = trial_delta;
        jacobian = trial_jacobian;
        residual = trial_residual;
        accepted = true;
      }
    }
    if (!accepted) {
      n = actual - delta;  // the fixed-point step: |r| shrinks by L at least
      map_.DeltaAndJacobian(n, delta, jacobian);
      residual = n + delta - actual;
    }
    // In exact arithmetic |r|_2 shrinks at every step (see the static_assert
    // above), so a step that does not shrink it is rounding.
    const double new_norm = residual.norm();
    if (!(new_norm < norm)) {  // keep the better point
      n = previous_n, delta = previous_delta, residual = previous_residual, jacobian = previous_jacobian;
      break;
    }
    norm = new_norm;
  }
  Solution solution{n, norm, iterations, SolveStatus::kOk};
  if (solution.residual_mm > kInverseResidualTolMm) solution.status = SolveStatus::kNotConverged;
  return ApplyPolicy(map_, solution, n, actual, policy);
}

// ------------------------------------------------------------------ the paper's solver

namespace {

// The edges [lo, hi] and the lines strictly between them.
std::vector<double> LinesWithin(const std::vector<double>& lines, double lo, double hi) {
  std::vector<double> within = {lo};
  for (double v : lines) {
    if (v > lo && v < hi) within.push_back(v);
  }
  within.push_back(hi);
  return within;
}

// Inverts the piecewise-linear map nominal -> nominal + delta(nominal) given
// at `nodes` (increasing; delta(k) is the error at nodes[k]) for `actual`,
// by linear interpolation between neighbouring nodes. Beyond the ends the
// edge error is used (slope 1), the direct calibration's own extension.
template <typename Delta>
double InvertPiecewiseLinear(const std::vector<double>& nodes, Delta delta, double actual) {
  double previous = nodes[0] + delta(nodes[0]);
  if (actual <= previous) return nodes[0] + (actual - previous);
  for (std::size_t k = 1; k < nodes.size(); ++k) {
    double here = nodes[k] + delta(nodes[k]);
    if (actual <= here) return nodes[k - 1] + (actual - previous) / (here - previous) * (nodes[k] - nodes[k - 1]);
    previous = here;
  }
  return nodes.back() + (actual - previous);
}

}  // namespace

PaperSolver::PaperSolver(const ErrorTable& table, double tolerance_mm, int max_steps)
    : map_(table), tolerance_mm_(tolerance_mm), max_steps_(max_steps) {
  CheckSolvable(AnalyzeTable(table));
  SMTCAL_CHECK(tolerance_mm > 0 && max_steps >= 2, "the paper's solver needs a tolerance and 2 steps");
  const Rect& d = map_.domain();
  x_function_ = {TableAxis::X, LinesWithin(map_.xs(TableAxis::X), d.x0, d.x1),
                 LinesWithin(map_.ys(TableAxis::X), d.y0, d.y1)};
  y_function_ = {TableAxis::Y, LinesWithin(map_.ys(TableAxis::Y), d.y0, d.y1),
                 LinesWithin(map_.xs(TableAxis::Y), d.x0, d.x1)};
}

// On the row (column) at nominal `across`, the nodes map nominal v to actual
// v + Delta(v) (between grid rows Delta is interpolated linearly along each
// column), and the actual value is inverted by linear interpolation between
// neighbouring nodes. Rows are taken where F is defined (the domain; outside
// it, its edge row), so the paper's functions and the direct calibration
// agree everywhere.
double PaperSolver::Nominal(const DiscreteFunction& f, double actual, double across) const {
  across = std::clamp(across, f.across.front(), f.across.back());
  auto delta = [&](double along) {
    return f.axis == TableAxis::X ? map_.AxisDelta(TableAxis::X, along, across)
                                  : map_.AxisDelta(TableAxis::Y, across, along);
  };
  return InvertPiecewiseLinear(f.along, delta, actual);
}

// The rows (columns) within the interval: those at both ends and every grid
// row (column) inside.
PaperSolver::Interval PaperSolver::Step(const DiscreteFunction& f, double actual, Interval across) const {
  double first = Nominal(f, actual, across.lo);
  Interval found{first, first};
  auto include = [&](double line) {
    double v = Nominal(f, actual, line);
    found.lo = std::min(found.lo, v);
    found.hi = std::max(found.hi, v);
  };
  include(across.hi);
  for (double line : f.across) {
    if (line > across.lo && line < across.hi) include(line);
  }
  return found;
}

Solution PaperSolver::Solve(const Eigen::Vector2d& actual, OutsidePolicy policy) const {
  SMTCAL_CHECK(std::isfinite(actual.x()) && std::isfinite(actual.y()), "solving for a non-finite point");
  // Step 1: all nominal rows. Step 2: y within the x interval found.
  Interval x = Step(x_function_, actual.x(), Interval{x_function_.across.front(), x_function_.across.back()});
  Interval y = Step(y_function_, actual.y(), x);
  int steps = 2;
  Eigen::Vector2d n;
  double residual = 0;
  while (true) {
    // After every step from the second: the interval means, corrected
    // through the tables, compared with the required position.
    n = {0.5 * (x.lo + x.hi), 0.5 * (y.lo + y.hi)};
    residual = (n + map_.Delta(n) - actual).norm();
    if (residual <= tolerance_mm_ || steps >= max_steps_) break;
    ++steps;
    if (steps % 2 == 1) {
      x = Step(x_function_, actual.x(), y);
    } else {
      y = Step(y_function_, actual.y(), x);
    }
  }
  Solution solution{n, residual, steps, SolveStatus::kOk};
  if (residual > tolerance_mm_) solution.status = SolveStatus::kNotConverged;
  return ApplyPolicy(map_, solution, n, actual, policy);
}

}  // namespace smtcal
