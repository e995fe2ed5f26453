// check_places: what LinuxCNC did in a simulated run (run_scenario.py)
// against smtcal's own C++ (README.md in this folder).
//
//   smtcal_linuxcnc_sim_check --program P.place --cell C.cell.toml --run check.json --servo-period-s T
//
// check.json, written by run_scenario.py: per cycle the board's true pose,
// the trips LinuxCNC latched (by index), the `smtcal fixture --json` output
// for them, and the machine's position at every Place (the vacuum valve
// going off). For every cycle it prints and checks:
//   trips    how far past its true marker edge each trip was latched, along
//            the direction of travel (the sensor chain's latency; the edges
//            are the markers' in the board's true frame, as the sensor HAL
//            draws them); a scan that passed must have every trip latched
//            at or past its edge and at most one servo period's travel at
//            the scan speed past it (the sensor HAL runs after the motion
//            controller in the servo thread, from the position motion just
//            commanded; motion reads the input in the next period and
//            latches that position);
//   places   every Place the machine made against smtcal's C++ correction
//            from the same trips: the cycle's Place targets in the order
//            the compile-time trace runs them (the program's first cycle),
//            FIX from `smtcal fixture`, FIX . f, the region's inverse
//            (CompileState::SolverFor), u plus the board's angle;
//   landing  where each part really lands: the command through the cell's
//            tables (the robot's error as the cell describes it) into the
//            board's true frame, against the programmed point.
// A cycle may give the robot a scale the tables do not know
// ("robot_scale_ppm" about "robot_scale_about_mm", the monitor's scenario):
// the sensor and the parts are then off by s (p - about) more.
// Exit 0 when every place equals the C++ correction within kSameMm and lands
// within its region's tolerance; 1 otherwise (2: usage or unreadable input).
//
//   smtcal_linuxcnc_sim_check --cell C.cell.toml --sensor-model
//
// prints (JSON) where the simulated robot really puts the sensor around each
// scan path: the cell's direct calibration (the tables of the regions over
// the markers, none: the identity) fitted by an affine map A(p) = M p + b
// over the path's area, for the sensor HAL's sum2 gains (driver.py), with
// the fit's largest error. The trips' check above uses the same A.
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "calibration/fixture_estimation.h"
#include "calibration/fixture_geometry.h"
#include "frontend/cell_toml.h"
#include "passes/compile_pipeline.h"
#include "passes/correction/compile_state.h"

namespace smtcal {
namespace {

using nlohmann::json;

// LinuxCNC computes the runtime in doubles as smtcal does, and its motion
// controller ends a move on its target: a place agrees with the C++
// correction to rounding (measured below 1e-12 mm). 1e-9 mm leaves room and
// still tells any real difference.
constexpr double kSameMm = 1e-9;
constexpr double kSameDeg = 1e-9;

struct Options {
  std::string program, cell, run;
  double servo_period_s = 0;
  bool sensor_model = false;
};

bool ParseArgs(int argc, char** argv, Options& options) {
  if (argc == 4 && std::string(argv[1]) == "--cell" && std::string(argv[3]) == "--sensor-model") {
    options.cell = argv[2];
    options.sensor_model = true;
    return true;
  }
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--program") options.program = argv[i + 1];
    else if (key == "--cell") options.cell = argv[i + 1];
    else if (key == "--run") options.run = argv[i + 1];
    else if (key == "--servo-period-s") options.servo_period_s = std::atof(argv[i + 1]);
    else return false;
  }
  return !options.program.empty() && !options.cell.empty() && !options.run.empty() && options.servo_period_s > 0;
}

json ReadJson(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return json::parse(text.str());
}

Eigen::Affine3d FixFromScan(const json& scan) {
  Eigen::Affine3d fix;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) fix.matrix()(r, c) = scan["fix"]["matrix"][r][c].get<double>();
  }
  return fix;
}

Eigen::Affine3d TruePose(const json& pose) {
  return PlanarFix({pose["x_mm"].get<double>(), pose["y_mm"].get<double>()},
                   Radians(pose["angle_deg"].get<double>()));
}

// An affine map of base positions: where the sensor really is for a command.
struct SensorModel {
  Eigen::Matrix2d m = Eigen::Matrix2d::Identity();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  double max_error_mm = 0;
  Eigen::Vector2d operator()(const Eigen::Vector2d& p) const { return m * p + b; }
};

// The cell's direct calibration fitted by an affine map over scan path
// `path` (its points at the nominal pose, widened by the trip window), on an
// 11 x 11 grid, least squares.
SensorModel FitSensorModel(const cell::Cell& cell, const cell::Fixture& fixture, std::size_t path) {
  const std::vector<Eigen::Vector2d> points = ScanPathsInBase(fixture, NominalFix(fixture))[path];
  Eigen::Vector2d lo = points.front(), hi = points.front();
  for (const Eigen::Vector2d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  lo.array() -= fixture.trip_window_mm;
  hi.array() += fixture.trip_window_mm;
  constexpr int kGrid = 11;
  Eigen::MatrixXd a(kGrid * kGrid, 3);
  Eigen::MatrixXd f(kGrid * kGrid, 2);
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      const Eigen::Vector2d p = lo + (hi - lo).cwiseProduct(Eigen::Vector2d(i, j) / (kGrid - 1));
      a.row(i * kGrid + j) << p.x(), p.y(), 1;
      f.row(i * kGrid + j) = DirectCalibrateInCell(cell.regions, p).transpose();
    }
  }
  const Eigen::MatrixXd x = a.colPivHouseholderQr().solve(f);  // 3 x 2
  SensorModel model;
  model.m = x.topRows<2>().transpose();
  model.b = x.row(2).transpose();
  model.max_error_mm = (a * x - f).rowwise().norm().maxCoeff();
  return model;
}

std::vector<SensorModel> SensorModels(const cell::Cell& cell, const cell::Fixture& fixture) {
  std::vector<SensorModel> models;
  for (std::size_t path = 0; path < fixture.scan_paths.size(); ++path) {
    models.push_back(FitSensorModel(cell, fixture, path));
  }
  return models;
}

// The cycle's Place targets in the order the machine makes them.
std::vector<const Target*> PlacesInOrder(const CompileState& state) {
  std::vector<const Target*> places;
  for (const auto& [cycle, events] : state.cycle_traces) {
    for (const TraceEvent& event : events) {
      const Target& target = state.targets[event.target];
      if (event.kind == TraceEvent::Kind::kMotion && target.is_placement()) places.push_back(&target);
    }
  }
  return places;
}

// The trips: how far past the true edge each was latched, along the leg.
struct TripLatency {
  double smallest = 0, largest = 0;
};
// The robot's scale the tables do not know, this cycle: s and the point it is about.
struct RobotScale {
  double s = 0;
  Eigen::Vector2d about = Eigen::Vector2d::Zero();
  Eigen::Vector2d Off(const Eigen::Vector2d& command) const { return s * (command - about); }
};

RobotScale ScaleOf(const json& cycle) {
  RobotScale scale;
  scale.s = cycle.value("robot_scale_ppm", 0.0) * 1e-6;
  if (cycle.contains("robot_scale_about_mm")) {
    scale.about = {cycle["robot_scale_about_mm"][0].get<double>(), cycle["robot_scale_about_mm"][1].get<double>()};
  }
  return scale;
}

TripLatency CheckTrips(const cell::Fixture& fixture, const std::vector<SensorModel>& sensor, const json& trips,
                       const Eigen::Affine3d& truth, const RobotScale& scale) {
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const double nominal_angle = FixAngleRad(NominalFix(fixture));
  const double turn = nominal_angle - FixAngleRad(truth);  // legs run at the nominal pose
  const Eigen::Rotation2Dd to_true(turn);
  TripLatency latency{1e300, -1e300};
  std::string line = "  trips past their true edge (mm):";
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const std::string key = std::to_string(k);
    if (!trips.contains(key)) {
      line += fmt::format(" {} -", TripName(k));
      continue;
    }
    const Eigen::Vector2d base(trips[key][0].get<double>(), trips[key][1].get<double>());
    const Eigen::Vector2d f = ToFixtureFrame(truth, sensor[expected[k].path](base) + scale.Off(base));  // where the sensor was
    const EdgeLine edge = EdgeLineOf(fixture.edges[static_cast<std::size_t>(expected[k].edge)]);
    const Eigen::Vector2d travel = to_true * expected[k].leg_direction;
    const double past = (edge.normal.dot(f) - edge.offset) / edge.normal.dot(travel);
    line += fmt::format(" {} {:.4f}", TripName(k), past);
    latency.smallest = std::min(latency.smallest, past);
    latency.largest = std::max(latency.largest, past);
  }
  std::cout << line << "\n";
  return latency;
}

int Run(const Options& options) {
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::uint32_t> file = sources.Load(options.program);
  if (!file) {
    std::cerr << file.error().message << "\n";
    return 2;
  }
  CompiledProgram compiled;
  Result<bool> ran = CompileForCell(file.value(), options.cell, false, sources, diags, compiled);
  if (!ran || !ran.value() || diags.has_errors()) {
    std::cerr << diags.RenderText() << (ran ? "" : ran.error().message) << "\n";
    return 2;
  }
  CompileState& state = *compiled.program.compile;
  const cell::Cell& cell = *compiled.cell;
  const cell::Fixture& fixture = cell.fixtures.at(0);
  const std::vector<const Target*> places = PlacesInOrder(state);
  const std::vector<SensorModel> sensor = SensorModels(cell, fixture);
  const json run = ReadJson(options.run);

  bool ok = true;
  int cycle_number = 0;
  for (const json& cycle : run["cycles"]) {
    ++cycle_number;
    const Eigen::Affine3d truth = TruePose(cycle["pose"]);
    std::cout << fmt::format("cycle {}: board at x {:.4f} y {:.4f} angle {:.4f} deg{}\n", cycle_number,
                             FixOrigin(truth).x(), FixOrigin(truth).y(), FixAngleRad(truth) * kDegPerRad,
                             cycle["pose"].value("present", true) ? "" : " (no board)");
    const RobotScale scale = ScaleOf(cycle);
    const TripLatency past = CheckTrips(fixture, sensor, cycle["trips"], truth, scale);
    const json scan = ReadJson(cycle["scan"].get<std::string>());
    const double speed = fixture.TripLatchSpeedMmS();  // the feed that latches the trips
    // The sensor HAL's affine model of the tables is that far off at most.
    double model_error = 0;
    for (const SensorModel& model : sensor) model_error = std::max(model_error, model.max_error_mm);
    const double bound = speed * options.servo_period_s + model_error + 1e-9;
    if (past.largest >= past.smallest) {
      std::cout << fmt::format("  trips latched {:.4f} to {:.4f} mm past their edges at {} mm/s ({:.2f} to {:.2f} "
                               "servo periods)\n",
                               past.smallest, past.largest, speed, past.smallest / (speed * options.servo_period_s),
                               past.largest / (speed * options.servo_period_s));
      if (scan["ok"].get<bool>() && (past.smallest < -model_error - 1e-9 || past.largest > bound)) {
        std::cerr << fmt::format("cycle {}: a trip latched {:.4f} mm before or {:.4f} mm past its edge; expected 0 "
                                 "to {:.4f} mm (one servo period at {} mm/s)\n",
                                 cycle_number, past.smallest, past.largest, bound, speed);
        ok = false;
      }
    }
    const json& machine = cycle["places"];
    if (!scan["ok"].get<bool>()) {
      std::cout << fmt::format("  scan refused ({}): {} places\n", scan["fault"].get<std::string>(), machine.size());
      if (!machine.empty()) {
        std::cerr << fmt::format("cycle {}: the scan was refused, yet the machine placed {} parts\n", cycle_number,
                                 machine.size());
        ok = false;
      }
      continue;
    }
    const Eigen::Affine3d fix = FixFromScan(scan);
    std::cout << fmt::format("  FIX from the latched trips: x {:.6f} y {:.6f} angle {:.6f} deg ({:+.4f} {:+.4f} "
                             "mm, {:+.6f} deg from the true pose)\n",
                             FixOrigin(fix).x(), FixOrigin(fix).y(), FixAngleRad(fix) * kDegPerRad,
                             FixOrigin(fix).x() - FixOrigin(truth).x(), FixOrigin(fix).y() - FixOrigin(truth).y(),
                             RelativeAngleRad(truth, fix) * kDegPerRad);
    if (machine.size() != places.size()) {
      std::cerr << fmt::format("cycle {}: the machine placed {} parts, the program places {}\n", cycle_number,
                               machine.size(), places.size());
      ok = false;
      continue;
    }
    double worst_same = 0, worst_u = 0, worst_landing = 0, worst_share = 0;
    for (std::size_t i = 0; i < places.size(); ++i) {
      const Target& target = *places[i];
      const std::string what = fmt::format("Place {} (line {})", target.text, target.stmt->loc.line);
      const json& at = machine[i];  // x y z a b c, speed
      const Eigen::Vector2d command(at[0].get<double>(), at[1].get<double>());
      // smtcal's C++ correction from the same trips.
      const Pose4 required = PoseToBase(fix, target.in_frame);
      const cell::Region* region = cell.RegionAt(Xy(required));
      if (region == nullptr) {
        std::cerr << what << ": no region holds the required position\n";
        ok = false;
        continue;
      }
      const Solution solution = state.SolverFor(*region).Solve(Xy(required), region->outside);
      const double same = (command - solution.point).norm();
      const double du = std::abs(at[5].get<double>() - required[3]);
      // Where the part lands: the command through the cell's tables, in the board's true frame.
      const Eigen::Vector2d reached = DirectCalibrateInCell(cell.regions, command) + scale.Off(command);
      const double landing = (ToFixtureFrame(truth, reached) - Xy(target.in_frame)).norm();
      worst_same = std::max(worst_same, same);
      worst_u = std::max(worst_u, du);
      worst_landing = std::max(worst_landing, landing);
      worst_share = std::max(worst_share, landing / region->tolerance_mm);
      // The position is the first status update that shows the valve off;
      // on a loaded host that can be the start of the Jump's rise, which
      // moves z alone, so z and the speed are printed, not compared.
      if (same > kSameMm || du > kSameDeg || landing > region->tolerance_mm ||
          solution.status != SolveStatus::kOk) {
        std::cerr << fmt::format("cycle {}: {}: machine {:.9f} {:.9f} z {:.6f} u {:.9f} speed {}, C++ {:.9f} {:.9f} "
                                 "u {:.9f} ({}), lands {:.4f} mm from its point (tolerance {} mm)\n",
                                 cycle_number, what, command.x(), command.y(), at[2].get<double>(),
                                 at[5].get<double>(), at[6].get<double>(), solution.point.x(), solution.point.y(),
                                 required[3], StatusName(solution.status), landing, region->tolerance_mm);
        ok = false;
      }
    }
    std::cout << fmt::format("  {} places: largest difference to the C++ correction {:.2e} mm (u {:.2e} deg); "
                             "largest landing error {:.4f} mm ({:.0f} % of the tolerance)\n",
                             places.size(), worst_same, worst_u, worst_landing, 100 * worst_share);
  }
  return ok ? 0 : 1;
}

// --sensor-model: the fits as JSON, one per scan path.
int PrintSensorModels(const Options& options) {
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(options.cell, sources, diags);
  if (!loaded || !loaded.value()) {
    std::cerr << diags.RenderText() << "\n";
    return 2;
  }
  const cell::Cell& cell = *loaded.value();
  const cell::Fixture& fixture = cell.fixtures.at(0);
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  json out = json::array();
  const std::vector<SensorModel> models = SensorModels(cell, fixture);
  for (std::size_t path = 0; path < models.size(); ++path) {
    const SensorModel& model = models[path];
    // The marker the path scans: 1 for edges p1 and p2, 2 for p3 and p4
    // (the sensor HAL's units per marker).
    int marker = 0;
    for (const ExpectedTrip& trip : expected) {
      if (trip.path == path) marker = trip.edge < 2 ? 1 : 2;
    }
    out.push_back({{"path", fixture.scan_paths[path].name},
                   {"marker", marker},
                   {"m", {{model.m(0, 0), model.m(0, 1)}, {model.m(1, 0), model.m(1, 1)}}},
                   {"b", {model.b.x(), model.b.y()}},
                   {"max_error_mm", model.max_error_mm}});
  }
  std::cout << out.dump(1) << "\n";
  return 0;
}

}  // namespace
}  // namespace smtcal

int main(int argc, char** argv) {
  smtcal::Options options;
  if (!smtcal::ParseArgs(argc, argv, options)) {
    std::fprintf(stderr, "usage: %s --program P.place --cell C.cell.toml --run check.json --servo-period-s T\n",
                 argv[0]);
    return 2;
  }
  try {
    return options.sensor_model ? smtcal::PrintSensorModels(options) : smtcal::Run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 2;
  }
}
