// Comparing two error tables (calibration/table_diff.h): node by node on
// one grid, through the interpolation on two, per region.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "calibration/table_diff.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

ErrorTable Table(std::mt19937_64& rng) { return test::RandomSmoothTable(rng, 150, 60, 50, 50, 11, 0.1); }

TEST(TableDiff, AShiftOnTheSameGridIsSeenAtEveryNode) {
  std::mt19937_64 rng(1);
  const ErrorTable a = Table(rng);
  ErrorTable b = a;
  for (double& v : b[TableAxis::X].error_mm) v += 0.012;
  const TableChanges changes = CompareTables(a, b, 10, nullptr);
  const AxisComparison& x = changes.axes[0];
  EXPECT_TRUE(x.same_grid);
  EXPECT_EQ(x.stats.nodes, 121u);
  EXPECT_NEAR(x.stats.max_abs_um, 12, 1e-9);
  EXPECT_NEAR(x.stats.mean_um, 12, 1e-9);
  EXPECT_NEAR(x.stats.rms_um, 12, 1e-9);
  EXPECT_EQ(x.stats.beyond, 121u);
  EXPECT_EQ(changes.axes[1].stats.max_abs_um, 0);
  EXPECT_EQ(changes.beyond(), 121u);
  EXPECT_EQ(CompareTables(a, b, 12.5, nullptr).beyond(), 0u);
  for (const NodeChange& node : changes.nodes) {
    EXPECT_TRUE(node.on_old_grid && node.on_new_grid);
  }
}

// A uniform change has no node that changed "most" (issue 40): the x axis
// shifted alike everywhere (to within printing) is uniform and ranks no
// node; one node changed 1 µm more than the rest is ranked first.
TEST(TableDiff, AUniformChangeRanksNoNode) {
  std::mt19937_64 rng(2);
  const ErrorTable a = Table(rng);
  ErrorTable b = a;
  std::vector<double>& x = b[TableAxis::X].error_mm;
  for (std::size_t i = 0; i < x.size(); ++i) x[i] += 0.012 + (i % 2 == 0 ? 0.00000001 : 0);  // 12.00001 µm or 12
  TableChanges changes = CompareTables(a, b, 10, nullptr);
  EXPECT_TRUE(changes.axes[0].stats.uniform());
  EXPECT_TRUE(LargestChanges(changes, 10).empty());
  x[37] += 0.001;
  changes = CompareTables(a, b, 10, nullptr);
  EXPECT_FALSE(changes.axes[0].stats.uniform());
  const std::vector<std::size_t> largest = LargestChanges(changes, 10);
  ASSERT_FALSE(largest.empty());
  EXPECT_NEAR(changes.nodes[largest.front()].change_um, 13, 1e-6);
  EXPECT_NEAR(changes.axes[0].stats.max_um - changes.axes[0].stats.min_um, 1, 1e-6);
}

TEST(TableDiff, OnAnotherGridTheSameFieldDoesNotChange) {
  std::mt19937_64 rng(2);
  const ErrorTable a = Table(rng);
  // B: A's field sampled on a grid twice as fine, over a smaller area.
  const CalibrationMap map(a);
  ErrorTable b;
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = b[axis];
    for (int i = 0; i <= 16; ++i) t.xs.push_back(a[axis].xs[2] + 2.5 * i);
    for (int j = 0; j <= 16; ++j) t.ys.push_back(a[axis].ys[2] + 2.5 * j);
    for (double y : t.ys) {
      for (double x : t.xs) t.error_mm.push_back(map.AxisDelta(axis, x, y));
    }
  }
  const TableChanges changes = CompareTables(a, b, 10, nullptr);
  for (const AxisComparison& c : changes.axes) {
    EXPECT_FALSE(c.same_grid);
    EXPECT_TRUE(c.overlap);
    EXPECT_LT(c.stats.max_abs_um, 1e-9);
    EXPECT_GT(c.old_nodes_outside, 0u);  // A's nodes beyond B's smaller grid
    EXPECT_EQ(c.new_nodes_outside, 0u);
  }
  // A's nodes inside B's grid lie on B's grid too (every second line): once each.
  EXPECT_EQ(changes.axes[0].stats.nodes, 17u * 17u);
  ASSERT_TRUE(ChangeTable(a, b).has_value());
}

TEST(TableDiff, RegionsGetTheirOwnFigures) {
  std::mt19937_64 rng(3);
  const ErrorTable a = Table(rng);
  ErrorTable b = a;
  // Only the nodes with x >= 175 change.
  AxisTable& t = b[TableAxis::Y];
  for (std::size_t j = 0; j < t.ny(); ++j) {
    for (std::size_t i = 0; i < t.nx(); ++i) {
      if (t.xs[i] >= 175) t.error_mm[t.Index(i, j)] -= 0.02;
    }
  }
  std::vector<cell::Region> regions(2);
  regions[0].name = "left";
  regions[0].x_mm = {150, 170};
  regions[0].y_mm = {60, 110};
  regions[1].name = "right";
  regions[1].x_mm = {176, 200};
  regions[1].y_mm = {60, 110};
  const TableChanges changes = CompareTables(a, b, 10, &regions);
  ASSERT_EQ(changes.regions.size(), 2u);
  EXPECT_EQ(changes.regions[0].axes[1].max_abs_um, 0);
  EXPECT_NEAR(changes.regions[1].axes[1].max_abs_um, 20, 1e-9);
  EXPECT_NEAR(changes.regions[1].axes[1].mean_um, -20, 1e-9);
  const std::vector<std::size_t> largest = LargestChanges(changes, 3);
  ASSERT_EQ(largest.size(), 3u);
  EXPECT_NEAR(changes.nodes[largest[0]].change_um, -20, 1e-9);
}

}  // namespace
}  // namespace smtcal
