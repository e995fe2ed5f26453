// verify: what the corrected program commands is within what the cell can do.
//
// Assumes: static-inversion and fixture-correction ran.
// Guarantees when it reports no error, for every target whose position is
// known: its command lies within the robot's axis limits; a fixture target
// stays inside its region for every pose the fixture's check limits let a
// cycle run with (any shift up to max_shift_mm, any rotation up to
// max_rotation_deg about the fixture origin), so the runtime's inverse never
// leaves its table; every inverse residual is within kInverseResidualTolMm;
// every Pick and Place fits its region's tolerance with the budget residual +
// repeatability + sensor share (fixture targets). It also estimates each
// Cycle's time and the scan's share of it (state.cycles). Never changes the IR.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <set>

#include <fmt/format.h>

#include "calibration/motion_time.h"
#include "calibration/scan_plan.h"
#include "ir/constant_fold.h"
#include "ir/symbols.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"

namespace smtcal {

namespace {

class VerifyTargets final : public Pass {
 public:
  std::string_view Name() const override { return "verify"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    SMTCAL_CHECK(program.compile != nullptr, "verify runs after bind");
    CompileState& state = *program.compile;
    const cell::Cell& cell = *state.cell;
    std::set<int> unbounded_reported;
    for (Target& target : state.targets) {
      if (!target.known) continue;
      CheckLimits(target, cell.robot, diags);
      CheckTravelHeight(target, cell.robot, diags);
      if (target.region == nullptr) continue;
      if (target.kind == CorrectionKind::kFixture) CheckFixtureMotion(target, state, diags);
      CheckBudget(target, state, unbounded_reported, diags);
    }
    EstimateCycles(state);
  }

 private:
  static SourceRange Where(const Target& target) { return sema::StmtRange(*target.stmt); }

  static void CheckLimits(const Target& target, const cell::Robot& robot, Diagnostics& diags) {
    static constexpr std::array<std::string_view, 4> kAxes = {"x", "y", "z", "u"};
    static constexpr std::array<std::string_view, 4> kUnits = {"mm", "mm", "mm", "°"};
    const Pose4& command = target.kind == CorrectionKind::kUncorrected ? target.required : target.nominal;
    for (int a = 0; a < 4; ++a) {
      if (robot.limits[a].Contains(command[a])) continue;
      diags.Report(DiagKind::TargetBeyondRobotLimits, Where(target), TargetKeyword(*target.stmt), target.text,
                   kAxes[a], FormatMm(command[a]), kUnits[a], FormatMm(robot.limits[a].lo),
                   FormatMm(robot.limits[a].hi), kUnits[a]);
    }
  }

  // The smallest shift that takes the target out of its region, over the four
  // sides of the region and the rotations the fixture may make.
  static void CheckFixtureMotion(const Target& target, const CompileState& state, Diagnostics& diags) {
    const FixtureBinding& binding = state.fixtures[target.fixture];
    const cell::Fixture& fixture = *binding.cell_fixture;
    const cell::Region& region = *target.region;
    Eigen::Vector3d origin = binding.nominal.translation();
    Eigen::Vector2d arm(target.required[0] - origin.x(), target.required[1] - origin.y());
    struct Side {
      std::string_view direction;
      Eigen::Vector2d outward;
      double margin;
    };
    const std::array<Side, 4> sides = {{
        {"-x", {-1, 0}, target.required[0] - region.x_mm.lo},
        {"+x", {1, 0}, region.x_mm.hi - target.required[0]},
        {"-y", {0, -1}, target.required[1] - region.y_mm.lo},
        {"+y", {0, 1}, region.y_mm.hi - target.required[1]},
    }};
    double worst_shift = fixture.max_shift_mm;
    const Side* worst = nullptr;
    double worst_turn = 0;
    for (const Side& side : sides) {
      for (double turn : {-fixture.max_rotation_deg, fixture.max_rotation_deg}) {
        double c = std::cos(Radians(turn)), s = std::sin(Radians(turn));
        Eigen::Vector2d turned(c * arm.x() - s * arm.y(), s * arm.x() + c * arm.y());
        double shift = side.margin - (turned - arm).dot(side.outward);
        if (shift < worst_shift) {
          worst_shift = shift;
          worst = &side;
          worst_turn = (turned - arm).dot(side.outward) > 0 ? turn : 0;
        }
      }
    }
    if (worst == nullptr) return;
    std::string turn_text = worst_turn == 0 ? std::string() : fmt::format(" and turns {:+}°", worst_turn);
    diags.Report(DiagKind::FixtureShiftLeavesRegion, Where(target), TargetKeyword(*target.stmt), target.text,
                 FormatComputedMm(target.required[0]), FormatComputedMm(target.required[1]), region.name, FormatMm(region.x_mm.lo),
                 FormatMm(region.x_mm.hi), FormatMm(region.y_mm.lo), FormatMm(region.y_mm.hi), binding.name,
                 fmt::format("{:.3f}", std::max(0.0, worst_shift)), worst->direction, turn_text,
                 FormatMm(fixture.max_shift_mm), FormatMm(fixture.max_rotation_deg));
  }

  // A Pick or Place comes down from LimZ (or the cell's safe z) to its z: at
  // or above that height the gripper never reaches the part.
  static void CheckTravelHeight(const Target& target, const cell::Robot& robot, Diagnostics& diags) {
    if (!std::holds_alternative<ir::PickPlace>(target.stmt->node)) return;
    const auto& pick_place = std::get<ir::PickPlace>(target.stmt->node);
    const bool limz = pick_place.limz != nullptr;
    if (limz && !sema::FoldConstant(pick_place.limz.get())) return;  // known only at run time
    const double z = target.required[2];
    const double from = LimZOf(*target.stmt, robot);
    if (z < from) return;
    const bool pick = pick_place.kind == ir::PickPlaceKind::Pick;
    diags.Report(DiagKind::PickPlaceAtTravelHeight, Where(target), TargetKeyword(*target.stmt), target.text,
                 FormatMm(z), limz ? fmt::format("its LimZ {}", FormatMm(from))
                                   : fmt::format("the cell's safe_limz_mm = {}", FormatMm(from)),
                 pick ? "the gripper would reach for the part" : "the part would be released",
                 pick ? "pick" : "place", FormatMm(from));
  }

  static std::string BudgetParts(const ErrorBudget& budget) {
    std::string text;
    for (std::size_t k = 0; k < kErrorSources; ++k) {
      const ErrorShare& share = budget.shares[k];
      if (share.BudgetMm() == 0) continue;
      text += fmt::format("{}{} {:.4f}", text.empty() ? "" : ", ", ErrorSourceName(static_cast<ErrorSource>(k)),
                          share.BudgetMm());
    }
    return text;
  }

  // Which tables to measure at what pitch when the interpolation between
  // their nodes takes too much of a budget: the target's own region and the
  // regions under its fixture's trips. Each table's advice is its grid
  // advice (AdviseGrid: what cell check, table check and measure plan say of
  // it); when every table is within its share and the trips still carry too
  // much, the pitch at which the budget would fit (the departures scale with
  // the pitch squared; everything else stays).
  static std::string InterpolationHint(const ErrorBudget& budget, const Target& target, const CompileState& state) {
    const ErrorShare& part = budget[ErrorSource::kInterpolation];
    const double own = target.region->interpolation.NormMm();
    std::vector<const cell::Region*> regions = {target.region};
    if (target.fixture >= 0) {
      const FixtureErrorModel& model = state.ErrorModelFor(*state.fixtures[target.fixture].cell_fixture);
      for (int r : model.trip_regions()) {
        const cell::Region* region = r >= 0 ? &state.cell->regions[static_cast<std::size_t>(r)] : nullptr;
        if (region != nullptr && std::find(regions.begin(), regions.end(), region) == regions.end()) {
          regions.push_back(region);
        }
      }
    }
    std::string names, advice;
    double pitch = 0;
    bool declared = false;
    for (const cell::Region* region : regions) {
      names += fmt::format("{}'{}'", names.empty() ? "" : ", ", region->name);
      pitch = std::max(pitch, region->interpolation.PitchMm());
      const GridAdvice grid = AdviseGrid(region->interpolation, region->tolerance_mm);
      if (!grid.coarse) continue;
      advice += fmt::format("{}'{}' at a pitch of at most {:.1f} mm", advice.empty() ? "" : ", ", region->name,
                            grid.pitch_mm);
      declared = declared || grid.check_points_would_settle;
    }
    const std::string through_trips =
        target.fixture >= 0 ? fmt::format(" and {:.4f} mm more through the trips", part.bound_mm - own) : std::string();
    const std::string noise =
        part.SigmaMm() > 0 ? fmt::format(" (and the check points' noise, σ {:.4f} mm)", part.SigmaMm()) : std::string();
    std::string text = fmt::format(
        "between the nodes of the table{} of region{} {} (largest pitch {} mm) the robot's error may depart from the "
        "interpolation by {:.4f} mm here{}{}, {}; ",
        regions.size() == 1 ? "" : "s", regions.size() == 1 ? "" : "s", names, fmt::format("{:.1f}", pitch), own,
        through_trips, noise, InterpolationKindDescription(target.region->interpolation.Kind()));
    if (!advice.empty()) {
      text += "measure " + advice;
      if (declared) text += ", or measure check points at the cell centres (docs/error-tables.md)";
      return text;
    }
    const double allowed = target.region->tolerance_mm - (target.budget_mm - part.bound_mm);
    const double new_pitch = PitchForShare(pitch, part.bound_mm, allowed);
    text += fmt::format("every table is within {:.0f} % of its tolerance between its nodes, but together they take "
                        "too much of this budget; ",
                        100 * kInterpolationShareOfTolerance);
    text += new_pitch > 0 ? fmt::format("measure {} at a pitch of at most {:.1f} mm", regions.size() == 1 ? "it" : "them",
                                        new_pitch)
                          : std::string("no pitch fits while the other parts take the whole tolerance");
    return text;
  }

  // What to do about the largest part of a budget.
  static std::string BudgetHint(ErrorSource largest, const ErrorBudget& budget, const Target& target,
                                const CompileState& state) {
    const cell::Fixture* fixture = target.fixture >= 0 ? state.fixtures[target.fixture].cell_fixture : nullptr;
    switch (largest) {
      case ErrorSource::kInterpolation:
        return InterpolationHint(budget, target, state);
      case ErrorSource::kUncalibratedTrips:
        return fmt::format("trips of fixture '{}' lie outside every calibrated table, so the robot's own error there "
                           "moves the whole board: calibrate a region under its markers (docs/cell.md)",
                           fixture != nullptr ? fixture->name : "");
      case ErrorSource::kSensor:
        if (fixture != nullptr && fixture->estimator == cell::Estimator::kPaper) {
          return fmt::format("fixture '{}' uses estimator = \"paper\" (Eq. 4, the default when the fixture names "
                             "none), which extrapolates each edge from two trips; set estimator = \"rigid\" in its "
                             "[[fixture]] to fit all trips at once (docs/periphery.md)",
                             fixture->name);
        }
        return "a more accurate marker sensor, markers farther apart or more trips would shrink it";
      case ErrorSource::kLatency:
        return "lower the fixture's scan_speed_mm_s (or the controller's servo period, robot.servo_period_s)";
      case ErrorSource::kScanRepeatability:
      case ErrorSource::kRepeatability:
        return "the robot's repeatability alone takes this much: the tolerance cannot be met with this robot";
      case ErrorSource::kTable:
      case ErrorSource::kTripTables:
        return "measure the table with more repetitions (its node means are this uncertain)";
      case ErrorSource::kResidual:
        return "the inverse calibration did not converge here; check the table (smtcal table check)";
    }
    return "";
  }

  void CheckBudget(Target& target, const CompileState& state, std::set<int>& unbounded_reported,
                   Diagnostics& diags) {
    if (target.kind == CorrectionKind::kUncorrected) return;
    const ErrorBudget budget = state.BudgetOf(target);
    const ErrorShare total = budget.Total();
    target.budget_bounded = budget.bounded;
    target.budget_mm = total.BudgetMm();
    target.worst_case_mm = total.worst_mm;
    if (!std::holds_alternative<ir::PickPlace>(target.stmt->node) || !state.report_budget_findings) return;
    if (!budget.bounded) {
      if (!unbounded_reported.insert(target.fixture).second) return;
      const FixtureBinding& binding = state.fixtures[target.fixture];
      const FixtureErrorModel& model = state.ErrorModelFor(*binding.cell_fixture);
      std::string trips;
      for (std::size_t k : model.UncalibratedTrips()) trips += (trips.empty() ? "" : ", ") + TripName(k);
      diags.Report(DiagKind::FixtureBudgetUnbounded, sema::StmtRange(*binding.decl), binding.name,
                   model.defined() ? trips : std::string("(the nominal trips define no pose)"));
      return;
    }
    if (target.budget_mm <= target.region->tolerance_mm) return;
    const ErrorSource largest = budget.Largest();
    Diagnostic* diag = diags.Report(DiagKind::BudgetOverTolerance, Where(target), TargetKeyword(*target.stmt),
                                    target.text, fmt::format("{:.4f}", target.budget_mm),
                                    FormatMm(target.region->tolerance_mm), target.region->name,
                                    ErrorSourceDescription(largest),
                                    fmt::format("{:.4f}", budget[largest].BudgetMm()),
                                    BudgetHint(largest, budget, target, state));
    Diagnostics::AddNote(diag, Where(target), fmt::format("the budget's parts, each alone at 4 sigma (mm): {}",
                                                          BudgetParts(budget)));
  }

  // ---------------------------------------------------------------- cycle time

  struct Position {
    Pose4 pose{};
    bool known = false;
  };

  static double TravelTime(const cell::Robot& robot, const Pose4& from, const Pose4& to) {
    double xy = MoveTime(std::hypot(to[0] - from[0], to[1] - from[1]), robot.xy_speed_mm_s, robot.xy_accel_mm_s2);
    double u = MoveTime(to[3] - from[3], robot.u_speed_deg_s, robot.u_accel_deg_s2);
    return std::max(xy, u);
  }

  // A Jump (and the approach of a Pick or Place): up to LimZ, across, down.
  static double JumpTime(const cell::Robot& robot, const Pose4& from, const Pose4& to, double limz) {
    double up = MoveTime(limz - from[2], robot.z_speed_mm_s, robot.z_accel_mm_s2);
    double down = MoveTime(limz - to[2], robot.z_speed_mm_s, robot.z_accel_mm_s2);
    return up + TravelTime(robot, from, to) + down;
  }

  static double LimZOf(const ir::Stmt& stmt, const cell::Robot& robot) {
    const ir::Expr* limz = nullptr;
    if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) limz = pick->limz.get();
    if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) limz = motion->limz.get();
    std::optional<sema::Constant> value = sema::FoldConstant(limz);
    return value ? value->value : robot.safe_limz_mm;
  }

  // The marker scan as the runtime drives it (calibration/scan_plan.h), from
  // where the robot stands: in the steady state (predicted, when the fixture
  // predicts), the first cycle's (in full) and the floor; it leaves the robot
  // where the steady state's ends.
  static void ScanTimes(const cell::Robot& robot, const FixtureBinding& binding, Position& at,
                        CycleEstimate& estimate) {
    std::optional<ScanPoint> from;
    if (at.known) from = ScanPoint(at.pose[0], at.pose[1], at.pose[2]);
    const ScanTiming steady = smtcal::ScanTime(robot, *binding.cell_fixture, from, ScanSearch::kPredicted);
    estimate.scan_s = steady.seconds;
    estimate.first_scan_s = smtcal::ScanTime(robot, *binding.cell_fixture, from, ScanSearch::kFull).seconds;
    estimate.scan_floor_s = ScanFloor(robot, *binding.cell_fixture, from).seconds;
    at = {{steady.end.x(), steady.end.y(), steady.end.z(), at.known ? at.pose[3] : 0.0}, true};
  }

  // Where the robot is commanded for a target (base frame; a fixture
  // target's at the fixture's nominal pose).
  static const Pose4& Command(const Target& target) {
    return target.kind == CorrectionKind::kUncorrected ? target.required : target.nominal;
  }

  // Where a cycle leaves the robot: its last known target. The cycle repeats,
  // so the next one, and its scan, start there.
  static Position CycleEnd(const CompileState& state, const std::vector<TraceEvent>& events) {
    Position end;
    for (const TraceEvent& event : events) {
      if (event.kind != TraceEvent::Kind::kMotion) continue;
      const Target& target = state.targets[event.target];
      if (target.known) end = {Command(target), true};
    }
    return end;
  }

  static void EstimateCycles(CompileState& state) {
    const cell::Robot& robot = state.cell->robot;
    state.cycles.clear();
    for (const auto& [stmt, events] : state.cycle_traces) {
      const auto& cycle = std::get<ir::Cycle>(stmt->node);
      CycleEstimate estimate;
      estimate.cycle = stmt;
      estimate.fixture = cycle.fixture;
      Position at = CycleEnd(state, events);
      int fixture = state.FindFixture(cycle.fixture);
      if (fixture >= 0) ScanTimes(robot, state.fixtures[fixture], at, estimate);
      for (const TraceEvent& event : events) {
        if (event.kind == TraceEvent::Kind::kWait) {
          estimate.motion_s += event.wait_s;
          continue;
        }
        const Target& target = state.targets[event.target];
        if (!target.known) continue;
        const Pose4& to = Command(target);
        bool jump = !std::holds_alternative<ir::Motion>(target.stmt->node) ||
                    std::get<ir::Motion>(target.stmt->node).kind == ir::MotionKind::Jump;
        if (at.known) {
          estimate.motion_s += jump ? JumpTime(robot, at.pose, to, LimZOf(*target.stmt, robot))
                                    : TravelTime(robot, at.pose, to) +
                                          MoveTime(to[2] - at.pose[2], robot.z_speed_mm_s, robot.z_accel_mm_s2);
        }
        if (const auto* pick = std::get_if<ir::PickPlace>(&target.stmt->node)) {
          bool place = pick->kind == ir::PickPlaceKind::Place;
          estimate.motion_s += place ? robot.place_time_s : robot.pick_time_s;
          estimate.placements += place ? 1 : 0;
        }
        at = {to, true};
      }
      state.cycles.push_back(estimate);
    }
    std::sort(state.cycles.begin(), state.cycles.end(), [](const CycleEstimate& a, const CycleEstimate& b) {
      return std::tie(a.cycle->loc.file, a.cycle->loc.line, a.cycle->loc.column) <
             std::tie(b.cycle->loc.file, b.cycle->loc.line, b.cycle->loc.column);
    });
  }
};

}  // namespace

std::unique_ptr<Pass> CreateVerifyTargetsPass() { return std::make_unique<VerifyTargets>(); }

}  // namespace smtcal
