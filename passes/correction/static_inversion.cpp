// static-inversion: base-frame targets get their nominal coordinates at
// compile time through the inverse calibration of their region.
//
// Assumes: regions ran (each known target has its region and kind).
// Guarantees when it reports no error: every static and every known run-time
// base target has `nominal` = F⁻¹(required) in x and y (z and u pass through:
// the regions' D is (2, {x, y})) with its residual |F(nominal) - required|
// and iteration count, following the region's policy for points outside its
// table; each static statement's target in the IR is replaced by its nominal
// XY(...), the required position kept in the statement's comment, so the
// corrected program commands the robot directly. Run-time targets keep their
// text; the controller corrects them.
#include <charconv>
#include <memory>

#include <fmt/format.h>

#include "ir/ir_ops.h"
#include "ir/ir_text.h"
#include "ir/symbols.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"

namespace smtcal {

namespace {

class StaticInversion final : public Pass {
 public:
  std::string_view Name() const override { return "static-inversion"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    SMTCAL_CHECK(program.compile != nullptr, "static-inversion runs after bind");
    CompileState& state = *program.compile;
    for (Target& target : state.targets) {
      bool base = target.kind == CorrectionKind::kStatic || target.kind == CorrectionKind::kRunTimeBase;
      if (!base || !target.known || target.region == nullptr) continue;
      const InverseSolver& solver = state.SolverFor(*target.region);
      Solution solution = solver.Solve(Xy(target.required), target.region->outside);
      // The residual is recomputed for the command as the program writes it.
      Eigen::Vector2d command(RoundForProgramText(solution.point.x()), RoundForProgramText(solution.point.y()));
      target.nominal = {command.x(), command.y(), target.required[2], target.required[3]};
      target.residual_mm = solution.residual_mm;
      if (solution.status == SolveStatus::kOk) {
        Solution reached = DirectCalibrate(solver.map(), command, target.region->outside);
        target.residual_mm = (reached.point - Xy(target.required)).norm();
      }
      target.iterations = solution.iterations;
      target.iteration_bound = solver.iteration_bound();
      if (solution.status == SolveStatus::kOutside || solution.status == SolveStatus::kNotConverged) {
        std::string why = solution.status == SolveStatus::kOutside
                              ? fmt::format("the command it needs, ({:.3f}, {:.3f}), lies outside the region's table {}",
                                            solution.point.x(), solution.point.y(),
                                            target.region->table_path)
                              : fmt::format("the solver stopped {} mm away", FormatMm(solution.residual_mm));
        diags.Report(DiagKind::StaticTargetNotInvertible, sema::StmtRange(*target.stmt), TargetKeyword(*target.stmt),
                     target.text, FormatComputedMm(target.required[0]), FormatComputedMm(target.required[1]), target.region->name, why);
        continue;
      }
      if (target.kind == CorrectionKind::kStatic) Lower(target);
    }
  }

 private:
  // The statement now commands the nominal position itself.
  static void Lower(const Target& target) {
    auto& stmt = const_cast<ir::Stmt&>(*target.stmt);  // the pass owns the IR it runs on
    ir::PointExpr* point = ir::MotionTarget(stmt);
    SMTCAL_CHECK(point != nullptr, "a target is a Motion or a Pick/Place");
    ir::Coords coords;
    coords.values = target.nominal;
    coords.loc = point->loc;
    point->base = coords;
    point->offsets.clear();
    std::string& comment = stmt.trailing_comment;
    comment += comment.empty() ? " " : "; ";
    // Appended piece by piece: every static placement of a CAD-sized program has one.
    comment += "required ";
    comment += target.text;
    comment += " = ";
    comment += PrintCoords({target.required, {}});
    comment += ", region ";
    comment += target.region->name;
    comment += ", residual ";
    char residual[32];  // as printf's %.1e
    comment.append(residual, std::to_chars(residual, residual + sizeof residual, target.residual_mm,
                                           std::chars_format::scientific, 1).ptr);
    comment += " mm";
  }
};

}  // namespace

std::unique_ptr<Pass> CreateStaticInversionPass() { return std::make_unique<StaticInversion>(); }

}  // namespace smtcal
