// The machine model of `smtcal diff` (calibration/machine_model.h): a
// controller with the robot's own tables puts every fixture point where the
// board puts it, at every pose the diff evaluates; a re-measured placing or
// marker table moves what it commands by what the tables say.
//
// Property tests print their seed; SMTCAL_TEST_SEED repeats one.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "calibration/fixture_geometry.h"
#include "calibration/machine_model.h"
#include "calibration/tolerances.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

using test::FixtureSeed;
using test::RandomSmoothTable;
using test::RegionOf;

// The paper cell's board with random tables under its markers and a placing
// region under the first layer.
cell::Cell RandomCell(std::mt19937_64& rng) {
  cell::Cell cell;
  cell.name = "test";
  cell.fixtures.push_back(test::PaperFixture(cell::Estimator::kRigid));
  cell.regions.push_back(RegionOf("layer1", RandomSmoothTable(rng, 150, 60, 50, 50, 11, 0.1)));
  cell.regions.push_back(RegionOf("marker1", RandomSmoothTable(rng, 127.5, 31, 25, 25, 6, 0.05), 0.1));
  cell.regions.push_back(RegionOf("marker2", RandomSmoothTable(rng, 313.5, 114, 25, 25, 6, 0.05), 0.1));
  return cell;
}

void AddToXTable(cell::Region& region, double mm) {
  for (double& value : region.table[TableAxis::X].error_mm) value += mm;
}

TEST(MachineModel, PosesSampleTheCheckLimits) {
  const cell::Fixture fixture = test::PaperFixture();
  const std::vector<BoardPose> poses = CheckLimitPoses(fixture);
  ASSERT_EQ(poses.size(), 27u);
  EXPECT_TRUE(poses.front().nominal());
  for (const BoardPose& pose : poses) {
    EXPECT_LE(std::hypot(pose.shift_x_mm, pose.shift_y_mm), fixture.max_shift_mm * kDiffPoseLimitFraction + 1e-12);
    EXPECT_LE(std::fabs(pose.rotation_deg), fixture.max_rotation_deg * kDiffPoseLimitFraction + 1e-12);
  }
  EXPECT_EQ(DescribeBoardPose(poses.front()), "nominal pose");
  EXPECT_EQ(DescribeBoardPose({0, 1.98, 0.495}), "shifted 1.980 mm toward 90°, turned +0.495°");
}

// Without tables the robot goes where it is commanded: the scan trips where
// the program's legs (at the nominal pose) cross the moved edges, as the
// tests' simulated scan computes it independently.
TEST(MachineModel, ScannedTripsLieOnTheProgramsLegsWhereTheyCrossTheMovedEdges) {
  const std::uint64_t seed = FixtureSeed();
  SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
  std::mt19937_64 rng(seed);
  const cell::Fixture fixture = test::PaperFixture();
  const std::vector<cell::Region> none;
  const PointCorrector identity(none);
  for (int trial = 0; trial < 20; ++trial) {
    // Small poses: every trip stays on its edge.
    const BoardPose pose{test::Uniform(rng, -0.3, 0.3), test::Uniform(rng, -0.3, 0.3), test::Uniform(rng, -0.1, 0.1)};
    const Eigen::Affine3d board = BoardPoseFix(fixture, pose);
    const std::vector<std::optional<Eigen::Vector2d>> trips = ScannedTrips(fixture, identity, board);
    const std::vector<Eigen::Vector2d> simulated = test::SimulateTrips(fixture, board);
    ASSERT_EQ(trips.size(), simulated.size());
    for (std::size_t k = 0; k < trips.size(); ++k) {
      ASSERT_TRUE(trips[k].has_value()) << TripName(k) << " at " << DescribeBoardPose(pose);
      EXPECT_LT((*trips[k] - simulated[k]).norm(), 1e-9) << TripName(k) << " at " << DescribeBoardPose(pose);
    }
  }
  // Shifted 1.98 mm in +x, T8 slides 3.85 mm down V2's second leg (1.98 mm
  // times the leg's 15:9 slope's secant), not 1.98 mm with the board.
  const std::vector<std::optional<Eigen::Vector2d>> shifted =
      ScannedTrips(fixture, identity, BoardPoseFix(fixture, {1.98, 0, 0}));
  const std::vector<std::optional<Eigen::Vector2d>> nominal = ScannedTrips(fixture, identity, NominalFix(fixture));
  ASSERT_TRUE(shifted[7] && nominal[7]);
  EXPECT_NEAR((*shifted[7] - *nominal[7]).norm(), 1.98 * std::hypot(1.0, 15.0 / 9.0), 1e-9);
  // Shifted 3.5 mm, p3's line lies beyond the start of V2's first leg and
  // the end of its second: T5 and T8 are not made; T1 still is.
  const std::vector<std::optional<Eigen::Vector2d>> far =
      ScannedTrips(fixture, identity, BoardPoseFix(fixture, {3.5, 0, 0}));
  EXPECT_FALSE(far[4].has_value());
  EXPECT_FALSE(far[7].has_value());
  EXPECT_TRUE(far[0].has_value());
}

// The model's poses are ones the robot's own scan accepts, within the
// limits; one brought in from its limit lies at the scan's boundary.
TEST(MachineModel, PosesAreWhatTheScanAcceptsWithinTheLimits) {
  const std::uint64_t seed = FixtureSeed();
  SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
  std::mt19937_64 rng(seed);
  const cell::Cell cell = RandomCell(rng);
  const MachineWorld world(cell);
  MachineModel model(cell, world);
  const cell::Fixture& board = cell.fixtures[0];
  const std::vector<BoardPose> limits = CheckLimitPoses(board);
  model.SetPoses(0, CommonPoses({{&model, 0}}));
  const std::vector<BoardPose>& poses = model.Poses(0);
  ASSERT_EQ(poses.size(), limits.size());
  const PointCorrector robot(cell.regions);
  ScanOptions options;
  options.estimator = board.estimator;
  options.regions = &cell.regions;
  const auto accepts = [&](const BoardPose& pose) {
    return ScanFixture(board, ScannedTrips(board, robot, BoardPoseFix(board, pose)), options).ok();
  };
  int brought_in = 0;
  for (std::size_t p = 0; p < poses.size(); ++p) {
    SCOPED_TRACE(DescribeBoardPose(limits[p]));
    std::string why;
    EXPECT_TRUE(model.ScanFix(0, p, &why).has_value()) << why;
    const double limit_size = std::hypot(limits[p].shift_x_mm, limits[p].shift_y_mm) + std::fabs(limits[p].rotation_deg);
    const double size = std::hypot(poses[p].shift_x_mm, poses[p].shift_y_mm) + std::fabs(poses[p].rotation_deg);
    if (limit_size == 0) continue;
    const double fraction = size / limit_size;
    EXPECT_LE(fraction, 1 + 1e-12);
    // The same direction.
    const BoardPose along = ScaledPose(limits[p], fraction);
    EXPECT_LT(std::fabs(along.shift_x_mm - poses[p].shift_x_mm), 1e-12);
    EXPECT_LT(std::fabs(along.shift_y_mm - poses[p].shift_y_mm), 1e-12);
    EXPECT_LT(std::fabs(along.rotation_deg - poses[p].rotation_deg), 1e-12);
    if (fraction > 1 - 1e-12) continue;
    ++brought_in;
    // Brought in to 99 % of the boundary, found to 1/1024 of the limit.
    EXPECT_TRUE(accepts(poses[p]));
    EXPECT_FALSE(accepts(ScaledPose(limits[p], std::min(1.0, fraction / kDiffPoseLimitFraction + 2.0 / 1024))));
  }
  // The paper board's trips leave their windows and edges well inside
  // 2 mm and 0.5° in most directions (tests/linuxcnc-sim/README.md).
  EXPECT_GT(brought_in, 10);
}

TEST(MachineModel, ItsOwnTablesPutEveryPointWhereTheBoardDoes) {
  const std::uint64_t seed = FixtureSeed();
  SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < 5; ++trial) {
    const cell::Cell cell = RandomCell(rng);
    const MachineWorld world(cell);
    const MachineModel model(cell, world);
    const cell::Fixture& board = cell.fixtures[0];
    for (std::size_t p = 0; p < model.Poses(0).size(); ++p) {
      const Eigen::Vector2d f(test::Uniform(rng, 16, 58), test::Uniform(rng, 24, 66));
      const MachinePoint point = model.FixturePoint(0, p, f);
      ASSERT_TRUE(point.ok) << point.why;
      const Eigen::Vector2d wanted = ToBase(BoardPoseFix(board, model.Poses(0)[p]), f);
      EXPECT_LT((point.lands - wanted).norm(), 1e-9) << "pose " << DescribeBoardPose(model.Poses(0)[p]);
      EXPECT_NEAR(point.angle_deg, board.angle_deg + model.Poses(0)[p].rotation_deg, 1e-9);
      EXPECT_EQ(point.region, 0);
    }
  }
}

TEST(MachineModel, ARemeasuredPlacingTableMovesCommandsAndLandings) {
  const std::uint64_t seed = FixtureSeed();
  SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
  std::mt19937_64 rng(seed);
  const cell::Cell old_cell = RandomCell(rng);
  cell::Cell new_cell = old_cell;
  AddToXTable(new_cell.regions[0], 0.012);  // the robot errs 12 µm further in x
  // As the diff does: both through their own tables, the robot as NEW's cell says.
  const MachineWorld world(new_cell);
  const MachineModel old_model(old_cell, world), new_model(new_cell, world);
  const Eigen::Vector2d f(20, 40);
  for (std::size_t p = 0; p < old_model.Poses(0).size(); ++p) {
    const MachinePoint a = old_model.FixturePoint(0, p, f), b = new_model.FixturePoint(0, p, f);
    ASSERT_TRUE(a.ok && b.ok);
    // The markers' tables did not change: the same FIX, so the same required position.
    EXPECT_LT((a.required - b.required).norm(), 1e-9);
    // OLD's command now lands 12 µm off; NEW's command is 12 µm back.
    EXPECT_NEAR(b.lands.x() - a.lands.x(), -0.012, 1e-9);
    EXPECT_NEAR(b.lands.y() - a.lands.y(), 0, 1e-9);
    EXPECT_NEAR(b.command.x() - a.command.x(), -0.012, 0.012 * 0.05);  // less the table's slope
  }
  // A base position corrected at run time moves alike; a command as written does not.
  const Eigen::Vector2d required(170, 80);
  EXPECT_NEAR(new_model.RunTimePoint(required).command.x() - old_model.RunTimePoint(required).command.x(), -0.012,
              0.012 * 0.05);
  EXPECT_LT((new_model.AsWritten(required).lands - old_model.AsWritten(required).lands).norm(), 1e-12);
}

TEST(MachineModel, ARemeasuredMarkerTableMovesTheBoardsTargets) {
  const std::uint64_t seed = FixtureSeed();
  SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
  std::mt19937_64 rng(seed);
  const cell::Cell old_cell = RandomCell(rng);
  cell::Cell new_cell = old_cell;
  AddToXTable(new_cell.regions[1], 0.012);  // under marker 1 only: the board seems turned
  const MachineWorld world(new_cell);
  const MachineModel old_model(old_cell, world), new_model(new_cell, world);
  double largest = 0;
  for (std::size_t p = 0; p < old_model.Poses(0).size(); ++p) {
    const MachinePoint a = old_model.FixturePoint(0, p, {40, 40}), b = new_model.FixturePoint(0, p, {40, 40});
    ASSERT_TRUE(a.ok && b.ok) << a.why << b.why;
    largest = std::max(largest, (b.lands - a.lands).norm());
  }
  // Marker 1's trips moved 12 µm: the fitted board moves by micrometres.
  EXPECT_GT(largest, 0.001);
  EXPECT_LT(largest, 0.05);
}

// One machine for both programs: OLD's cell says the board's nominal pose
// and its scan paths are elsewhere than NEW's cell (the machine) does. Its
// legs then run elsewhere, its trips land elsewhere on the same true edges,
// and its runtime finds the same pose: nothing it commands moves.
TEST(MachineModel, ANominalPoseOrScanPathOfItsOwnMovesNothing) {
  const std::uint64_t seed = FixtureSeed();
  SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
  std::mt19937_64 rng(seed);
  const cell::Cell new_cell = RandomCell(rng);
  for (int change = 0; change < 3; ++change) {
    cell::Cell old_cell = new_cell;
    cell::Fixture& fixture = old_cell.fixtures[0];
    if (change == 0) fixture.origin_mm += Eigen::Vector2d(0.02, -0.015);
    if (change == 1) fixture.angle_deg += 0.01;
    if (change == 2) {
      for (cell::ScanPath& path : fixture.scan_paths) {
        for (cell::Point2& point : path.points) point.y() += 0.3;  // every leg crosses its edge 0.3 mm higher
      }
    }
    const MachineWorld world(new_cell);
    MachineModel old_model(old_cell, world), new_model(new_cell, world);
    const std::vector<BoardPose> poses = CommonPoses({{&old_model, 0}, {&new_model, 0}});
    old_model.SetPoses(0, poses);
    new_model.SetPoses(0, poses);
    for (std::size_t p = 0; p < poses.size(); ++p) {
      SCOPED_TRACE(testing::Message() << "change " << change << ", " << DescribeBoardPose(poses[p]));
      const MachinePoint a = old_model.FixturePoint(0, p, {40, 40}), b = new_model.FixturePoint(0, p, {40, 40});
      ASSERT_TRUE(a.ok && b.ok) << a.why << b.why;
      EXPECT_LT((b.lands - a.lands).norm(), 1e-7);
      // And where the board puts it.
      EXPECT_LT((b.lands - ToBase(BoardPoseFix(new_cell.fixtures[0], poses[p]), {40, 40})).norm(), 1e-9);
    }
  }
}

// The board re-measured: marker 2's edges 20 µm further out (L1 + 0.02).
// The machine's board is NEW's; OLD's runtime fits the same trips to its
// own, older geometry and finds another pose, so every part it places moves
// by the difference, as `smtcal fixture` on those trips with each cell says.
TEST(MachineModel, ARemeasuredMarkerEdgeMovesEveryPartOfTheOtherProgram) {
  const std::uint64_t seed = FixtureSeed();
  SCOPED_TRACE(testing::Message() << "seed " << seed << " (SMTCAL_TEST_SEED repeats it)");
  std::mt19937_64 rng(seed);
  const cell::Cell old_cell = RandomCell(rng);
  cell::Cell new_cell = old_cell;
  cell::Fixture& board = new_cell.fixtures[0];
  board.l1_mm += 0.02;
  board.edges[2].from.x() += 0.02;
  board.edges[2].to.x() += 0.02;
  board.edges[3].from.x() += 0.02;
  board.edges[3].to.x() += 0.02;
  const MachineWorld world(new_cell);
  MachineModel old_model(old_cell, world), new_model(new_cell, world);
  const std::vector<BoardPose> poses = CommonPoses({{&old_model, 0}, {&new_model, 0}});
  old_model.SetPoses(0, poses);
  new_model.SetPoses(0, poses);
  const PointCorrector robot(new_cell.regions);
  for (std::size_t p = 0; p < poses.size(); ++p) {
    SCOPED_TRACE(DescribeBoardPose(poses[p]));
    const Eigen::Affine3d truth = BoardPoseFix(board, poses[p]);
    // The same trips, each program's own estimate of them.
    const std::vector<std::optional<Eigen::Vector2d>> trips = ScannedTrips(old_cell.fixtures[0], board, robot, truth);
    ScanOptions options;
    options.estimator = old_cell.fixtures[0].estimator;
    options.regions = &old_cell.regions;
    const ScanResult old_scan = ScanFixture(old_cell.fixtures[0], trips, options);
    ASSERT_TRUE(old_scan.ok());
    for (const Eigen::Vector2d& f : {Eigen::Vector2d(20, 30), Eigen::Vector2d(150, 70)}) {
      const MachinePoint a = old_model.FixturePoint(0, p, f), b = new_model.FixturePoint(0, p, f);
      ASSERT_TRUE(a.ok && b.ok) << a.why << b.why;
      EXPECT_LT((b.lands - ToBase(truth, f)).norm(), 1e-9);  // NEW's program knows the board
      EXPECT_LT((a.lands - ToBase(*old_scan.fix, f)).norm(), 1e-9);  // OLD's puts it where its estimate does
      EXPECT_GT((a.lands - b.lands).norm(), 0.001);                  // micrometres apart
      EXPECT_LT((a.lands - b.lands).norm(), 0.03);
    }
  }
}

}  // namespace
}  // namespace smtcal
