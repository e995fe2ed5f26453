// The scan's capture range and time (calibration/scan_plan.h): the V paths
// the example had take a fifth of the fixture's limits, its hairpins all of
// them; every pose the capture range admits scans cleanly (a property test:
// the legs cross their edge segments and the estimate is the pose); the
// time model against hand-computed moves.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "calibration/fixture_estimation.h"
#include "calibration/motion_time.h"
#include "calibration/scan_plan.h"
#include "fixture_test_cell.h"

namespace smtcal {
namespace {

using test::FixtureSeed;
using test::HairpinFixture;
using test::PaperFixture;
using test::Uniform;

TEST(ScanPlan, MoveTimeIsTrapezoidal) {
  EXPECT_DOUBLE_EQ(MoveTime(0, 100, 1000), 0);
  EXPECT_NEAR(MoveTime(4, 100, 1000), 2 * std::sqrt(4.0 / 1000), 1e-12);  // triangular: never at speed
  EXPECT_NEAR(MoveTime(100, 100, 1000), 100.0 / 100 + 100.0 / 1000, 1e-12);
  EXPECT_DOUBLE_EQ(MoveTime(-4, 100, 1000), MoveTime(4, 100, 1000));
}

TEST(ScanPlan, VPathsCaptureAFifthOfTheLimits) {
  const cell::Fixture fixture = PaperFixture(cell::Estimator::kRigid);
  const CaptureRange range = ScanCaptureRange(fixture);
  EXPECT_GT(range.factor, 0.2);
  EXPECT_LT(range.factor, 0.25);
  EXPECT_NEAR(range.shift_mm, range.factor * 2, 1e-12);
  EXPECT_NEAR(range.rotation_deg, range.factor * 0.5, 1e-12);
  EXPECT_FALSE(range.limited_by.empty());
  // The board the example's old scenario refused: 0.6 mm off towards -y,
  // where T4 leaves edge p2's visible segment.
  std::string why;
  EXPECT_FALSE(ScanMeasuresPose(fixture, {0.0, 1.2}, 0, &why));
  EXPECT_NE(why.find("visible segment"), std::string::npos) << why;
  EXPECT_TRUE(ScanMeasuresPose(fixture, {0.1, -0.1}, 0.02));
}

TEST(ScanPlan, HairpinsCaptureEveryBoardTheLimitsAccept) {
  const CaptureRange range = ScanCaptureRange(HairpinFixture());
  EXPECT_GE(range.factor, 1.0) << range.limited_by;
  EXPECT_LT(range.factor, 1.1);  // marker 2's 8 mm edges: 3.9 mm either side, 3.83 needed
  EXPECT_FALSE(range.limited_by.empty());
}

TEST(ScanPlan, TooSmallAWindowLimitsTheRange) {
  cell::Fixture fixture = HairpinFixture();
  fixture.trip_window_mm = 3;
  const CaptureRange range = ScanCaptureRange(fixture);
  EXPECT_LT(range.factor, 1.0);
  EXPECT_NE(range.limited_by.find("trip_window_mm"), std::string::npos) << range.limited_by;
}

// Every pose within the capture range: each leg crosses its edge's visible
// segment, and (within the fixture's limits too, which the checks hold a
// board to) the scan of the exact trips passes every check and gives the
// pose. Just beyond the range in the direction that limits it, a pose fails.
TEST(ScanPlan, PosesWithinTheCaptureRangeScanCleanly) {
  const std::uint64_t seed = FixtureSeed();
  SCOPED_TRACE("seed " + std::to_string(seed) + " (SMTCAL_TEST_SEED repeats)");
  std::mt19937_64 rng(seed);
  for (const cell::Fixture& fixture : {PaperFixture(cell::Estimator::kRigid), HairpinFixture()}) {
    const CaptureRange range = ScanCaptureRange(fixture);
    const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
    for (int n = 0; n < 300; ++n) {
      const double radius = range.shift_mm * std::sqrt(Uniform(rng, 0, 1)) * 0.999;
      const double direction = Uniform(rng, 0, 2 * M_PI);
      const Eigen::Vector2d shift = radius * Eigen::Vector2d(std::cos(direction), std::sin(direction));
      const double turn = Uniform(rng, -1, 1) * range.rotation_deg * 0.999;
      std::string why;
      ASSERT_TRUE(ScanMeasuresPose(fixture, shift, turn, &why)) << fixture.scan_paths[0].name << ": " << why;
      const Eigen::Affine3d truth = PlanarFix(fixture.origin_mm + shift, (fixture.angle_deg + turn) * kRadPerDeg);
      const std::vector<Eigen::Vector2d> trips = test::SimulateTrips(fixture, truth);
      for (std::size_t k = 0; k < trips.size(); ++k) {
        // The trip lies on the visible segment of its edge on the true board.
        const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(expected[k].edge)];
        const Eigen::Vector2d f = ToFixtureFrame(truth, trips[k]);
        const Eigen::Vector2d along = edge.to - edge.from;
        const double u = (f - edge.from).dot(along) / along.squaredNorm();
        EXPECT_GT(u, 0) << TripName(k);
        EXPECT_LT(u, 1) << TripName(k);
      }
      if (radius > fixture.max_shift_mm || std::abs(turn) > fixture.max_rotation_deg) continue;
      ScanOptions options;
      options.estimator = cell::Estimator::kRigid;
      const ScanResult scan = ScanFixture(fixture, test::Present(trips), options);
      ASSERT_TRUE(scan.ok()) << DescribeFailure(scan, fixture);
      EXPECT_NEAR((FixOrigin(*scan.fix) - FixOrigin(truth)).norm(), 0, 1e-9);
    }
    // Beyond the range the paths lose the board somewhere.
    if (range.factor < kMaxCaptureFactor) {
      bool lost = false;
      for (int i = 0; i < 720 && !lost; ++i) {
        const double direction = i * M_PI / 360;
        for (double sign : {-1.0, 1.0}) {
          const Eigen::Vector2d shift =
              range.shift_mm * 1.02 * Eigen::Vector2d(std::cos(direction), std::sin(direction));
          lost = lost || !ScanMeasuresPose(fixture, shift, sign * range.rotation_deg * 1.02);
        }
      }
      EXPECT_TRUE(lost) << fixture.scan_paths[0].name;
    }
  }
}

// The robot the scan's times are checked with, by hand.
cell::Robot TimedRobot(double probe_turnaround_s) {
  cell::Robot robot;
  robot.xy_speed_mm_s = 800;
  robot.xy_accel_mm_s2 = 3000;
  robot.z_speed_mm_s = 300;
  robot.z_accel_mm_s2 = 2000;
  robot.safe_limz_mm = 0;
  robot.servo_period_s = 0.001;
  robot.probe_turnaround_s = probe_turnaround_s;
  return robot;
}

// One straight path across one edge: the moves by hand.
TEST(ScanPlan, TimeFollowsTheRuntimesMoves) {
  const cell::Robot robot = TimedRobot(0.004);
  cell::Fixture fixture = HairpinFixture();
  fixture.scan_z_mm = -2;
  const ScanTiming two = ScanTime(robot, fixture, std::nullopt);
  EXPECT_EQ(two.probe_moves, 3 * 8);
  EXPECT_NEAR(two.turnaround_s, 24 * 0.004, 1e-12);
  EXPECT_GT(two.latch_s, 0);
  // Two jumps down and up at the paths (z 2 mm each way) and the traverse
  // from M2's end to M1's start.
  const double z = MoveTime(2, 300, 2000);
  const Eigen::Vector2d m2_end(138 + 194.1, 40 + 86.1), m1_start(138 - 2.6, 40 + 3.9);
  EXPECT_NEAR(two.travel_s, 4 * z + MoveTime((m1_start - m2_end).norm(), 800, 3000), 1e-12);
  EXPECT_NEAR(two.end.x(), 138 - 2.6, 1e-12);
  EXPECT_NEAR(two.end.z(), 0, 1e-12);
  EXPECT_NEAR(two.seconds, two.travel_s + two.search_s + two.latch_s + two.turnaround_s, 1e-12);
  // One stage at the latch speed latches as well, and takes far longer.
  cell::Fixture one = fixture;
  one.scan_speed_mm_s = 8;
  one.latch_speed_mm_s = 0;
  const ScanTiming slow = ScanTime(robot, one, std::nullopt);
  EXPECT_EQ(slow.probe_moves, 8);
  EXPECT_EQ(slow.latch_s, 0);
  EXPECT_GT(slow.seconds, 2 * two.seconds);
  // Along the legs at 8 mm/s: about their length over the speed.
  double length = 0;
  for (const cell::ScanPath& path : one.scan_paths) {
    for (std::size_t i = 1; i < path.points.size(); ++i) length += (path.points[i] - path.points[i - 1]).norm();
  }
  EXPECT_NEAR(slow.search_s, length / 8, 0.1 * length / 8);
  // From a known point: the jump there first.
  const ScanTiming from = ScanTime(robot, fixture, ScanPoint(300, 130, -3));
  EXPECT_NEAR(from.travel_s - two.travel_s,
              MoveTime(3, 300, 2000) + MoveTime((Eigen::Vector2d(138 + 194.1, 40 + 85.9) -
                                                 Eigen::Vector2d(300, 130)).norm(), 800, 3000),
              1e-12);
}

// The predicted scan (every trip in its window) and the floor, against the
// full scan and by hand.
TEST(ScanPlan, PredictedScanAndFloor) {
  const cell::Robot robot = TimedRobot(0.025);
  cell::Fixture fixture = HairpinFixture();
  fixture.scan_z_mm = -2;
  const ScanPoint from(300, 130, -3);
  const ScanTiming full = ScanTime(robot, fixture, from);
  // Without a window every scan is searched in full.
  const ScanTiming none = ScanTime(robot, fixture, from, ScanSearch::kPredicted);
  EXPECT_EQ(none.seconds, full.seconds);
  EXPECT_EQ(none.probe_moves, full.probe_moves);
  fixture.predicted_window_mm = 0.3;
  const ScanTiming predicted = ScanTime(robot, fixture, from, ScanSearch::kPredicted);
  // Per path: the descent, four latches, three moves between them (the
  // hairpin's turn outside the marker is 0.36 mm, more than LinuxCNC's
  // shortest probe move).
  EXPECT_EQ(predicted.probe_moves, 2 * (1 + 4 + 3));
  EXPECT_NEAR(predicted.turnaround_s, 16 * 0.025, 1e-12);
  EXPECT_LT(predicted.seconds, full.seconds - 1);
  EXPECT_NEAR(predicted.seconds,
              predicted.travel_s + predicted.search_s + predicted.latch_s + predicted.turnaround_s, 1e-12);
  // A latch from 0.3 mm before the edge at 8 mm/s: accelerate (8/3000 s over
  // 0.0107 mm), cruise, half a servo period late, brake.
  const double latch = 8.0 / 3000 + (0.3 - 64.0 / 6000) / 8 + 0.0005 + 8.0 / 3000;
  EXPECT_NEAR(predicted.latch_s, 8 * latch, 1e-9);
  // The floor: the same jumps to the trips themselves, one latch from rest
  // reaching 8 mm/s at the edge, a turnaround per trip.
  const ScanTiming floor = ScanFloor(robot, fixture, from);
  EXPECT_EQ(floor.probe_moves, 8);
  EXPECT_EQ(floor.search_s, 0);
  EXPECT_NEAR(floor.latch_s, 8 * (2 * 8.0 / 3000 + 0.0005), 1e-12);
  EXPECT_NEAR(floor.turnaround_s, 8 * 0.025, 1e-12);
  const double z = MoveTime(2, 300, 2000);
  const Eigen::Vector2d t1(138 + 190, 40 + 85.9), t4(138 + 190, 40 + 86.1), t5(138 + 0, 40 + 3.9);
  EXPECT_NEAR(floor.travel_s,
              MoveTime(3, 300, 2000) + MoveTime((t1 - Eigen::Vector2d(300, 130)).norm(), 800, 3000) + 3 * z +
                  MoveTime((t5 - t4).norm(), 800, 3000) + z,
              1e-12);
  EXPECT_LT(floor.seconds, predicted.seconds);
  EXPECT_LT(predicted.seconds, full.seconds);
}

}  // namespace
}  // namespace smtcal
