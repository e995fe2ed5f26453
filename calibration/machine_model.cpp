// The machine model of `smtcal diff` (calibration/machine_model.h).
#include "calibration/machine_model.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/fixture_geometry.h"
#include "calibration/tolerances.h"

namespace smtcal {

std::vector<BoardPose> CheckLimitPoses(double max_shift_mm, double max_rotation_deg) {
  const double shift = kDiffPoseLimitFraction * max_shift_mm;
  const double turn = kDiffPoseLimitFraction * max_rotation_deg;
  std::vector<BoardPose> poses = {{0, 0, 0}, {0, 0, -turn}, {0, 0, turn}};
  for (int direction = 0; direction < 8; ++direction) {
    const double angle = direction * 45.0 * kRadPerDeg;
    // Exact zeros along the axes: cos(90°) is 6e-17 in doubles.
    const double c = direction % 4 == 2 ? 0 : std::cos(angle), s = direction % 4 == 0 ? 0 : std::sin(angle);
    for (double rotation : {0.0, -turn, turn}) poses.push_back({shift * c, shift * s, rotation});
  }
  return poses;
}

std::vector<BoardPose> CheckLimitPoses(const cell::Fixture& fixture) {
  return CheckLimitPoses(fixture.max_shift_mm, fixture.max_rotation_deg);
}

BoardPose ScaledPose(const BoardPose& pose, double fraction) {
  return {pose.shift_x_mm * fraction, pose.shift_y_mm * fraction, pose.rotation_deg * fraction};
}

Eigen::Affine3d BoardPoseFix(const cell::Fixture& fixture, const BoardPose& pose) {
  return PlanarFix(fixture.origin_mm + Eigen::Vector2d(pose.shift_x_mm, pose.shift_y_mm),
                   (fixture.angle_deg + pose.rotation_deg) * kRadPerDeg);
}

std::string DescribeBoardPose(const BoardPose& pose) {
  if (pose.nominal()) return "nominal pose";
  std::string text;
  const double shift = std::hypot(pose.shift_x_mm, pose.shift_y_mm);
  if (shift > 0) {
    text = fmt::format("shifted {:.3f} mm toward {:.0f}°", shift,
                       std::atan2(pose.shift_y_mm, pose.shift_x_mm) * kDegPerRad);
  }
  if (pose.rotation_deg != 0) text += fmt::format("{}turned {:+.3f}°", text.empty() ? "" : ", ", pose.rotation_deg);
  return text;
}

std::vector<std::optional<Eigen::Vector2d>> ScannedTrips(const cell::Fixture& scanner, const cell::Fixture& board,
                                                         const PointCorrector& robot, const Eigen::Affine3d& board_fix) {
  const Eigen::Affine3d nominal = NominalFix(scanner);
  std::vector<std::optional<Eigen::Vector2d>> trips;
  for (const ExpectedTrip& trip : ExpectedTrips(scanner)) {
    const std::vector<cell::Point2>& points = scanner.scan_paths[trip.path].points;
    const Eigen::Vector2d from = ToBase(nominal, points[trip.leg]), to = ToBase(nominal, points[trip.leg + 1]);
    const Eigen::Vector2d leg = to - from;
    const cell::MarkerEdge& edge = board.edges[static_cast<std::size_t>(trip.edge)];
    const Eigen::Vector2d a = ToBase(board_fix, edge.from), along = ToBase(board_fix, edge.to) - a;
    const Eigen::Vector2d normal(-along.y(), along.x());
    // normal . (F(from + t leg) - a) = 0. F is the identity plus tables of
    // slopes far below 1 (the loaders check them): Newton steps with the
    // identity's derivative contract. A leg parallel to the true edge (a
    // board turned as far as no scan accepts) is never crossed.
    const double rate = normal.dot(leg);
    if (std::fabs(rate) <= 1e-12 * normal.norm() * leg.norm()) {
      trips.push_back(std::nullopt);
      continue;
    }
    double t = trip.along_mm / leg.norm();
    for (int step = 0; step < 100; ++step) {
      const double miss = normal.dot(robot.Forward(from + t * leg) - a) / rate;
      t -= miss;
      if (std::fabs(miss) * leg.norm() < 1e-13) break;
    }
    // Where the leg ends the path does: no trip beyond it. The edge is taken
    // as its whole line: what a LinuxCNC output's data give of it (backend/
    // linuxcnc/linuxcnc_output.h) and no kinder than the cell, where a trip
    // past the end of its edge is not made (the model then evaluates a pose
    // the cell would refuse, never refuses one it runs).
    constexpr double kEnd = 1e-9;  // ends included, as ExpectedTrips counts them, up to rounding
    trips.push_back(std::isfinite(t) && t >= -kEnd && t <= 1 + kEnd ? std::optional<Eigen::Vector2d>(from + t * leg)
                                                                     : std::nullopt);
  }
  return trips;
}

std::vector<std::optional<Eigen::Vector2d>> ScannedTrips(const cell::Fixture& fixture, const PointCorrector& robot,
                                                         const Eigen::Affine3d& board_fix) {
  return ScannedTrips(fixture, fixture, robot, board_fix);
}

MachineWorld::MachineWorld(const cell::Cell& world) : world_(world), robot_(world.regions) {}

const cell::Fixture& MachineWorld::Board(const cell::Fixture& own) const {
  const cell::Fixture* board = world_.FindFixture(own.name);
  return board != nullptr ? *board : own;
}

MachineModel::MachineModel(const cell::Cell& side, const MachineWorld& world)
    : side_(side), world_(world), side_corrector_(side.regions), scans_(side.fixtures.size()) {}

ScanResult MachineModel::Scan(std::size_t fixture, const BoardPose& pose) const {
  const cell::Fixture& own = side_.fixtures[fixture];
  const cell::Fixture& board = world_.Board(own);
  ScanOptions options;
  options.estimator = own.estimator;
  options.regions = &side_.regions;
  // The trips this program's scan paths make on the machine's board at this
  // pose, as the real robot latches them; its runtime takes it from there.
  return ScanFixture(own, ScannedTrips(own, board, world_.robot(), BoardPoseFix(board, pose)), options);
}

bool MachineModel::Accepts(std::size_t fixture, const BoardPose& pose, std::string* why) const {
  const ScanResult result = Scan(fixture, pose);
  if (why != nullptr) *why = result.ok() ? std::string() : DescribeFailure(result, side_.fixtures[fixture]);
  return result.ok();
}

void MachineModel::SetPoses(std::size_t fixture, std::vector<BoardPose> poses) {
  SMTCAL_CHECK(fixture < scans_.size(), "a fixture of the side's cell");
  scans_[fixture].emplace();
  scans_[fixture]->poses = std::move(poses);
}

MachineModel::Scans& MachineModel::ScansOf(std::size_t fixture) const {
  SMTCAL_CHECK(fixture < scans_.size(), "a fixture of the side's cell");
  std::optional<Scans>& scans = scans_[fixture];
  if (!scans) {
    scans.emplace();
    scans->poses = CommonPoses({{this, fixture}});
  }
  if (scans->fix.size() != scans->poses.size()) {
    for (const BoardPose& pose : scans->poses) {
      ScanResult result = Scan(fixture, pose);
      scans->fix.push_back(result.fix);
      scans->refused.push_back(result.ok() ? std::string() : DescribeFailure(result, side_.fixtures[fixture]));
    }
  }
  return *scans;
}

namespace {

// The fraction of `limit` out to which `accepts` holds, to 1/1024 (from the
// nominal pose out: 1 when it holds at the limit, 0 when not even at the
// nominal pose).
template <typename Accepts>
double AcceptedFraction(const BoardPose& limit, const Accepts& accepts) {
  if (limit.nominal()) return accepts(limit) ? 1 : 0;
  if (accepts(limit)) return 1;
  if (!accepts(ScaledPose(limit, 0))) return 0;
  double lo = 0, hi = 1;
  for (int step = 0; step < 10; ++step) {
    const double mid = 0.5 * (lo + hi);
    (accepts(ScaledPose(limit, mid)) ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

std::vector<BoardPose> CommonPoses(const std::vector<std::pair<const MachineModel*, std::size_t>>& scanners) {
  SMTCAL_CHECK(!scanners.empty(), "a board scanned by at least one program");
  double shift = 0, rotation = 0;
  for (const auto& [model, fixture] : scanners) {
    const cell::Fixture& own = model->side().fixtures[fixture];
    shift = std::max(shift, own.max_shift_mm);
    rotation = std::max(rotation, own.max_rotation_deg);
  }
  const auto all_accept = [&](const BoardPose& pose) {
    return std::all_of(scanners.begin(), scanners.end(),
                       [&](const auto& scanner) { return scanner.first->Accepts(scanner.second, pose); });
  };
  std::vector<BoardPose> poses;
  for (const BoardPose& limit : CheckLimitPoses(shift, rotation)) {
    const double fraction = AcceptedFraction(limit, all_accept);
    // A scan that refuses the nominal pose refuses the board everywhere the
    // diff looks; the poses stay at the limits (the diff says they are refused).
    if (fraction == 0 || fraction == 1) {
      poses.push_back(limit);
    } else {
      // Inside the boundary by the margin the limits get (kDiffPoseLimitFraction).
      poses.push_back(ScaledPose(limit, kDiffPoseLimitFraction * fraction));
    }
  }
  return poses;
}

std::vector<double> AcceptedFractions(const MachineModel& model, std::size_t fixture,
                                      const std::vector<BoardPose>& limits) {
  std::vector<double> fractions;
  for (const BoardPose& limit : limits) {
    fractions.push_back(AcceptedFraction(limit, [&](const BoardPose& pose) { return model.Accepts(fixture, pose); }));
  }
  return fractions;
}

const std::vector<BoardPose>& MachineModel::Poses(std::size_t fixture) const { return ScansOf(fixture).poses; }

const std::optional<Eigen::Affine3d>& MachineModel::ScanFix(std::size_t fixture, std::size_t pose,
                                                            std::string* why) const {
  const Scans& scans = ScansOf(fixture);
  if (why != nullptr) *why = scans.refused[pose];
  return scans.fix[pose];
}

MachinePoint MachineModel::Commanded(const CorrectedPoint& corrected) const {
  MachinePoint point;
  point.required = corrected.required;
  point.region = corrected.region;
  point.command = corrected.command;
  const SolveStatus status = corrected.solution.status;
  if (status == SolveStatus::kOutside || status == SolveStatus::kNotConverged) {
    point.why = status == SolveStatus::kOutside
                    ? fmt::format("the command it needs lies outside the table of region {}",
                                  side_.regions[static_cast<std::size_t>(corrected.region)].name)
                    : std::string("the inverse did not converge");
    return point;
  }
  point.ok = true;
  point.lands = world_.robot().Forward(point.command);
  return point;
}

MachinePoint MachineModel::FixturePoint(std::size_t fixture, std::size_t pose,
                                        const Eigen::Vector2d& in_fixture) const {
  std::string refused;
  const std::optional<Eigen::Affine3d>& fix = ScanFix(fixture, pose, &refused);
  if (!fix) {
    MachinePoint point;
    point.why = fmt::format("the scan of {} refuses the board ({})", side_.fixtures[fixture].name, refused);
    return point;
  }
  MachinePoint point = Commanded(side_corrector_.Correct(*fix, in_fixture));
  point.angle_deg = FixAngleRad(*fix) * kDegPerRad;
  return point;
}

MachinePoint MachineModel::RunTimePoint(const Eigen::Vector2d& required) const {
  return Commanded(side_corrector_.Invert(required));
}

MachinePoint MachineModel::AsWritten(const Eigen::Vector2d& command) const {
  MachinePoint point;
  point.ok = true;
  point.command = command;
  point.lands = world_.robot().Forward(command);
  point.required = point.lands;  // what the command was computed to reach
  return point;
}

}  // namespace smtcal
