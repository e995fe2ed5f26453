// The machine model of `smtcal diff` (calibration/machine_model.h).
#include "calibration/machine_model.h"

#include <array>
#include <cmath>

#include <fmt/format.h>

#include "base/check.h"
#include "calibration/fixture_geometry.h"
#include "calibration/tolerances.h"

namespace smtcal {

std::vector<BoardPose> CheckLimitPoses(const cell::Fixture& fixture) {
  const double shift = kDiffPoseLimitFraction * fixture.max_shift_mm;
  const double turn = kDiffPoseLimitFraction * fixture.max_rotation_deg;
  std::vector<BoardPose> poses = {{0, 0, 0}, {0, 0, -turn}, {0, 0, turn}};
  for (int direction = 0; direction < 8; ++direction) {
    const double angle = direction * 45.0 * kRadPerDeg;
    // Exact zeros along the axes: cos(90°) is 6e-17 in doubles.
    const double c = direction % 4 == 2 ? 0 : std::cos(angle), s = direction % 4 == 0 ? 0 : std::sin(angle);
    for (double rotation : {0.0, -turn, turn}) poses.push_back({shift * c, shift * s, rotation});
  }
  return poses;
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

std::vector<std::optional<Eigen::Vector2d>> ScannedTrips(const cell::Fixture& fixture, const PointCorrector& robot,
                                                         const Eigen::Affine3d& board) {
  const Eigen::Affine3d nominal = NominalFix(fixture);
  std::vector<std::optional<Eigen::Vector2d>> trips;
  for (const ExpectedTrip& trip : ExpectedTrips(fixture)) {
    const std::vector<cell::Point2>& points = fixture.scan_paths[trip.path].points;
    const Eigen::Vector2d from = ToBase(nominal, points[trip.leg]), to = ToBase(nominal, points[trip.leg + 1]);
    const Eigen::Vector2d leg = to - from;
    const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(trip.edge)];
    const Eigen::Vector2d a = ToBase(board, edge.from), along = ToBase(board, edge.to) - a;
    const Eigen::Vector2d normal(-along.y(), along.x());
    // normal . (F(from + t leg) - a) = 0. F is the identity plus tables of
    // slopes far below 1 (the loaders check them): Newton steps with the
    // identity's derivative contract. A trip's leg is never parallel to its
    // edge (ExpectedTrips).
    const double rate = normal.dot(leg);
    double t = trip.along_mm / leg.norm();
    for (int step = 0; step < 100; ++step) {
      const double miss = normal.dot(robot.Forward(from + t * leg) - a) / rate;
      t -= miss;
      if (std::fabs(miss) * leg.norm() < 1e-13) break;
    }
    // Where the leg ends the path does: no trip beyond it. The edge is taken
    // as its whole line: what a LinuxCNC output's data give of it (frontend/
    // linuxcnc_output.h) and no kinder than the cell, where a trip past the
    // end of its edge is not made (the model then evaluates a pose the
    // cell would refuse, never refuses one it runs).
    constexpr double kEnd = 1e-9;  // ends included, as ExpectedTrips counts them, up to rounding
    trips.push_back(t >= -kEnd && t <= 1 + kEnd ? std::optional<Eigen::Vector2d>(from + t * leg) : std::nullopt);
  }
  return trips;
}

MachineModel::MachineModel(const cell::Cell& side, const cell::Cell& truth)
    : side_(side),
      truth_(truth),
      side_corrector_(side.regions),
      truth_corrector_(truth.regions),
      scans_(side.fixtures.size()) {}

const MachineModel::Scans& MachineModel::ScansOf(std::size_t fixture) const {
  SMTCAL_CHECK(fixture < scans_.size(), "a fixture of the side's cell");
  std::optional<Scans>& scans = scans_[fixture];
  if (scans) return *scans;
  scans.emplace();
  const cell::Fixture& own = side_.fixtures[fixture];
  const cell::Fixture* board = truth_.FindFixture(own.name);
  if (board == nullptr) board = &own;
  for (const BoardPose& limit : CheckLimitPoses(*board)) scans->poses.push_back(AcceptedPose(*board, limit));
  ScanOptions options;
  options.estimator = own.estimator;
  options.regions = &side_.regions;
  for (const BoardPose& pose : scans->poses) {
    // The trips this side's scan paths make on the board at this pose, as
    // the real robot latches them; the side's runtime takes it from there.
    ScanResult result = ScanFixture(own, ScannedTrips(own, truth_corrector_, BoardPoseFix(*board, pose)), options);
    scans->fix.push_back(result.fix);
    scans->refused.push_back(result.ok() ? std::string() : DescribeFailure(result, own));
  }
  return *scans;
}

BoardPose MachineModel::AcceptedPose(const cell::Fixture& board, const BoardPose& limit) const {
  ScanOptions options;
  options.estimator = board.estimator;
  options.regions = &truth_.regions;
  const auto accepts = [&](double fraction) {
    return ScanFixture(board, ScannedTrips(board, truth_corrector_, BoardPoseFix(board, ScaledPose(limit, fraction))),
                       options)
        .ok();
  };
  // A scan that refuses the nominal pose refuses the board everywhere the
  // diff looks; the poses stay at the limits (the diff says they are refused).
  if (limit.nominal() || accepts(1) || !accepts(0)) return limit;
  // The scan accepts the board from the nominal pose out to a boundary
  // (a trip leaves its window or its edge): bisect for it.
  double lo = 0, hi = 1;
  for (int step = 0; step < 10; ++step) {
    const double mid = 0.5 * (lo + hi);
    (accepts(mid) ? lo : hi) = mid;
  }
  // Inside the boundary by the margin the limits get (kDiffPoseLimitFraction).
  return ScaledPose(limit, kDiffPoseLimitFraction * lo);
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
  point.lands = truth_corrector_.Forward(point.command);
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
  point.lands = truth_corrector_.Forward(command);
  point.required = point.lands;  // what the command was computed to reach
  return point;
}

}  // namespace smtcal
