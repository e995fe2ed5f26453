// The scan geometry: expected trips of the paper cell's board in path order,
// their windows, and the paths and trips in base coordinates for a pose.
#include <gtest/gtest.h>

#include "calibration/fixture_geometry.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

TEST(FixtureGeometry, PaperBoardTripsInPathOrder) {
  const cell::Fixture fixture = test::PaperFixture();
  const std::vector<ExpectedTrip> trips = ExpectedTrips(fixture);
  ASSERT_EQ(trips.size(), 8u);
  // T1..T8 on p2, p1, p1, p2, p3, p4, p4, p3 (edges 1, 0, 0, 1, 2, 3, 3, 2).
  const int edges[] = {1, 0, 0, 1, 2, 3, 3, 2};
  const Eigen::Vector2d points[] = {{0, 3}, {3, 0}, {4.2, 0}, {0, 7}, {190, 87}, {187, 90}, {185.8, 90}, {190, 83}};
  for (std::size_t k = 0; k < trips.size(); ++k) {
    SCOPED_TRACE(TripName(k));
    EXPECT_EQ(trips[k].edge, edges[k]);
    EXPECT_NEAR((trips[k].in_fixture - points[k]).norm(), 0, 1e-12);
    EXPECT_EQ(trips[k].path, k / 4);
    EXPECT_EQ(trips[k].leg, (k / 2) % 2);
  }
  // Along each leg the trips come in order.
  EXPECT_LT(trips[0].along_mm, trips[1].along_mm);
  EXPECT_NEAR(trips[0].along_mm, 3 * std::sqrt(2.0), 1e-12);
}

TEST(FixtureGeometry, TripsMoveWithThePose) {
  const cell::Fixture fixture = test::PaperFixture();
  const Eigen::Affine3d pose = PlanarFix(Eigen::Vector2d(100, 50), 30 * kRadPerDeg);
  const std::vector<Eigen::Vector2d> base = NominalTrips(fixture, pose);
  const std::vector<ExpectedTrip> trips = ExpectedTrips(fixture);
  for (std::size_t k = 0; k < trips.size(); ++k) {
    EXPECT_NEAR((ToFixtureFrame(pose, base[k]) - trips[k].in_fixture).norm(), 0, 1e-12);
  }
  const auto paths = ScanPathsInBase(fixture, pose);
  ASSERT_EQ(paths.size(), 2u);
  EXPECT_NEAR((paths[0][0] - ToBase(pose, Eigen::Vector2d(-3, 6))).norm(), 0, 1e-12);
  EXPECT_NEAR(FixAngleRad(pose), 30 * kRadPerDeg, 1e-15);
  EXPECT_NEAR((FixOrigin(pose) - Eigen::Vector2d(100, 50)).norm(), 0, 0);
}

TEST(FixtureGeometry, WindowsAreClippedToTheLeg) {
  cell::Fixture fixture = test::PaperFixture();
  fixture.trip_window_mm = 100;  // wider than any leg
  const std::vector<TripWindow> windows = TripWindows(fixture);
  ASSERT_EQ(windows.size(), 8u);
  // T1 is on V1's first leg (-3,6)->(6,-3): the window is the whole leg.
  EXPECT_NEAR((windows[0].from - Eigen::Vector2d(135, 46)).norm(), 0, 1e-12);
  EXPECT_NEAR((windows[0].to - Eigen::Vector2d(144, 37)).norm(), 0, 1e-12);
  fixture.trip_window_mm = 1;
  const TripWindow narrow = TripWindows(fixture)[0];
  EXPECT_NEAR((narrow.from - narrow.nominal).norm(), 1, 1e-12);
  EXPECT_NEAR((narrow.to - narrow.nominal).norm(), 1, 1e-12);
}

TEST(FixtureGeometry, EdgeLinesHaveUnitNormalsAndPassThroughTheEdge) {
  const cell::Fixture fixture = test::PaperFixture();
  for (const cell::MarkerEdge& edge : fixture.edges) {
    const EdgeLine line = EdgeLineOf(edge);
    EXPECT_NEAR(line.normal.norm(), 1, 1e-15);
    EXPECT_NEAR(line.normal.dot(edge.from) - line.offset, 0, 1e-12);
    EXPECT_NEAR(line.normal.dot(edge.to) - line.offset, 0, 1e-12);
  }
}

TEST(FixtureGeometry, RelativeAngleWrapsAroundPi) {
  const Eigen::Affine3d a = PlanarFix(Eigen::Vector2d::Zero(), 179 * kRadPerDeg);
  const Eigen::Affine3d b = PlanarFix(Eigen::Vector2d::Zero(), -179 * kRadPerDeg);
  EXPECT_NEAR(RelativeAngleRad(a, b) * kDegPerRad, 2, 1e-9);
  EXPECT_NEAR(RelativeAngleRad(b, a) * kDegPerRad, -2, 1e-9);
}

}  // namespace
}  // namespace smtcal
