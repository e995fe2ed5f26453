// Outlier nodes of error tables (calibration/table_outliers.h): none in smooth
// tables, random or the example's; a slipped digit, a lost sign or a bad
// measurement in any node is found, with the slip named; two adjacent slips
// are both named and no neighbour is blamed. Seed:
// SMTCAL_TEST_SEED.
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "base/diagnostics.h"
#include "calibration/table_outliers.h"
#include "frontend/table_csv.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

// A table like a measured one: 11 x 11 nodes at 5 mm pitch, a robot's error
// (a scale and squareness error and a bow over a few hundred millimetres,
// up to about 0.2 mm) and each node the mean of 20 measurements with 2.5 µm
// scatter, as the paper measured.
ErrorTable MeasuredLikeTable(std::mt19937_64& rng) {
  ErrorTable table;
  table.name = "measured-like";
  std::normal_distribution<double> noise(0, 0.0025 / std::sqrt(20.0));
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = table.axes[static_cast<int>(axis)];
    for (int k = 0; k < 11; ++k) {
      t.xs.push_back(5.0 * k);
      t.ys.push_back(5.0 * k);
    }
    const double offset = test::Uniform(rng, -0.1, 0.1), sx = test::Uniform(rng, -0.002, 0.002),
                 sy = test::Uniform(rng, -0.002, 0.002), bow = test::Uniform(rng, -0.05, 0.05),
                 wavelength = test::Uniform(rng, 150, 400), phase = test::Uniform(rng, 0, 6.28);
    for (double y : t.ys) {
      for (double x : t.xs) {
        t.error_mm.push_back(offset + sx * x + sy * y + bow * std::sin(2 * std::numbers::pi * (x + 0.5 * y) / wavelength + phase) +
                             noise(rng));
        t.stddev_mm.push_back(0.0025);
        t.count.push_back(20);
      }
    }
  }
  return table;
}

TEST(TableOutliers, SmoothRandomTablesHaveNone) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < 200; ++trial) {
    const ErrorTable table = test::RandomSmoothTable(rng, 0, 0, 50, 50, 11, test::Uniform(rng, 0.01, 0.3));
    EXPECT_TRUE(FindTableOutliers(table).empty()) << "trial " << trial;
    EXPECT_TRUE(FindTableOutliers(MeasuredLikeTable(rng)).empty()) << "trial " << trial;
  }
}

TEST(TableOutliers, TheExampleTablesHaveNone) {
  for (const char* name : {"placing-table.csv", "layer2-table.csv", "layer3-table.csv", "feeders-table.csv",
                           "marker1-table.csv", "marker2-table.csv"}) {
    SourceManager sources;
    Diagnostics diags(sources);
    Result<std::uint32_t> file = sources.Load(fmt::format("{}/examples/paper-cell/{}", SMTCAL_SOURCE_DIR, name));
    ASSERT_TRUE(file) << name;
    std::optional<ErrorTable> table = ReadErrorTable(file.value(), diags);
    ASSERT_TRUE(table) << diags.RenderText();
    EXPECT_TRUE(FindTableOutliers(*table).empty()) << name;
  }
}

TEST(TableOutliers, EverySlipInAnyNodeIsFoundAndNamed) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  struct Slip {
    double factor;
    const char* named;
  };
  for (const Slip slip : {Slip{10, "a decimal point moved"}, Slip{0.1, "a decimal point moved"},
                          Slip{1000, "micrometres written as millimetres"}, Slip{-1, "a lost or added minus sign"}}) {
    for (int trial = 0; trial < 60; ++trial) {
      ErrorTable table = MeasuredLikeTable(rng);
      const TableAxis axis = trial % 2 == 0 ? TableAxis::X : TableAxis::Y;
      AxisTable& t = table.axes[static_cast<int>(axis)];
      const std::size_t i = static_cast<std::size_t>(trial % 11), j = static_cast<std::size_t>((trial * 7) % 11);
      const double value = t.error_mm[t.Index(i, j)];
      // A slip that moves the value by less than 10 µm is not told from noise.
      if (std::abs(value * (slip.factor - 1)) < 0.01) continue;
      t.error_mm[t.Index(i, j)] = value * slip.factor;
      const std::vector<TableOutlier> outliers = FindTableOutliers(table);
      ASSERT_EQ(outliers.size(), 1u) << "factor " << slip.factor << " at node " << i << ", " << j;
      EXPECT_EQ(outliers[0].axis, axis);
      EXPECT_EQ(outliers[0].i, i);
      EXPECT_EQ(outliers[0].j, j);
      EXPECT_NEAR(outliers[0].predicted_mm, value, 0.005);  // an edge node is extrapolated over the bow
      EXPECT_NE(outliers[0].likely_slip.find(slip.named), std::string::npos)
          << "factor " << slip.factor << ": '" << outliers[0].likely_slip << "'";
    }
  }
}

TEST(TableOutliers, ABadMeasurementIsFoundWithoutASlipToName) {
  std::mt19937_64 rng(test::FixtureSeed());
  ErrorTable table = MeasuredLikeTable(rng);
  AxisTable& t = table.axes[0];
  t.error_mm[t.Index(5, 5)] += 0.037;
  const std::vector<TableOutlier> outliers = FindTableOutliers(table);
  ASSERT_EQ(outliers.size(), 1u);
  EXPECT_EQ(outliers[0].i, 5u);
}

// Two adjacent nodes slipped: both are named, once each, with predictions
// from their good neighbours; no neighbour is blamed.
TEST(TableOutliers, TwoAdjacentSlippedNodesAreBothNamedAndNothingElse) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < 100; ++trial) {
    ErrorTable table = MeasuredLikeTable(rng);
    const TableAxis axis = trial % 2 == 0 ? TableAxis::X : TableAxis::Y;
    AxisTable& t = table.axes[static_cast<int>(axis)];
    const std::size_t i = static_cast<std::size_t>(trial % 10), j = static_cast<std::size_t>((trial * 7) % 11);
    const double a = t.error_mm[t.Index(i, j)], b = t.error_mm[t.Index(i + 1, j)];
    const double fa = trial % 3 == 0 ? -1 : 10, fb = trial % 3 == 1 ? -1 : 10;
    // Two small slips side by side can hide each other: 30 µm each is plain.
    if (std::abs(a * (fa - 1)) < 0.03 || std::abs(b * (fb - 1)) < 0.03) continue;
    t.error_mm[t.Index(i, j)] = a * fa;
    t.error_mm[t.Index(i + 1, j)] = b * fb;
    const std::vector<TableOutlier> outliers = FindTableOutliers(table);
    std::string found;
    for (const TableOutlier& o : outliers) {
      found += fmt::format(" ({}, {}) {:.6f} predicted {:.6f} [{}];", o.i, o.j, o.value_mm, o.predicted_mm, o.likely_slip);
    }
    ASSERT_EQ(outliers.size(), 2u) << "trial " << trial << " at " << i << ", " << j << ":" << found;
    EXPECT_EQ(outliers[0].i, i);
    EXPECT_EQ(outliers[1].i, i + 1);
    EXPECT_EQ(outliers[0].j, j);
    EXPECT_EQ(outliers[1].j, j);
    EXPECT_NEAR(outliers[0].predicted_mm, a, 0.005);
    EXPECT_NEAR(outliers[1].predicted_mm, b, 0.005);
  }
}

// A node whose own measurements scatter far beyond its axis's (one bad
// reading among them) is the one blamed, not the neighbours its mean spoils.
TEST(TableOutliers, ANodeWithABadReadingIsBlamedNotItsNeighbours) {
  std::mt19937_64 rng(test::FixtureSeed());
  ErrorTable table = MeasuredLikeTable(rng);
  AxisTable& t = table.axes[0];
  const std::size_t node = t.Index(5, 5);
  // The case: one reading of -77.0 among twenty of -0.077.
  t.error_mm[node] = (19 * -0.077 - 77.0) / 20;
  t.stddev_mm[node] = 17.2;
  const std::vector<TableOutlier> outliers = FindTableOutliers(table);
  ASSERT_EQ(outliers.size(), 1u);
  EXPECT_EQ(outliers[0].i, 5u);
  EXPECT_EQ(outliers[0].j, 5u);
  EXPECT_NE(outliers[0].likely_slip.find("a bad measurement among its 20"), std::string::npos)
      << outliers[0].likely_slip;
}

}  // namespace
}  // namespace smtcal
