// fixture-correction: targets in a fixture frame are corrected on the
// controller every cycle; this pass prepares what the runtime needs.
//
// Assumes: regions ran; bound fixtures with taught points have FIX_0 (bind).
// Guarantees: every taught point on a fixture is converted to its fixture
// coordinates FIXPOS_0 = FIX_0⁻¹ · F(ROBOT_0) (direct calibration first: the
// taught coordinates are where the robot was commanded, F says where it
// really was), and its declaration in the IR becomes a programmed point
// `In FIXTURE` with the taught coordinates in its comment, so the runtime
// treats it like any off-line point (FIX_n · FIXPOS_0, the closed form of the
// paper's Eq. 9). Every fixture target records its point in fixture
// coordinates, the region whose table the runtime inverts (at the nominal
// pose), that table's iteration bound and the command at the nominal pose
// (for the report).
#include <map>
#include <memory>

#include <fmt/format.h>

#include "ir/ir_text.h"
#include "ir/symbols.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"

namespace smtcal {
namespace {

Pose4 RoundedForProgramText(Pose4 pose) {
  for (double& value : pose) value = RoundForProgramText(value);
  return pose;
}

class FixtureCorrection final : public Pass {
 public:
  std::string_view Name() const override { return "fixture-correction"; }

  void Run(ir::Program& program, Diagnostics& /*diags*/) override {
    SMTCAL_CHECK(program.compile != nullptr, "fixture-correction runs after bind");
    CompileState& state = *program.compile;
    const cell::Cell& cell = *state.cell;

    std::map<const ir::Stmt*, std::size_t> taught_index;
    for (const ir::StmtPtr& item : program.items) {
      const auto* decl = std::get_if<ir::PointDecl>(&item->node);
      if (decl == nullptr || !decl->taught) continue;
      int fixture = state.FindFixture(decl->frame);
      if (fixture < 0 || !state.fixtures[fixture].fix0) continue;  // reported by bind
      TaughtPoint taught;
      taught.decl = item.get();
      taught.taught = decl->coords.values;
      taught.region = cell.RegionAt(Xy(taught.taught));
      taught.reached = taught.taught;
      if (taught.region != nullptr) {
        Solution reached = DirectCalibrate(state.SolverFor(*taught.region).map(), Xy(taught.taught),
                                           taught.region->outside);
        taught.reached[0] = reached.point.x();
        taught.reached[1] = reached.point.y();
      }
      taught.fixpos0 = RoundedForProgramText(PoseToFixture(*state.fixtures[fixture].fix0, taught.reached));
      taught_index[item.get()] = state.taught.size();
      state.taught.push_back(taught);
    }

    for (Target& target : state.targets) {
      if (target.kind != CorrectionKind::kFixture || !target.known) continue;
      const FixtureBinding& binding = state.fixtures[target.fixture];
      if (target.taught_decl != nullptr) {
        auto it = taught_index.find(target.taught_decl);
        if (it == taught_index.end()) continue;  // no FIX_0: reported by bind
        const TaughtPoint& taught = state.taught[it->second];
        for (int a = 0; a < 4; ++a) target.in_frame[a] = taught.fixpos0[a] + target.taught_offset[a];
        target.required = PoseToBase(binding.nominal, target.in_frame);
        target.region = cell.RegionAt(Xy(target.required));
      }
      if (target.region == nullptr) continue;  // reported by regions
      const InverseSolver& solver = state.SolverFor(*target.region);
      Solution solution = solver.Solve(Xy(target.required), target.region->outside);
      target.nominal = {solution.point.x(), solution.point.y(), target.required[2], target.required[3]};
      target.residual_mm = solution.residual_mm;
      target.iterations = solution.iterations;
      target.iteration_bound = solver.iteration_bound();
    }

    for (const TaughtPoint& taught : state.taught) Lower(taught);
  }

 private:
  // The taught declaration becomes the off-line point it is equivalent to.
  static void Lower(const TaughtPoint& taught) {
    auto& stmt = const_cast<ir::Stmt&>(*taught.decl);  // the pass owns the IR it runs on
    auto& decl = std::get<ir::PointDecl>(stmt.node);
    std::string note = fmt::format("taught {} On {}; FIXPOS_0 = FIX_0^-1 * F(taught){}", PrintCoords({taught.taught, {}}), decl.frame,
                                   taught.region != nullptr ? ", F of region " + taught.region->name : "");
    decl.taught = false;
    decl.coords.values = taught.fixpos0;
    stmt.trailing_comment = stmt.trailing_comment.empty() ? " " + note : stmt.trailing_comment + "; " + note;
  }
};

}  // namespace

std::unique_ptr<Pass> CreateFixtureCorrectionPass() { return std::make_unique<FixtureCorrection>(); }

}  // namespace smtcal
