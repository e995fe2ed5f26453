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
  scans->poses = CheckLimitPoses(*board);
  ScanOptions options;
  options.estimator = own.estimator;
  options.regions = &side_.regions;
  for (const BoardPose& pose : scans->poses) {
    // The trips this side's scan paths make on the board at this pose, as
    // the real robot latches them; the side's runtime takes it from there.
    const std::vector<Eigen::Vector2d> latched = CommandedTrips(own, truth_.regions, BoardPoseFix(*board, pose));
    std::vector<std::optional<Eigen::Vector2d>> trips(latched.begin(), latched.end());
    ScanResult result = ScanFixture(own, trips, options);
    scans->fix.push_back(result.fix);
    scans->refused.push_back(result.ok() ? std::string() : DescribeFailure(result, own));
  }
  return *scans;
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
