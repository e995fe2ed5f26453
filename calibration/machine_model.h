// Where a controller running smtcal's runtime puts a point: the command it
// gives and where the part lands, for every board pose a fixture's check
// limits let a cycle run with. `smtcal diff` compares two programs through
// it, each with its own cell (docs/diff.md, "On the machine").
//
// The model of one cycle with the board at pose P (its nominal pose moved by
// a shift of its origin and a rotation about it):
//   - the robot moves as the `truth` cell's tables say (the diff takes NEW's
//     cell: the robot as last measured). The program's scan paths run where
//     the fixture's nominal pose puts them; the marker scan latches the
//     command c on each leg at which the robot's real position F_truth(c)
//     crosses the line of the trip's marker edge of the board at P
//     (ScannedTrips): a trip moves along its leg, and one whose leg ends
//     first is not made;
//   - the controller calibrates those trips through ITS cell's tables and
//     estimates FIX with its fixture's estimator, every check included
//     (ScanFixture); a scan that fails a check places nothing;
//   - a fixture point f is commanded at F^-1(FIX . f) through the region of
//     its cell whose bounds hold FIX . f (PointCorrector: the same
//     computation as the runtimes and the compiler); a base position the
//     controller corrects (a run-time target) at F^-1(r); a command written
//     in the program is given as it is;
//   - the part lands at F_truth(command).
// The scan is modelled with a perfect sensor: what the diff asks is how two
// programs differ on the same machine, not how well either places.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "calibration/cell.h"
#include "calibration/fixture_estimation.h"

namespace smtcal {

// One pose of a fixture's board: its nominal pose with the origin shifted by
// (shift_x_mm, shift_y_mm) in the base frame and the board turned by
// rotation_deg about its origin.
struct BoardPose {
  double shift_x_mm = 0, shift_y_mm = 0;
  double rotation_deg = 0;
  bool nominal() const { return shift_x_mm == 0 && shift_y_mm == 0 && rotation_deg == 0; }
};

// The directions the diff evaluates the board in (docs/diff.md): the
// nominal pose first; then the board turned by +-r alone; then shifted by s
// in each of the eight directions 0, 45, ..., 315 degrees, each without
// rotation and turned by -r and +r: 27 poses, with s = kDiffPoseLimitFraction
// * max_shift_mm and r = kDiffPoseLimitFraction * max_rotation_deg. A scan
// need not accept them all (its trips may leave the trip window or their
// edges first): MachineModel::Poses brings each in to what the robot's scan
// accepts. They sample the limits; the largest move between them is not a
// bound.
std::vector<BoardPose> CheckLimitPoses(const cell::Fixture& fixture);
// `pose` scaled by `fraction` (shift and rotation alike).
BoardPose ScaledPose(const BoardPose& pose, double fraction);
// FIX of the board at `pose`.
Eigen::Affine3d BoardPoseFix(const cell::Fixture& fixture, const BoardPose& pose);
// "nominal pose", "shifted 1.980 mm toward 45°, turned +0.990°".
std::string DescribeBoardPose(const BoardPose& pose);

// Where the scan of `fixture` latches its trips, in trip order, with the
// board at `board` on a robot whose real position for a command c is
// robot.Forward(c): the program's scan paths run where the fixture's nominal
// pose puts them, and trip k is the command on its leg at which the real
// position crosses its marker edge of the board at `board` (the sensor is
// perfect). The edge is taken as its whole line (a LinuxCNC output does not
// record where a marker's edge ends); nullopt where the leg ends before the
// real path meets it: the scan is refused.
std::vector<std::optional<Eigen::Vector2d>> ScannedTrips(const cell::Fixture& fixture, const PointCorrector& robot,
                                                         const Eigen::Affine3d& board);

// One point on the machine.
struct MachinePoint {
  bool ok = false;
  std::string why;                                     // when not ok: why nothing is commanded
  Eigen::Vector2d required = Eigen::Vector2d::Zero();  // where the part must go (base frame; as written: where it lands)
  Eigen::Vector2d command = Eigen::Vector2d::Zero();   // what the controller commands
  double angle_deg = 0;                                // added to u: the board's rotation as estimated
  Eigen::Vector2d lands = Eigen::Vector2d::Zero();     // F_truth(command)
  int region = -1;  // the region (index in the side's cell) that corrected it, or -1
};

class MachineModel {
 public:
  // `side` is the cell the program was compiled for, `truth` the robot's
  // (may be the same object). Both must outlive the model; their tables are
  // valid (the loaders check them).
  MachineModel(const cell::Cell& side, const cell::Cell& truth);

  const cell::Cell& side() const { return side_; }
  // The poses of the side's fixture `fixture` (index in its cell): those of
  // the truth cell's fixture of the same name, which is where the board
  // really is, or the side's own when the truth has no such fixture.
  // CheckLimitPoses, each brought in to kDiffPoseLimitFraction of the
  // farthest pose in its direction (to 1/1024) that the robot's own scan
  // accepts (the fixture's scan through the truth cell's tables): the poses
  // a cycle can run with, within the limits. The same for both sides of a
  // diff (they share the truth).
  const std::vector<BoardPose>& Poses(std::size_t fixture) const;
  // FIX as the side's controller estimates it at pose `pose`, or why its
  // scan refuses the board there.
  const std::optional<Eigen::Affine3d>& ScanFix(std::size_t fixture, std::size_t pose, std::string* why) const;

  // A point in fixture `fixture`'s frame, at pose `pose`.
  MachinePoint FixturePoint(std::size_t fixture, std::size_t pose, const Eigen::Vector2d& in_fixture) const;
  // A base position the controller corrects through its tables.
  MachinePoint RunTimePoint(const Eigen::Vector2d& required) const;
  // A command the program gives as written.
  MachinePoint AsWritten(const Eigen::Vector2d& command) const;

 private:
  struct Scans {
    std::vector<BoardPose> poses;
    std::vector<std::optional<Eigen::Affine3d>> fix;  // per pose
    std::vector<std::string> refused;                 // per pose: why the scan failed
  };
  const Scans& ScansOf(std::size_t fixture) const;
  BoardPose AcceptedPose(const cell::Fixture& board, const BoardPose& limit) const;
  MachinePoint Commanded(const CorrectedPoint& corrected) const;

  const cell::Cell& side_;
  const cell::Cell& truth_;
  PointCorrector side_corrector_;
  PointCorrector truth_corrector_;
  mutable std::vector<std::optional<Scans>> scans_;  // per side fixture, made on first use
};

}  // namespace smtcal
