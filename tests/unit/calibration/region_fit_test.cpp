// FitInRegion (calibration/region_fit.h): which region a shape belongs to,
// how far it reaches past each edge, and the move that centres it — the
// numbers `cell check` (pockets) and `import` (boards) print.
#include "calibration/region_fit.h"

#include <cmath>

#include <gtest/gtest.h>

namespace smtcal {
namespace {

cell::Cell TwoRegions() {
  cell::Cell cell;
  cell::Region a;
  a.name = "layer1";
  a.x_mm = {150.5, 199.5};
  a.y_mm = {60.5, 109.5};
  cell::Region b = a;
  b.name = "layer2";
  b.x_mm = {205.5, 254.5};
  cell.regions = {a, b};
  return cell;
}

TEST(RegionFit, AShapeInsideItsRegionFits) {
  const cell::Cell cell = TwoRegions();
  const RegionFit fit = FitInRegion(cell, {{160, 70}, {190, 100}});
  ASSERT_NE(fit.region, nullptr);
  EXPECT_EQ(fit.region->name, "layer1");
  EXPECT_TRUE(fit.fits());
  EXPECT_FALSE(fit.larger());
  EXPECT_EQ(fit.past_mm(), 0);
}

// The example's pocket of tests/golden/cell-plot/pocket_over_region.toml:
// x 163..210, y 61..108 against layer1.
TEST(RegionFit, APocketOverTheEdgeSaysHowFarAndWhereAndTheMoveThatFits) {
  const cell::Cell cell = TwoRegions();
  const RegionFit fit = FitInRegion(cell, {{163, 61}, {210, 61}, {210, 108}, {163, 108}});
  ASSERT_NE(fit.region, nullptr);
  EXPECT_EQ(fit.region->name, "layer1");  // holds the centre (186.5, 84.5)
  EXPECT_FALSE(fit.fits());
  EXPECT_FALSE(fit.larger());
  EXPECT_NEAR(fit.past_x_hi, 10.5, 1e-12);
  EXPECT_EQ(fit.past_x_lo, 0);
  EXPECT_NEAR(fit.past_mm(), 10.5, 1e-12);
  EXPECT_EQ(fit.worst_point, Eigen::Vector2d(210, 61));  // the first corner that far out
  const Eigen::Vector2d move = fit.CentringMove();
  EXPECT_NEAR(move.x(), 175 - 186.5, 1e-12);
  EXPECT_NEAR(move.y(), 85 - 84.5, 1e-12);
  // Moved so, it fits.
  std::vector<Eigen::Vector2d> moved = {{163, 61}, {210, 61}, {210, 108}, {163, 108}};
  for (Eigen::Vector2d& p : moved) p += move;
  EXPECT_TRUE(FitInRegion(cell, moved).fits());
}

// A board 50 mm tall on a 49 mm region: no move makes it fit.
TEST(RegionFit, AShapeLargerThanItsRegionIsLarger) {
  const cell::Cell cell = TwoRegions();
  const RegionFit fit = FitInRegion(cell, {{170, 60}, {180, 110}});
  ASSERT_NE(fit.region, nullptr);
  EXPECT_TRUE(fit.larger());
  EXPECT_NEAR(fit.past_y_lo, 0.5, 1e-12);
  EXPECT_NEAR(fit.past_y_hi, 0.5, 1e-12);
}

// A shape whose centre is between the regions belongs to the one it overlaps
// most; one that overlaps none has no region.
TEST(RegionFit, TheRegionIsTheOneOverlappedMostOrNone) {
  const cell::Cell cell = TwoRegions();
  // Centre x 204.5, in neither; 2.5 mm over layer1, 6.5 mm over layer2.
  const RegionFit between = FitInRegion(cell, {{197, 70}, {212, 80}});
  ASSERT_NE(between.region, nullptr);
  EXPECT_EQ(between.region->name, "layer2");
  EXPECT_NEAR(between.past_x_lo, 8.5, 1e-12);
  const RegionFit far = FitInRegion(cell, {{0, 0}, {10, 10}});
  EXPECT_EQ(far.region, nullptr);
  EXPECT_FALSE(far.fits());
  EXPECT_TRUE(std::isinf(far.past_mm()));
}

}  // namespace
}  // namespace smtcal
