// The table commands' solvers at one point, for the table and point-list
// harnesses.
#pragma once

#include "calibration/error_table_check.h"
#include "calibration/inverse_calibration.h"
#include "tests/fuzz/fuzz_target.h"

namespace smtcal::fuzz {

// Both inverse solvers and the forward map of one table, made once.
struct Solvers {
  Solvers(const ErrorTable& table, const TableAnalysis& analysis)
      : inverse(table, analysis), paper(table, kPaperSolverTolMm), map(table) {}
  InverseSolver inverse;
  PaperSolver paper;
  CalibrationMap map;
};

// Every solver at `point`, every outside policy. The default solver must
// converge within the bound proven for the table.
inline void Solve(const Solvers& solvers, const Eigen::Vector2d& point) {
  for (OutsidePolicy policy : {OutsidePolicy::kError, OutsidePolicy::kClamp, OutsidePolicy::kNone}) {
    Solution s = solvers.inverse.Solve(point, policy);
    if (s.status == SolveStatus::kNotConverged) Fail("the default solver exceeded its proven bound");
    solvers.paper.Solve(point, policy);
    DirectCalibrate(solvers.map, point, policy);
  }
}

}  // namespace smtcal::fuzz
