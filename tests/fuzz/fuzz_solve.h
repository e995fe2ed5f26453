// The table commands' solvers at one point, for the table and point-list
// harnesses.
#pragma once

#include "calibration/error_table_check.h"
#include "calibration/inverse_calibration.h"
#include "tests/fuzz/fuzz_target.h"

namespace smtcal::fuzz {

// Both inverse solvers and the forward map at `point`, every outside policy.
// The default solver must converge within the bound proven for the table.
inline void Solve(const ErrorTable& table, const TableAnalysis& analysis, const Eigen::Vector2d& point) {
  InverseSolver solver(table, analysis);
  PaperSolver paper(table, kPaperSolverTolMm);
  CalibrationMap map(table);
  for (OutsidePolicy policy : {OutsidePolicy::kError, OutsidePolicy::kClamp, OutsidePolicy::kNone}) {
    Solution s = solver.Solve(point, policy);
    if (s.status == SolveStatus::kNotConverged) Fail("the default solver exceeded its proven bound");
    paper.Solve(point, policy);
    DirectCalibrate(map, point, policy);
  }
}

}  // namespace smtcal::fuzz
