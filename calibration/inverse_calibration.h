// Direct and inverse calibration through a validated error table.
//
// Direct: a = F(n) = n + Delta(n). Inverse: the nominal n with F(n) = a for a
// required actual position a. Two inverse solvers:
//
// - InverseSolver (the default): Newton on F(n) - a with the exact Jacobian of
//   the piece it is in, guarded by the fixed-point step n <- a - Delta(n). In a
//   valid table the fixed-point step shrinks the residual r = F(n) - a by the
//   contraction factor L = max |grad Delta|_inf < 1 (|r'| = |Delta(n') -
//   Delta(n)| <= L |n' - n| = L |r|); a Newton step is kept only when it does
//   at least as well, so after k iterations |r|_inf <= L^k max|Delta|.
//   IterationBound() turns that into the number of iterations that always
//   suffices for kInverseResidualTolMm, and the solver never runs longer.
// - PaperSolver: the paper's iterative interval search (section 3.2.3), as
//   read in docs/error-tables.md, kept for comparison.
//
// Points outside the table follow an OutsidePolicy; nothing is ever
// extrapolated silently and no solve returns a NaN.
#pragma once

#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "calibration/error_table.h"
#include "calibration/error_table_check.h"
#include "calibration/tolerances.h"

namespace smtcal {

// What to do with a point outside the table (its nominal position outside the
// domain, for the inverse).
enum class OutsidePolicy {
  kError,  // refuse: status kOutside
  kClamp,  // use Delta's edge values (Delta at the point clamped into the domain)
  kNone,   // no correction: the point is returned unchanged
};

enum class SolveStatus {
  kOk,            // inside the table, corrected
  kClamped,       // outside, corrected with the edge values (kClamp)
  kUncorrected,   // outside, returned unchanged (kNone)
  kOutside,       // outside, refused (kError)
  kNotConverged,  // the solver stopped at its iteration limit above its tolerance
};
std::string_view StatusName(SolveStatus status);

struct Solution {
  // Forward: the actual position F(n). Inverse: the nominal position n (for
  // kOutside, the nominal position the table would need, outside it).
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  double residual_mm = 0;  // inverse: |F(n) - a|; forward: 0
  int iterations = 0;      // inverse: solver iterations; forward: 0
  SolveStatus status = SolveStatus::kOk;
};

// The direct calibration F(n) with the outside policy.
Solution DirectCalibrate(const CalibrationMap& map, const Eigen::Vector2d& n, OutsidePolicy policy);

// The number of default-solver iterations that always brings |F(n) - a| to
// kInverseResidualTolMm / 2 (the solver stops at kInverseResidualTolMm): the
// smallest k with sqrt(2) * L^k * D <= tol / 2, for contraction factor L < 1
// and D = max |Delta|_inf.
int IterationBound(double contraction, double max_abs_error_mm);
// The same for a valid table (analyzes it).
int IterationBound(const ErrorTable& table);

class InverseSolver {
 public:
  // The table must have passed ValidateErrorTable (checked: L <= kMaxErrorSlope
  // and det(I + grad Delta) >= kMinJacobianDet).
  explicit InverseSolver(const ErrorTable& table);
  InverseSolver(const ErrorTable& table, const TableAnalysis& analysis);

  // Allocation-free. Never more than iteration_bound() iterations; in a valid
  // table the status is never kNotConverged (the tests and the CLI check it).
  Solution Solve(const Eigen::Vector2d& actual, OutsidePolicy policy) const;

  int iteration_bound() const { return iteration_bound_; }
  double contraction() const { return contraction_; }
  const CalibrationMap& map() const { return map_; }

 private:
  CalibrationMap map_;
  double contraction_ = 0;
  int iteration_bound_ = 0;
};

class PaperSolver {
 public:
  // The table must have passed ValidateErrorTable (checked as above).
  explicit PaperSolver(const ErrorTable& table, double tolerance_mm = kPaperSolverTolMm,
                       int max_steps = kPaperSolverMaxSteps);

  // Iterations = interval steps taken. kNotConverged when max_steps ran out
  // before the corrected interval means came within the tolerance (outside
  // the table only under kClamp: kError and kNone apply as usual).
  Solution Solve(const Eigen::Vector2d& actual, OutsidePolicy policy) const;

  double tolerance_mm() const { return tolerance_mm_; }
  const CalibrationMap& map() const { return map_; }

 private:
  struct Interval {
    double lo, hi;
  };
  // One of the paper's two discrete functions, the same construction with x
  // and y swapped: x_N(x_N + Delta-x, y_N) on the rows of the x table (along
  // = x, across = y) and y_N(x_N, y_N + Delta-y) on the columns of the y
  // table (along = y, across = x). Its nodes lie within the domain (where F
  // is defined): the domain's edges and the grid lines between them.
  struct DiscreteFunction {
    TableAxis axis;
    std::vector<double> along;   // the nodes of each row (column)
    std::vector<double> across;  // the rows (columns): nominal y (x)
  };
  // The nominal coordinate along f's axis that gives `actual` on the row
  // (column) at nominal `across`.
  double Nominal(const DiscreteFunction& f, double actual, double across) const;
  // The interval of that nominal coordinate over the rows (columns) within
  // the interval `across`.
  Interval Step(const DiscreteFunction& f, double actual, Interval across) const;

  CalibrationMap map_;
  double tolerance_mm_;
  int max_steps_;
  DiscreteFunction x_function_;  // x_N(x_N + Delta-x, y_N)
  DiscreteFunction y_function_;  // y_N(x_N, y_N + Delta-y)
};

}  // namespace smtcal
