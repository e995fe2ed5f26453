// Where a controller running smtcal's runtime puts a point: the command it
// gives and where the part lands, for every board pose a cycle can run
// with. `smtcal diff` compares two programs through it, both on ONE machine
// (docs/diff.md, "On the machine").
//
// The machine (MachineWorld) is one robot and one board: by default what
// NEW's cell says, the latest description of the real cell. Its robot moves
// as that cell's tables say (F_true); its boards are that cell's fixtures:
// their true marker edges, at their nominal pose moved by a shift of the
// origin and a rotation about it (BoardPose).
//
// Each program brings only its own constants, its cell (MachineModel's
// `side`): the tables its runtime inverts, its fixtures' nominal poses,
// marker geometry (edges, L1, L2), estimator, scan paths and check limits.
// One cycle with the board at pose P:
//   - the program's scan paths run where ITS fixture's nominal pose puts
//     them; the marker scan latches the command c on each leg at which the
//     robot's real position F_true(c) crosses the line of the trip's TRUE
//     marker edge, the world's board at P (ScannedTrips): a trip moves along
//     its leg, and one whose leg ends first is not made;
//   - the program's runtime calibrates those trips through its own tables
//     and estimates FIX with its own estimator and marker geometry, every
//     check included with its own limits (ScanFixture); a scan that fails a
//     check places nothing;
//   - a fixture point f is commanded at F^-1(FIX . f) through the region of
//     its own cell whose bounds hold FIX . f (PointCorrector: the same
//     computation as the runtimes and the compiler); a base position the
//     controller corrects (a run-time target) at F^-1(r); a command written
//     in the program is given as it is;
//   - the part lands at F_true(command).
// So a key of a program's cell moves its parts exactly when the physics
// does: a re-measured marker edge moves its FIX, a moved origin or scan path
// only where its trips land on the same lines (nothing), a table what it
// corrects. The scan is modelled with a perfect sensor: what the diff asks
// is how two programs differ on the same machine, not how well either places.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
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
// edges first): CommonPoses brings each in to what the programs' scans
// accept. They sample the limits; the largest move between them is not a
// bound.
std::vector<BoardPose> CheckLimitPoses(double max_shift_mm, double max_rotation_deg);
std::vector<BoardPose> CheckLimitPoses(const cell::Fixture& fixture);
// `pose` scaled by `fraction` (shift and rotation alike).
BoardPose ScaledPose(const BoardPose& pose, double fraction);
// FIX of the board at `pose`.
Eigen::Affine3d BoardPoseFix(const cell::Fixture& fixture, const BoardPose& pose);
// "nominal pose", "shifted 1.980 mm toward 45°, turned +0.990°".
std::string DescribeBoardPose(const BoardPose& pose);

// Where the scan of `scanner` latches its trips, in trip order, on the
// board `board` placed at `board_fix`, on a robot whose real position for a
// command c is robot.Forward(c): the scanner's paths run where ITS nominal
// pose puts them, and trip k is the command on its leg at which the real
// position crosses the line of the board's edge that trip k is expected on
// (the same index: p1..p4). The sensor is perfect. The edge is taken as its
// whole line (a LinuxCNC output does not record where a marker's edge
// ends); nullopt where the leg ends before the real path meets it: the scan
// is refused.
std::vector<std::optional<Eigen::Vector2d>> ScannedTrips(const cell::Fixture& scanner, const cell::Fixture& board,
                                                         const PointCorrector& robot, const Eigen::Affine3d& board_fix);
// The same for a scanner on its own board.
std::vector<std::optional<Eigen::Vector2d>> ScannedTrips(const cell::Fixture& fixture, const PointCorrector& robot,
                                                         const Eigen::Affine3d& board_fix);

// The machine both programs of a diff run on: the robot and the boards of
// one cell (which must outlive it).
class MachineWorld {
 public:
  explicit MachineWorld(const cell::Cell& world);
  const cell::Cell& cell() const { return world_; }
  // F_true: where the robot really goes for a command.
  const PointCorrector& robot() const { return robot_; }
  // The board a program's fixture scans: the world's fixture of the same
  // name, or the program's own when the world has none.
  const cell::Fixture& Board(const cell::Fixture& own) const;

 private:
  const cell::Cell& world_;
  PointCorrector robot_;
};

// One point on the machine.
struct MachinePoint {
  bool ok = false;
  std::string why;                                     // when not ok: why nothing is commanded
  Eigen::Vector2d required = Eigen::Vector2d::Zero();  // where the part must go (base frame; as written: where it lands)
  Eigen::Vector2d command = Eigen::Vector2d::Zero();   // what the controller commands
  double angle_deg = 0;                                // added to u: the board's rotation as estimated
  Eigen::Vector2d lands = Eigen::Vector2d::Zero();     // F_true(command)
  int region = -1;  // the region (index in the side's cell) that corrected it, or -1
};

// One program's controller on the machine.
class MachineModel {
 public:
  // `side` is the cell the program was compiled for; both it and `world`
  // must outlive the model; its tables are valid (the loaders check them).
  MachineModel(const cell::Cell& side, const MachineWorld& world);

  const cell::Cell& side() const { return side_; }
  const MachineWorld& world() const { return world_; }

  // Whether this program's scan of its fixture `fixture` (index in its
  // cell) accepts the board at `pose`; `why` says why not.
  bool Accepts(std::size_t fixture, const BoardPose& pose, std::string* why = nullptr) const;

  // The poses its fixture `fixture` is evaluated at (CommonPoses: the same
  // for both programs); until set, the poses its own scan accepts.
  void SetPoses(std::size_t fixture, std::vector<BoardPose> poses);
  const std::vector<BoardPose>& Poses(std::size_t fixture) const;
  // FIX as this program's controller estimates it at pose `pose` (an index
  // into Poses), or why its scan refuses the board there.
  const std::optional<Eigen::Affine3d>& ScanFix(std::size_t fixture, std::size_t pose, std::string* why) const;

  // A point in fixture `fixture`'s frame, at pose `pose` (an index into Poses).
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
  ScanResult Scan(std::size_t fixture, const BoardPose& pose) const;
  Scans& ScansOf(std::size_t fixture) const;
  MachinePoint Commanded(const CorrectedPoint& corrected) const;

  const cell::Cell& side_;
  const MachineWorld& world_;
  PointCorrector side_corrector_;
  mutable std::vector<std::optional<Scans>> scans_;  // per side fixture, made on first use
};

// The poses of a board both programs are evaluated at: CheckLimitPoses of
// the wider of their fixtures' limits, each brought in, in its direction, to
// kDiffPoseLimitFraction of the farthest pose (found to 1/1024) that every
// program's scan accepts. `scanners` are the programs' models with the index
// of their fixture of that board. When a scan refuses even the nominal pose
// the poses stay at the limits (the diff says that program refuses the board).
std::vector<BoardPose> CommonPoses(const std::vector<std::pair<const MachineModel*, std::size_t>>& scanners);

// How far out, in the direction of each of CheckLimitPoses' poses (by
// index), `model`'s scan accepts the board: the fraction of that pose (to
// 1/1024; 1 when it accepts it, 0 when it refuses even the nominal pose).
std::vector<double> AcceptedFractions(const MachineModel& model, std::size_t fixture,
                                      const std::vector<BoardPose>& limits);

}  // namespace smtcal
