// Screening repeated readings at one position (calibration/reading_screen.h):
// no alarm on clean groups, even with an ordinary shift between the sets;
// a slipped reading is found with its slip named; a whole set slipped by a
// unit or a decimal point is found and blamed when the group (or its
// surroundings) can tell. Random groups print their seed (SMTCAL_TEST_SEED).
#include <cmath>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/reading_screen.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

// The paper's group: two sets of ten readings, 2.5 µm scatter, rounded to
// the transducers' 1 µm, the second set shifted by `shift_mm`.
struct Group {
  std::vector<double> values;
  std::vector<long long> sets;
};

Group PaperGroup(std::mt19937_64& rng, double value_mm, double shift_mm = 0, int sets = 2) {
  std::normal_distribution<double> noise(0, 0.0025);
  Group g;
  for (int set = 1; set <= sets; ++set) {
    for (int rep = 0; rep < 10; ++rep) {
      g.values.push_back(std::round((value_mm + (set == 2 ? shift_mm : 0) + noise(rng)) * 1000) / 1000);
      g.sets.push_back(set);
    }
  }
  return g;
}

constexpr double kTypical = 0.0025;

TEST(ReadingScreen, CleanGroupsRaiseNoAlarm) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < 2000; ++trial) {
    // A set shift of up to 6 scatters is a warning of `table build`, not a slip.
    const Group g = PaperGroup(rng, test::Uniform(rng, -0.2, 0.2), test::Uniform(rng, -0.015, 0.015));
    const ReadingScreen screen = ScreenReadings(g.values, g.sets, kTypical, test::Uniform(rng, -0.2, 0.2));
    EXPECT_TRUE(screen.outliers.empty()) << "trial " << trial;
    EXPECT_FALSE(screen.set_slip) << "trial " << trial;
  }
}

TEST(ReadingScreen, ASlippedReadingIsFoundAndNamed) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  struct Slip {
    double factor;
    SlipKind kind;
  };
  for (const Slip slip : {Slip{10, SlipKind::kDecimalPoint}, Slip{0.1, SlipKind::kDecimalPoint},
                          Slip{1000, SlipKind::kMicrometres}, Slip{-1, SlipKind::kSign}}) {
    for (int trial = 0; trial < 200; ++trial) {
      // Far enough from zero that the slip moves the reading beyond 10 scatters.
      const double value = (trial % 2 == 0 ? 1 : -1) * test::Uniform(rng, 0.04, 0.2);
      Group g = PaperGroup(rng, value, test::Uniform(rng, -0.005, 0.005));
      const std::size_t k = static_cast<std::size_t>(trial) % g.values.size();
      g.values[k] *= slip.factor;
      const ReadingScreen screen = ScreenReadings(g.values, g.sets, kTypical);
      ASSERT_EQ(screen.outliers.size(), 1u) << "factor " << slip.factor << " trial " << trial;
      EXPECT_EQ(screen.outliers[0].index, k);
      EXPECT_EQ(screen.outliers[0].slip.kind, slip.kind) << "factor " << slip.factor << ": "
                                                         << screen.outliers[0].slip.Describe();
      EXPECT_FALSE(screen.set_slip);
    }
  }
}

TEST(ReadingScreen, TheIssuesReadingIsMicrometresWrittenAsMillimetres) {
  std::mt19937_64 rng(1);
  Group g = PaperGroup(rng, -0.077);
  g.values[0] = -77.0;
  const ReadingScreen screen = ScreenReadings(g.values, g.sets, kTypical);
  ASSERT_EQ(screen.outliers.size(), 1u);
  EXPECT_EQ(screen.outliers[0].index, 0u);
  EXPECT_EQ(screen.outliers[0].slip.kind, SlipKind::kMicrometres);
  EXPECT_NEAR(screen.outliers[0].slip.fixed, -0.077, 1e-12);
}

TEST(ReadingScreen, AWholeSetInMicrometresIsBlamed) {
  std::mt19937_64 rng(2);
  for (long long slipped : {1, 2}) {
    Group g = PaperGroup(rng, 0.062);
    for (std::size_t k = 0; k < g.values.size(); ++k) {
      if (g.sets[k] == slipped) g.values[k] *= 1000;
    }
    const ReadingScreen screen = ScreenReadings(g.values, g.sets, kTypical);
    ASSERT_TRUE(screen.set_slip);
    EXPECT_TRUE(screen.set_slip->decided);
    EXPECT_EQ(screen.set_slip->set, slipped);
    EXPECT_EQ(screen.set_slip->slip.kind, SlipKind::kMicrometres);
    EXPECT_TRUE(screen.outliers.empty()) << "the slipped set is reported whole, not reading by reading";
  }
}

TEST(ReadingScreen, ASetWithAMovedDecimalPointNeedsTheSurroundingsOrAMajority) {
  std::mt19937_64 rng(3);
  Group g = PaperGroup(rng, -0.081);
  for (std::size_t k = 0; k < g.values.size(); ++k) {
    if (g.sets[k] == 2) g.values[k] *= 10;
  }
  // Alone, two sets a decimal point apart cannot tell which one slipped.
  ReadingScreen alone = ScreenReadings(g.values, g.sets, kTypical);
  ASSERT_TRUE(alone.set_slip);
  EXPECT_FALSE(alone.set_slip->decided);
  EXPECT_EQ(alone.set_slip->slip.kind, SlipKind::kDecimalPoint);
  // The neighbours say about -0.08: set 2 it is.
  ReadingScreen told = ScreenReadings(g.values, g.sets, kTypical, -0.079);
  ASSERT_TRUE(told.set_slip);
  EXPECT_TRUE(told.set_slip->decided);
  EXPECT_EQ(told.set_slip->set, 2);
  // Neighbours half-way between do not decide.
  ReadingScreen between = ScreenReadings(g.values, g.sets, kTypical, -0.45);
  ASSERT_TRUE(between.set_slip);
  EXPECT_FALSE(between.set_slip->decided);
  // Three sets: the majority decides.
  Group three = PaperGroup(rng, -0.081, 0, 3);
  for (std::size_t k = 0; k < three.values.size(); ++k) {
    if (three.sets[k] == 3) three.values[k] *= 0.1;
  }
  ReadingScreen majority = ScreenReadings(three.values, three.sets, kTypical);
  ASSERT_TRUE(majority.set_slip);
  EXPECT_TRUE(majority.set_slip->decided);
  EXPECT_EQ(majority.set_slip->set, 3);
}

TEST(ReadingScreen, ASlippedReadingInsideASlippedSetIsNotReportedTwice) {
  std::mt19937_64 rng(4);
  Group g = PaperGroup(rng, 0.05);
  for (std::size_t k = 0; k < g.values.size(); ++k) {
    if (g.sets[k] == 2) g.values[k] *= 1000;
  }
  g.values[3] = -g.values[3];  // and a lost sign in set 1
  const ReadingScreen screen = ScreenReadings(g.values, g.sets, kTypical);
  ASSERT_TRUE(screen.set_slip);
  EXPECT_EQ(screen.set_slip->set, 2);
  ASSERT_EQ(screen.outliers.size(), 1u);
  EXPECT_EQ(screen.outliers[0].index, 3u);
  EXPECT_EQ(screen.outliers[0].slip.kind, SlipKind::kSign);
}

TEST(ReadingScreen, TooFewReadingsPassUnjudged) {
  const ReadingScreen screen = ScreenReadings({0.01, 10.0}, {1, 1}, kTypical);
  EXPECT_TRUE(screen.outliers.empty());
  EXPECT_FALSE(screen.set_slip);
}

TEST(ReadingScreen, SingleReadingSetsAreJudgedAgainstTheGroup) {
  // A logger that numbers every reading as its own set.
  std::vector<double> values = {-0.050, -0.052, -0.051, -0.049, -5.1, -0.050};
  std::vector<long long> sets = {1, 2, 3, 4, 5, 6};
  const ReadingScreen screen = ScreenReadings(values, sets, kTypical);
  ASSERT_EQ(screen.outliers.size(), 1u);
  EXPECT_EQ(screen.outliers[0].index, 4u);
  EXPECT_EQ(screen.outliers[0].slip.kind, SlipKind::kDecimalPoint);
  EXPECT_FALSE(screen.set_slip);
}

}  // namespace
}  // namespace smtcal
