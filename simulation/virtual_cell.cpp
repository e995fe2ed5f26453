// The virtual cell: a compiled program's cycles on a robot with true errors
// (simulation/virtual_cell.h; docs/simulate.md says what is modelled and why).
#include "simulation/virtual_cell.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>

#include "base/check.h"

#include "calibration/fixture_estimation.h"
#include "calibration/fixture_geometry.h"
#include "simulation/sim_random.h"

namespace smtcal {

std::string_view SimModeName(SimMode mode) {
  switch (mode) {
    case SimMode::kNone: return "none";
    case SimMode::kMeanOffset: return "mean-offset";
    case SimMode::kTablesOnly: return "tables";
    case SimMode::kPeripheryOnly: return "periphery";
    case SimMode::kPaper: return "paper";
    case SimMode::kImproved: return "improved";
  }
  return "?";
}

std::string_view SimModeDescription(SimMode mode) {
  switch (mode) {
    case SimMode::kNone: return "no correction: commands as written, board at its nominal pose";
    case SimMode::kMeanOffset: return "task origin shifted by the region's table means (the paper's origin shift)";
    case SimMode::kTablesOnly: return "error tables only, no periphery calibration";
    case SimMode::kPeripheryOnly:
      return "periphery only, as the paper's production cell: raw trips, no scan checks, no tables";
    case SimMode::kPaper: return "both, as the paper: raw trips, no scan checks, tables, Eq. 9 in commanded space";
    case SimMode::kImproved:
      return "both, improved: direct-calibrated trips, least squares, Eq. 7 in actual space, tables";
  }
  return "?";
}

bool UsesPeriphery(SimMode mode) {
  return mode == SimMode::kPeripheryOnly || mode == SimMode::kPaper || mode == SimMode::kImproved;
}

bool UsesCellChecks(SimMode mode) { return mode == SimMode::kImproved; }

long PlannedPlacements(const CompileState& state, const SimOptions& options) {
  long per_round = 0;  // every Cycle statement once
  for (const CycleEstimate& estimate : state.cycles) {
    for (const TraceEvent& event : state.cycle_traces.at(estimate.cycle)) {
      if (event.kind != TraceEvent::Kind::kMotion) continue;
      const Target& target = state.targets[event.target];
      if (target.is_placement() && target.known) ++per_round;
    }
  }
  return per_round * options.cycles;
}

double Percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0;
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

namespace {

// One Place of a cycle's trace, with everything every mode needs.
struct PlacementPlan {
  const Target* target = nullptr;
  int fixture = -1;                       // index into CompileState::fixtures; -1: base frame
  Eigen::Vector2d in_frame = Eigen::Vector2d::Zero();   // the compiled program's point (fixture or base frame)
  Eigen::Vector2d true_point = Eigen::Vector2d::Zero(); // where the part truly belongs, same frame
  bool taught = false;
  Eigen::Vector2d taught_command = Eigen::Vector2d::Zero();  // ROBOT_0 (+ offset): replayed as taught
  Eigen::Vector2d mean_shift = Eigen::Vector2d::Zero();      // the region's table means
  double tolerance_mm = 0;
  int region = -1;  // index into the cell's regions: where the process figures go
};

struct CyclePlan {
  int fixture = -1;
  int cell_fixture = -1;  // the fixture's index in the cell (the records')
  std::vector<PlacementPlan> placements;
  double scan_s = 0, motion_s = 0, total_s = 0;
};

Eigen::Vector2d MeanShift(const cell::Region* region) {
  if (region == nullptr) return Eigen::Vector2d::Zero();
  const TableStats stats = ComputeTableStats(region->table);
  return {stats.shift_x_mm, stats.shift_y_mm};
}

// A draw of where the board truly is this cycle.
Eigen::Affine3d DrawBoard(const cell::Fixture& fixture, const BoardPoseModel& model, SimRandom& random) {
  Eigen::Vector2d shift = model.fixed_shift_mm;
  double rotation_deg = model.fixed_rotation_deg;
  if (model.shift != ShiftDistribution::kFixed) {
    constexpr int kMaxRedraws = 1000;  // a redraw is needed with probability < 1 % at sane settings
    for (int attempt = 0; attempt < kMaxRedraws; ++attempt) {
      const double u = random.Uniform01(), v = random.Uniform01();
      const double angle = 2 * std::numbers::pi * v;
      switch (model.shift) {
        case ShiftDistribution::kExponential:
          shift = -model.shift_scale_mm * std::log(1 - u) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
          break;
        case ShiftDistribution::kNormal:
          shift = model.shift_scale_mm * Eigen::Vector2d(random.Normal(), random.Normal());
          break;
        case ShiftDistribution::kUniform:
          shift = model.shift_scale_mm * std::sqrt(u) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
          break;
        case ShiftDistribution::kFixed: break;
      }
      if (shift.norm() <= model.shift_max_mm) break;
      shift = shift.normalized() * model.shift_max_mm;  // kept if every redraw fails
    }
    for (int attempt = 0; attempt < kMaxRedraws; ++attempt) {
      rotation_deg = model.rotation_sd_deg * random.Normal();
      if (std::abs(rotation_deg) <= model.rotation_max_deg) break;
      rotation_deg = std::copysign(model.rotation_max_deg, rotation_deg);
    }
  }
  return PlanarFix(fixture.origin_mm + shift, (fixture.angle_deg + rotation_deg) * kRadPerDeg);
}

// The pose a cell without checks (the paper's) takes from a scan the cell's
// checks failed: the estimate, whenever there is one. A missing trip leaves
// an edge without its line and trips that define no pose leave no crossing:
// those stop the cycle (nullopt). The trip window stops a scan before its
// estimate, so the estimate is made here.
std::optional<Eigen::Affine3d> UncheckedPose(const cell::Fixture& fixture, const ScanResult& scan) {
  const ScanCheck failed = scan.FirstFailure()->check;
  if (failed == ScanCheck::kMissingTrip || failed == ScanCheck::kDegenerate) return std::nullopt;
  if (scan.estimate) return scan.estimate->fix;
  std::vector<Eigen::Vector2d> trips;
  for (const std::optional<Eigen::Vector2d>& trip : scan.trips) trips.push_back(*trip);
  const std::optional<FixEstimate> estimate = EstimateFix(fixture, scan.expected, trips, scan.estimator);
  if (!estimate) return std::nullopt;
  return estimate->fix;
}

// Where the robot's real path along the commanded leg (from, to) crosses the
// true edge segment (a, b) moved `sensor_mm` along its normal, with the robot
// `robot_mm` off its path: the commanded point then, or nullopt when the real
// path does not cross the visible edge.
// `late_mm`: how far past the crossing the controller latched the trip,
// along the leg. `actual_of`: where the robot really is for a command.
template <typename Actual>
std::optional<Eigen::Vector2d> SimulateTrip(const Actual& actual_of, const Eigen::Vector2d& from,
                                            const Eigen::Vector2d& to, const Eigen::Vector2d& a,
                                            const Eigen::Vector2d& b, double sensor_mm,
                                            const Eigen::Vector2d& robot_mm, double late_mm) {
  const Eigen::Vector2d along = b - a;
  const Eigen::Vector2d normal = Eigen::Vector2d(-along.y(), along.x()).normalized();
  const double offset = normal.dot(a) + sensor_mm;
  auto real = [&](double t) -> Eigen::Vector2d {
    const Eigen::Vector2d commanded = from + t * (to - from);
    const Eigen::Vector2d actual = actual_of(commanded);
    return actual + robot_mm;
  };
  auto side = [&](double t) { return normal.dot(real(t)) - offset; };
  // F_true is piecewise bilinear and close to the identity: a straight leg
  // crosses a straight edge once; coarse steps find the bracket, bisection the point.
  constexpr int kSteps = 16;
  constexpr int kBisections = 60;
  double t0 = 0, g0 = side(0);
  for (int i = 1; i <= kSteps; ++i) {
    const double t1 = static_cast<double>(i) / kSteps, g1 = side(t1);
    if ((g0 <= 0) != (g1 <= 0)) {
      double lo = t0, hi = t1, glo = g0;
      for (int k = 0; k < kBisections; ++k) {
        const double mid = 0.5 * (lo + hi), gmid = side(mid);
        if ((gmid <= 0) == (glo <= 0)) {
          lo = mid;
          glo = gmid;
        } else {
          hi = mid;
        }
      }
      const double t = 0.5 * (lo + hi);
      const double s = (real(t) - a).dot(along) / along.squaredNorm();
      if (s < 0 || s > 1) return std::nullopt;  // past the end of the visible edge
      return from + t * (to - from) + late_mm * (to - from).normalized();
    }
    t0 = t1;
    g0 = g1;
  }
  return std::nullopt;
}

class Simulator {
 public:
  Simulator(const CompileState& state, const TruthSpec& truth, const SimOptions& options)
      : state_(state),
        cell_(*state.cell),
        truth_(truth),
        options_(options),
        random_(options.seed),
        field_(cell_, truth, random_.Split()),
        corrector_(cell_.regions) {
    repeatability_mm_ = truth.noise ? truth.repeatability_mm.value_or(cell_.robot.repeatability_mm) : 0.0;
    servo_period_s_ = truth.noise ? truth.servo_period_s.value_or(cell_.robot.servo_period_s) : 0.0;
    PlanCycles();
    PaperTeachPoses();
  }

  const TrueField& field() const { return field_; }

  SimResult Run() {
    SimResult result;
    result.options = options_;
    result.unknown_targets = unknown_targets_;
    result.tolerance_mm = min_tolerance_mm_;
    for (SimMode mode : kSimModes) {
      ModeResult m;
      m.mode = mode;
      m.scan_share = UsesPeriphery(mode) && total_s_ > 0 ? scan_s_ / total_s_ : 0.0;
      m.by_region.resize(cell_.regions.size());
      result.modes.push_back(m);
    }
    long per_round = 0;  // the placements of one pass through the Cycle statements
    for (const CyclePlan& plan : plans_) per_round += static_cast<long>(plan.placements.size());
    const long planned = per_round * options_.cycles;
    // Every placed part's error is kept: room for all of them at once, so the
    // memory is what PlannedPlacements says, not twice that while a vector grows.
    for (ModeResult& m : result.modes) m.errors_um.reserve(static_cast<std::size_t>(planned));
    scatter_stride_ = std::max<long>(1, planned / std::max<long>(1, static_cast<long>(options_.scatter_points)));
    // A stride sharing a factor with the placements per round would keep the
    // same few parts of every cycle (a stride of 200 with 40 parts a round
    // keeps only the first): the picture must show every part.
    while (scatter_stride_ > 1 && per_round > 1 && std::gcd(scatter_stride_, per_round) != 1) ++scatter_stride_;
    previous_.assign(kSimModes.size(), std::vector<std::optional<Eigen::Affine3d>>(state_.fixtures.size()));
    record_cycles_.assign(cell_.fixtures.size(), 0);
    for (int n = 0; n < options_.cycles; ++n) {
      for (const CyclePlan& plan : plans_) {
        RunCycle(plan, n + 1, result);
        ++result.cycles;
        result.placements_planned += static_cast<long>(plan.placements.size());
      }
    }
    return result;
  }

 private:
  static cell::Estimator ImprovedEstimator(const cell::Fixture* fixture) {
    return fixture != nullptr && fixture->estimator != cell::Estimator::kPaper ? fixture->estimator
                                                                                : cell::Estimator::kRigid;
  }

  void PlanCycles() {
    for (const CycleEstimate& estimate : state_.cycles) {
      CyclePlan plan;
      plan.fixture = state_.FindFixture(estimate.fixture);
      plan.scan_s = estimate.scan_s;
      plan.motion_s = estimate.motion_s;
      plan.total_s = estimate.total_s();
      for (std::size_t k = 0; k < cell_.fixtures.size() && plan.fixture >= 0; ++k) {
        if (&cell_.fixtures[k] == state_.fixtures[plan.fixture].cell_fixture) plan.cell_fixture = static_cast<int>(k);
      }
      scan_s_ += plan.fixture >= 0 ? estimate.scan_s : 0.0;
      total_s_ += estimate.total_s();
      for (const TraceEvent& event : state_.cycle_traces.at(estimate.cycle)) {
        if (event.kind != TraceEvent::Kind::kMotion) continue;
        const Target& target = state_.targets[event.target];
        if (!target.is_placement()) continue;
        if (!target.known) {
          ++unknown_targets_;
          continue;
        }
        plan.placements.push_back(PlanPlacement(target));
      }
      plans_.push_back(std::move(plan));
    }
  }

  PlacementPlan PlanPlacement(const Target& target) {
    PlacementPlan p;
    p.target = &target;
    p.fixture = target.kind == CorrectionKind::kFixture ? target.fixture : -1;
    p.in_frame = p.fixture >= 0 ? Xy(target.in_frame) : Xy(target.required);
    p.true_point = p.in_frame;
    p.mean_shift = MeanShift(cell_.RegionAt(Xy(target.required)));
    p.tolerance_mm = target.region != nullptr ? target.region->tolerance_mm : 0.1;
    for (std::size_t r = 0; r < cell_.regions.size(); ++r) {
      if (&cell_.regions[r] == target.region) p.region = static_cast<int>(r);
    }
    min_tolerance_mm_ = min_tolerance_mm_ == 0 ? p.tolerance_mm : std::min(min_tolerance_mm_, p.tolerance_mm);
    if (p.fixture >= 0 && target.taught_decl != nullptr) {
      const FixtureBinding& binding = state_.fixtures[p.fixture];
      for (const TaughtPoint& taught : state_.taught) {
        if (taught.decl != target.taught_decl || !binding.fix0) continue;
        // The board stood at FIX_0 when the point was taught, and the robot
        // really was at F_true(ROBOT_0).
        const Eigen::Vector2d offset(target.taught_offset[0], target.taught_offset[1]);
        p.taught = true;
        p.taught_command = Xy(taught.taught) + binding.fix0->linear().topLeftCorner<2, 2>() * offset;
        p.true_point = ToFixtureFrame(*binding.fix0, field_.Actual(Xy(taught.taught))) + offset;
      }
    }
    return p;
  }

  // FIX_0 of the paper's modes: the teach-time trips, raw, through the
  // fixture's estimator. The estimate is used even when its checks fail (the
  // operator accepted the teach scan); without one, the compiler's FIX_0.
  void PaperTeachPoses() {
    for (const FixtureBinding& binding : state_.fixtures) {
      std::optional<Eigen::Affine3d> fix0 = binding.fix0;
      const cell::Fixture& fixture = *binding.cell_fixture;
      if (!fixture.teach_trips_mm.empty()) {
        std::vector<std::optional<Eigen::Vector2d>> trips(fixture.teach_trips_mm.begin(),
                                                          fixture.teach_trips_mm.end());
        ScanOptions scan_options;
        scan_options.estimator = fixture.estimator;
        ScanResult scan = ScanFixture(fixture, trips, scan_options);
        if (scan.estimate) fix0 = scan.estimate->fix;
      }
      paper_fix0_.push_back(fix0);
    }
  }

  Eigen::Vector2d Invert(const Eigen::Vector2d& required) const { return corrector_.Invert(required).command; }

  // What mode `mode` commands for a placement, given this cycle's FIX_n (periphery modes).
  Eigen::Vector2d Command(SimMode mode, const PlacementPlan& p, const Eigen::Affine3d* fix_n) const {
    if (p.fixture < 0) {
      const Eigen::Vector2d& required = p.in_frame;
      switch (mode) {
        case SimMode::kNone:
        case SimMode::kPeripheryOnly: return required;
        case SimMode::kMeanOffset: return required - p.mean_shift;
        default: return Invert(required);
      }
    }
    const FixtureBinding& binding = state_.fixtures[p.fixture];
    switch (mode) {
      case SimMode::kNone:
        return p.taught ? p.taught_command : ToBase(binding.nominal, p.in_frame);
      case SimMode::kMeanOffset:
        return p.taught ? p.taught_command : ToBase(binding.nominal, p.in_frame) - p.mean_shift;
      case SimMode::kTablesOnly:
        return p.taught ? p.taught_command : Invert(ToBase(binding.nominal, p.in_frame));
      case SimMode::kPeripheryOnly:
      case SimMode::kPaper: {
        if (p.taught && paper_fix0_[p.fixture]) {
          // Eq. 9 on commanded coordinates: ROBOT_n = FIX_n FIX_0^-1 ROBOT_0.
          return ToBase(*fix_n, ToFixtureFrame(*paper_fix0_[p.fixture], p.taught_command));
        }
        const Eigen::Vector2d required = ToBase(*fix_n, p.in_frame);
        return mode == SimMode::kPaper ? Invert(required) : required;
      }
      case SimMode::kImproved: return Invert(ToBase(*fix_n, p.in_frame));
    }
    return p.in_frame;
  }

  ScanOptions ScanOptionsFor(SimMode mode, const cell::Fixture& fixture, std::size_t mode_index,
                             int fixture_index) const {
    ScanOptions scan_options;
    // The paper's modes take the fixture's estimator as the cell declares it:
    // Eq. 4 where the cell says "paper"; on a layout whose short marker edges
    // make Eq. 4 useless (the example's) the cell says "rigid", and the
    // paper's method there is the rigid fit on raw trips.
    scan_options.estimator = mode == SimMode::kImproved ? ImprovedEstimator(&fixture) : fixture.estimator;
    scan_options.regions = mode == SimMode::kImproved ? &cell_.regions : nullptr;
    scan_options.previous = previous_[mode_index][static_cast<std::size_t>(fixture_index)];
    return scan_options;
  }

  Eigen::Vector2d RobotNoise() {
    const double u = random_.Uniform(-1, 1), v = random_.Uniform(-1, 1);
    return repeatability_mm_ * Eigen::Vector2d(u, v);
  }

  // Where the robot really is for a command this cycle: the true field and
  // the drift of its scale.
  Eigen::Vector2d Actual(const Eigen::Vector2d& commanded) const {
    const Eigen::Vector2d actual = field_.Actual(commanded);
    if (drift_scale_ == 0) return actual;
    return actual + drift_scale_ * (commanded - truth_.drift.robot_scale_about_mm);
  }

  void RunCycle(const CyclePlan& plan, int cycle, SimResult& result) {
    const DriftModel& drift = truth_.drift;
    const double steps = drift.Steps(cycle);
    drift_scale_ = 1e-6 * drift.robot_scale_ppm_per_cycle * steps;
    // The draws, in a fixed order whatever the options: fault decisions,
    // board pose, scan noise, placement noise.
    const bool missed = random_.Chance(options_.missed_trip_rate);
    const double missed_pick = random_.Uniform01();
    const bool dirty = random_.Chance(options_.dirty_marker_rate);
    const double dirty_pick = random_.Uniform01(), dirty_sign = random_.Uniform01() < 0.5 ? -1.0 : 1.0;
    const bool beyond = random_.Chance(options_.board_beyond_rate);
    const double beyond_angle = random_.Uniform(0, 2 * std::numbers::pi), beyond_extra = random_.Uniform(0.1, 1.0);

    const cell::Fixture* fixture = plan.fixture >= 0 ? state_.fixtures[plan.fixture].cell_fixture : nullptr;
    Eigen::Affine3d board = Eigen::Affine3d::Identity();
    std::vector<std::optional<Eigen::Vector2d>> trips;
    bool injected = false;
    if (fixture != nullptr) {
      board = DrawBoard(*fixture, truth_.board, random_);
      if (steps > 0) {
        board = PlanarFix(FixOrigin(board) + steps * drift.board_mm_per_cycle,
                          FixAngleRad(board) + steps * drift.board_deg_per_cycle * kRadPerDeg);
      }
      if (beyond) {
        const double shift = fixture->max_shift_mm + beyond_extra;
        board = PlanarFix(fixture->origin_mm + shift * Eigen::Vector2d(std::cos(beyond_angle), std::sin(beyond_angle)),
                          FixAngleRad(board));
        ++result.injected_beyond;
      }
      trips = Scan(*fixture, board, steps);
      if (missed && !trips.empty()) {
        trips[std::min(trips.size() - 1, static_cast<std::size_t>(missed_pick * static_cast<double>(trips.size())))] =
            std::nullopt;
        ++result.injected_missed;
      }
      if (dirty && !trips.empty()) {
        const std::size_t k =
            std::min(trips.size() - 1, static_cast<std::size_t>(dirty_pick * static_cast<double>(trips.size())));
        if (trips[k]) *trips[k] += dirty_sign * options_.dirty_marker_mm * DirectionOfLeg(*fixture, k);
        ++result.injected_dirty;
      }
      injected = missed || dirty || beyond;
      result.injected_cycles += injected ? 1 : 0;
    }
    std::vector<Eigen::Vector2d> noise;
    noise.reserve(plan.placements.size());
    for (std::size_t j = 0; j < plan.placements.size(); ++j) noise.push_back(RobotNoise());

    for (std::size_t m = 0; m < kSimModes.size(); ++m) {
      const SimMode mode = kSimModes[m];

      ModeResult& out = result.modes[m];
      ++out.cycles;
      std::optional<Eigen::Affine3d> fix_n;
      if (UsesPeriphery(mode) && fixture != nullptr) {
        ScanResult scan = ScanFixture(*fixture, trips, ScanOptionsFor(mode, *fixture, m, plan.fixture));
        if (options_.record && mode == SimMode::kImproved && plan.cell_fixture >= 0) {
          long& number = record_cycles_[static_cast<std::size_t>(plan.cell_fixture)];
          result.records.push_back(RecordOfScan(plan.cell_fixture, ++number, clock_s_ + plan.scan_s, scan));
        }
        fix_n = scan.fix;
        if (!scan.ok()) {
          std::string check(ScanCheckName(scan.FirstFailure()->check));
          if (!UsesCellChecks(mode)) {
            fix_n = UncheckedPose(*fixture, scan);
            if (fix_n) {
              ++out.would_stop;
              ++out.would_stop_checks[check];
            } else if (scan.FirstFailure()->check == ScanCheck::kTripWindow) {
              check = ScanCheckName(ScanCheck::kDegenerate);  // what stopped it here
            }
          }
          if (!fix_n) {
            ++out.faults;
            out.faults_injected += injected ? 1 : 0;
            ++out.fault_checks[check];
            continue;  // the cycle stops: nothing placed
          }
        }
        previous_[m][static_cast<std::size_t>(plan.fixture)] = fix_n;
      }
      for (std::size_t j = 0; j < plan.placements.size(); ++j) {
        const PlacementPlan& p = plan.placements[j];
        const Eigen::Affine3d* fix = fix_n ? &*fix_n : p.fixture >= 0 ? &state_.fixtures[p.fixture].nominal : nullptr;
        const Eigen::Vector2d landed = Actual(Command(mode, p, fix)) + noise[j];
        const Eigen::Vector2d belongs = p.fixture >= 0 ? ToBase(board, p.true_point) : p.true_point;
        const Eigen::Vector2d error = landed - belongs;
        const double error_mm = error.norm();
        ++out.placements;
        const bool within = error_mm <= p.tolerance_mm;
        out.within += within ? 1 : 0;
        if (!within && injected) ++out.misplaced_injected;
        out.errors_um.push_back(error_mm * 1000);
        out.overall.Add(error, p.tolerance_mm);
        if (p.region >= 0) out.by_region[static_cast<std::size_t>(p.region)].Add(error, p.tolerance_mm);
        const long slot = placement_slot_ + static_cast<long>(j);
        if (slot % scatter_stride_ == 0 && out.scatter_um.size() < options_.scatter_points) {
          out.scatter_um.push_back(error * 1000);
        }
      }
    }
    placement_slot_ += static_cast<long>(plan.placements.size());
    clock_s_ += plan.total_s;
  }

  // The commanded trips of one scan with the board at `board`.
  // `steps`: the drift's steps this cycle (DriftModel).
  std::vector<std::optional<Eigen::Vector2d>> Scan(const cell::Fixture& fixture, const Eigen::Affine3d& board,
                                                   double steps) {
    const Eigen::Affine3d nominal = NominalFix(fixture);
    const DriftModel& drift = truth_.drift;
    const double accuracy = (truth_.noise ? truth_.sensor_accuracy_mm.value_or(fixture.sensor_accuracy_mm) : 0.0) +
                            steps * drift.sensor_accuracy_mm_per_cycle;
    const double threshold_mm = steps * drift.sensor_threshold_mm_per_cycle;
    const double latency_mm = fixture.TripLatchSpeedMmS() * servo_period_s_;
    const std::vector<ExpectedTrip>& expected = ExpectedFor(fixture);
    std::vector<std::optional<Eigen::Vector2d>> trips;
    std::vector<std::size_t> on_path(fixture.scan_paths.size(), 0);
    auto actual = [this](const Eigen::Vector2d& commanded) { return Actual(commanded); };
    for (const ExpectedTrip& e : expected) {
      const Eigen::Vector2d robot = RobotNoise();
      double sensor = accuracy * random_.Uniform(-1, 1);
      const double late = latency_mm * random_.Uniform01();
      const auto& points = fixture.scan_paths[e.path].points;
      const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(e.edge)];
      const Eigen::Vector2d from = ToBase(nominal, points[e.leg]), to = ToBase(nominal, points[e.leg + 1]);
      const Eigen::Vector2d a = ToBase(board, edge.from), b = ToBase(board, edge.to);
      // Every path starts off the markers, so its trips alternate: entering
      // a marker, leaving it. A threshold that sees the markers smaller
      // moves each edge line into its marker.
      const bool entering = on_path[e.path]++ % 2 == 0;
      if (threshold_mm != 0) {
        const Eigen::Vector2d normal = Eigen::Vector2d(-(b - a).y(), (b - a).x()).normalized();
        const double into = normal.dot(to - from) >= 0 ? 1.0 : -1.0;  // the leg crosses along +normal
        sensor += threshold_mm * (entering ? into : -into);
      }
      trips.push_back(SimulateTrip(actual, from, to, a, b, sensor, robot, late));
    }
    return trips;
  }

  const std::vector<ExpectedTrip>& ExpectedFor(const cell::Fixture& fixture) {
    auto it = expected_.find(&fixture);
    if (it == expected_.end()) it = expected_.emplace(&fixture, ExpectedTrips(fixture)).first;
    return it->second;
  }

  Eigen::Vector2d DirectionOfLeg(const cell::Fixture& fixture, std::size_t trip) {
    const ExpectedTrip& e = ExpectedFor(fixture)[trip];
    return NominalFix(fixture).linear().topLeftCorner<2, 2>() * e.leg_direction;
  }

  const CompileState& state_;
  const cell::Cell& cell_;
  const TruthSpec& truth_;
  SimOptions options_;
  SimRandom random_;
  TrueField field_;
  PointCorrector corrector_;
  double repeatability_mm_ = 0;
  double servo_period_s_ = 0;
  std::vector<CyclePlan> plans_;
  std::vector<std::optional<Eigen::Affine3d>> paper_fix0_;
  std::vector<std::vector<std::optional<Eigen::Affine3d>>> previous_;  // [mode][fixture]
  std::map<const cell::Fixture*, std::vector<ExpectedTrip>> expected_;
  int unknown_targets_ = 0;
  long scatter_stride_ = 1;  // the picture keeps every stride-th planned placement
  long placement_slot_ = 0;  // planned placements before this cycle
  double min_tolerance_mm_ = 0;
  double scan_s_ = 0, total_s_ = 0;
  double drift_scale_ = 0;           // the robot's scale drift this cycle (DriftModel)
  double clock_s_ = 0;               // the cycle-time estimate's clock at the start of this cycle
  std::vector<long> record_cycles_;  // per cell fixture: scans recorded
};

}  // namespace

SimResult Simulate(const CompileState& state, const TruthSpec& truth, const SimOptions& options) {
  SMTCAL_CHECK(state.cell != nullptr, "Simulate needs a compiled program");
  Simulator simulator(state, truth, options);
  SimResult result = simulator.Run();
  result.uncalibrated_accuracy_mm = simulator.field().uncalibrated_accuracy_mm();
  result.accuracy_assumed = simulator.field().accuracy_assumed();
  for (const cell::Region& region : state.cell->regions) result.regions.push_back(region.name);
  const cell::Fixture* first = state.fixtures.empty() ? nullptr : state.fixtures.front().cell_fixture;
  result.fixture_estimator =
      std::string(cell::EstimatorName(first != nullptr && first->estimator != cell::Estimator::kPaper
                                          ? first->estimator
                                          : cell::Estimator::kRigid));
  result.paper_estimator = first != nullptr ? std::string(cell::EstimatorName(first->estimator)) : "";
  return result;
}

}  // namespace smtcal
