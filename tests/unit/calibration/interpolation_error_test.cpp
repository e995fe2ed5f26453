// Tests of the interpolation error between an error table's nodes
// (calibration/interpolation_error.h): exact figures on fields whose answer
// is known, and the properties the budget relies on, against an independent
// model (a random smooth field as the robot's truth, tables sampled from it
// with noise, the true departure computed densely): over random smooth
// fields at several pitches the estimate bounds the true departure (with its
// noise at the budget's 4 sigma) and stays within twice it; through the
// fixture's estimator the budget's part bounds the true pose error and is
// exact for the worst departures the tables allow. Seed: SMTCAL_TEST_SEED
// (printed).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/fixture_estimation.h"
#include "calibration/fixture_geometry.h"
#include "calibration/interpolation_error.h"
#include "calibration/placement_budget.h"
#include "tests/unit/calibration/fixture_test_cell.h"
#include "tests/unit/calibration/smooth_field_tables.h"

namespace smtcal {
namespace {

using test::Field;
using test::kReadingScatterMm;
using test::kReadings;
using test::Measure;
using test::Measurement;
using test::RandomField;

// The independent model's departure: per cell of an axis table's grid, the
// largest |f - bilinear(f at the true nodes)|, sampled at `per_cell` + 1
// points per cell and direction (the true nodes: the nodes' noise is the
// budget's `table` part, not this one). Written apart from the code under
// test: its own cell loop and its own bilinear weights.
std::vector<double> TrueCellDepartures(const Field& f, const std::vector<double>& xs, const std::vector<double>& ys,
                                       int per_cell = 16) {
  std::vector<double> cells;
  for (std::size_t j = 0; j + 1 < ys.size(); ++j) {
    for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
      const double f00 = f(xs[i], ys[j]), f10 = f(xs[i + 1], ys[j]);
      const double f01 = f(xs[i], ys[j + 1]), f11 = f(xs[i + 1], ys[j + 1]);
      double largest = 0;
      for (int a = 0; a <= per_cell; ++a) {
        for (int b = 0; b <= per_cell; ++b) {
          const double s = static_cast<double>(a) / per_cell, t = static_cast<double>(b) / per_cell;
          const double x = xs[i] + s * (xs[i + 1] - xs[i]), y = ys[j] + t * (ys[j + 1] - ys[j]);
          const double bilinear = (1 - t) * ((1 - s) * f00 + s * f10) + t * ((1 - s) * f01 + s * f11);
          largest = std::max(largest, std::abs(f(x, y) - bilinear));
        }
      }
      cells.push_back(largest);
    }
  }
  return cells;
}

// The largest over the whole table of a grid at `pitch` from (0, 0).
double TrueDeparture(const Field& f, double pitch, int nodes) {
  std::vector<double> lines;
  for (int k = 0; k < nodes; ++k) lines.push_back(pitch * k);
  const std::vector<double> cells = TrueCellDepartures(f, lines, lines);
  return *std::max_element(cells.begin(), cells.end());
}

TEST(InterpolationError, CurvatureIsExactForAQuadraticField) {
  // f = a x^2 + b y^2 + c x y: bilinear interpolation reproduces x y and
  // misses a x^2 by a h^2 s(1-s): h^2/8 |f''| per direction at the centre.
  const double a = 2e-5, b = -3e-5, c = 1e-5, pitch = 5;
  const Field f = [&](double x, double y) { return a * x * x + b * y * y + c * x * y; };
  const ErrorTable table = Measure(f, f, pitch, 11, nullptr, /*checks=*/false);
  const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0);
  const double expected = (std::abs(a) + std::abs(b)) * pitch * pitch / 4;
  for (const AxisInterpolation& axis : e.axes) {
    EXPECT_NEAR(axis.estimate_mm, expected, 1e-12);
    EXPECT_EQ(axis.kind, InterpolationKind::kCurvature);
    EXPECT_EQ(axis.cells, 100u);
    EXPECT_EQ(axis.checked_cells, 0u);
    EXPECT_FALSE(axis.declared_mm.has_value());
  }
  // Opposite signs: the centre sees |a + b|, the curvature still |a| + |b|,
  // which bounds the true departure (at the edges' midpoints).
  EXPECT_GE(e.axes[0].estimate_mm, TrueDeparture(f, pitch, 11) - 1e-12);
  EXPECT_NEAR(e.NormMm(), expected * std::numbers::sqrt2, 1e-12);
}

TEST(InterpolationError, ABilinearFieldHasNoCurvatureAndItsCheckPointsShowOnlyNoise) {
  const Field f = [](double x, double y) { return 0.01 + 1e-4 * x - 2e-4 * y + 3e-6 * x * y; };
  const ErrorTable table = Measure(f, f, 5, 6, nullptr);
  const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0);
  const double se = kReadingScatterMm / std::sqrt(static_cast<double>(kReadings));
  // The departure is nothing; the noise is a standard deviation apart from
  // it: at a centre the four nodes weigh 1/4 each, sigma = se sqrt(1 + 4/16).
  for (const AxisInterpolation& axis : e.axes) {
    EXPECT_NEAR(axis.curvature_mm, 0, 1e-12);
    EXPECT_EQ(axis.kind, InterpolationKind::kCheckPoints);
    EXPECT_NEAR(axis.estimate_mm, 0, 1e-12);
    EXPECT_NEAR(axis.noise_mm, kCheckPointMargin * se * std::sqrt(1.25), 1e-12);
    EXPECT_NEAR(*axis.reading_scatter_mm, kReadingScatterMm, 1e-15);
    EXPECT_EQ(axis.check_points, 25u);
    EXPECT_EQ(axis.checked_cells, 25u);
    EXPECT_NEAR(axis.largest_residual_mm, 0, 1e-15);
  }
  EXPECT_NEAR(e.NoiseMm(), kCheckPointMargin * se * std::sqrt(1.25), 1e-12);
}

// Two repetitions of a transducer that reads in whole micrometres: most
// points' two readings agree (stddev 0), a few differ by a step. Each
// point's own stddev says little; the table's pooled one is the set-up's.
TEST(InterpolationError, TheNoiseIsThePooledReadingScatter) {
  const Field zero = [](double, double) { return 0.0; };
  ErrorTable table = Measure(zero, zero, 10, 3, nullptr);
  for (AxisTable& t : table.axes) {
    for (std::size_t k = 0; k < t.error_mm.size(); ++k) {
      t.stddev_mm[k] = k % 3 == 0 ? std::sqrt(0.5) * 0.001 : 0.0;  // readings 0 and 1 µm, or two alike
      t.count[k] = 2;
    }
    for (TableNode& check : t.checks) {
      check.stddev_mm = 0.0;
      check.count = 2;
    }
  }
  // Nodes 0, 3, 6 of nine differ: pooled over 9 + 4 points of one degree of freedom each.
  const double pooled = std::sqrt(3 * 0.5e-6 / 13);
  const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0.005);
  const double se = pooled / std::sqrt(2.0);
  for (const AxisInterpolation& axis : e.axes) {
    EXPECT_NEAR(*axis.reading_scatter_mm, pooled, 1e-15);
    EXPECT_NEAR(axis.noise_mm, kCheckPointMargin * se * std::sqrt(1.25), 1e-15);
  }
  // A table that states no scatter: every point one reading of `unknown_noise_mm`.
  for (AxisTable& t : table.axes) {
    t.stddev_mm.clear();
    t.count.clear();
    for (TableNode& check : t.checks) {
      check.stddev_mm.reset();
      check.count = 0;
    }
  }
  const InterpolationEstimate unknown = EstimateInterpolationError(table, std::nullopt, 0.005);
  EXPECT_FALSE(unknown.axes[0].reading_scatter_mm.has_value());
  EXPECT_NEAR(unknown.axes[0].noise_mm, kCheckPointMargin * 0.005 * std::sqrt(1.25), 1e-15);
  EXPECT_NEAR(unknown.axes[0].estimate_mm, 0, 1e-15);
}

TEST(InterpolationError, ACheckPointSeesWhatTheNodesMiss) {
  // A bump that vanishes at every node: the nodes see nothing, the check
  // point in the middle cell sees it all.
  const double bump = 0.004, pitch = 5;
  const Field f = [&](double x, double y) {
    return bump * std::pow(std::sin(std::numbers::pi * x / pitch) * std::sin(std::numbers::pi * y / pitch), 2);
  };
  ErrorTable table = Measure(f, f, pitch, 4, nullptr);
  for (AxisTable& t : table.axes) {
    for (TableNode& check : t.checks) {
      check.stddev_mm.reset();  // one reading of the pooled scatter
      check.count = 0;
    }
  }
  const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0);
  const double se = kReadingScatterMm / std::sqrt(static_cast<double>(kReadings));
  for (const AxisInterpolation& axis : e.axes) {
    EXPECT_NEAR(axis.curvature_mm, 0, 1e-15);
    EXPECT_EQ(axis.kind, InterpolationKind::kCheckPoints);
    EXPECT_NEAR(axis.estimate_mm, kCheckPointMargin * bump, 1e-12);
    EXPECT_NEAR(axis.noise_mm, kCheckPointMargin * std::hypot(kReadingScatterMm, se / 2), 1e-12);
    EXPECT_NEAR(axis.largest_residual_mm, bump, 1e-15);
  }
  EXPECT_GE(e.axes[0].estimate_mm, TrueDeparture(f, pitch, 4));
}

// At a cell's centre a check point tells A + B of the quadratic model
// d = A 4s(1-s) + B 4t(1-t); the curvature tells |A| and |B| at most. A
// saddle (A = -B) shows nothing at the centre and all of A at the edges'
// midpoints: the figure is max(|r|, min(c_x, |r| + c_y), min(c_y, |r| +
// c_x)), not c_x + c_y.
TEST(InterpolationError, ACentreCheckPointSharpensTheCurvatureOfASaddle) {
  const double a = 2e-5, pitch = 5;
  const Field saddle = [&](double x, double y) { return a * x * x - a * y * y; };
  const Field bowl = [&](double x, double y) { return a * x * x + a * y * y; };
  const double half = a * pitch * pitch / 4;  // |A| = |B| = c_x = c_y: h^2/8 |f''|
  const InterpolationEstimate s = EstimateInterpolationError(Measure(saddle, saddle, pitch, 7, nullptr), std::nullopt, 0);
  const InterpolationEstimate b = EstimateInterpolationError(Measure(bowl, bowl, pitch, 7, nullptr), std::nullopt, 0);
  EXPECT_NEAR(s.axes[0].curvature_mm, 2 * half, 1e-15);
  EXPECT_NEAR(s.axes[0].largest_residual_mm, 0, 1e-15);
  EXPECT_NEAR(s.axes[0].estimate_mm, kCheckPointMargin * half, 1e-15);
  EXPECT_NEAR(TrueDeparture(saddle, pitch, 7), half, 1e-12);
  EXPECT_NEAR(b.axes[0].estimate_mm, kCheckPointMargin * 2 * half, 1e-15);
  EXPECT_NEAR(TrueDeparture(bowl, pitch, 7), 2 * half, 1e-12);
}

TEST(InterpolationError, AnOffCentreCheckPointIsScaledToItsCellCentre) {
  const AxisTable t = [] {
    AxisTable table;
    table.xs = {0, 10};
    table.ys = {0, 10};
    table.error_mm = {0, 0, 0, 0};
    return table;
  }();
  EXPECT_DOUBLE_EQ(PlaceInCell(t, 5, 5).CentreShare(), 1.0);
  EXPECT_DOUBLE_EQ(PlaceInCell(t, 5, 0).CentreShare(), 0.5);
  EXPECT_DOUBLE_EQ(PlaceInCell(t, 0, 0).CentreShare(), 0.0);
  EXPECT_DOUBLE_EQ(PlaceInCell(t, 2.5, 2.5).CentreShare(), 0.75);
  ErrorTable table;
  table.axes = {t, t};
  TableNode check;
  check.kind = ReadingKind::kCheck;
  check.x_mm = 2.5;
  check.y_mm = 2.5;
  check.error_mm = 0.003;
  table[TableAxis::X].checks.push_back(check);
  const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0);
  // Off the centre the check point says p A + q B = r (p = q = 0.75 here),
  // not A + B: its figure is |r| / phi (phi = (p + q) / 2), no sharper.
  EXPECT_NEAR(e.axes[0].estimate_mm, kCheckPointMargin * 0.003 / 0.75, 1e-15);
  EXPECT_NEAR(e.axes[0].noise_mm, 0, 1e-15);  // the table states no noise, and none is assumed
  EXPECT_NEAR(e.axes[1].estimate_mm, 0, 1e-15);
}

TEST(InterpolationError, TheDeclaredRoughnessIsTheWaveTheNodesCouldHide) {
  // The robot declares 0.25 mm over 25 mm: waves down to 75 mm. On a line of
  // three nodes a wave can sit with its zero crossing at the middle node and
  // show nothing: the whole amplitude, A (1 - cos(pi h / 75)) mid-cell,
  // where no check point says otherwise.
  const Field zero = [](double, double) { return 0.0; };
  const DeclaredRoughness roughness{0.25, 25};
  ErrorTable coarse = Measure(zero, zero, 25, 3, nullptr);
  coarse[TableAxis::X].checks.clear();  // the y table keeps its check points
  const InterpolationEstimate e = EstimateInterpolationError(coarse, roughness, 0);
  const double declared = 0.25 * (1 - std::cos(std::numbers::pi / 3));
  EXPECT_EQ(e.axes[0].kind, InterpolationKind::kDeclared);
  EXPECT_NEAR(e.axes[0].estimate_mm, declared, 1e-15);
  EXPECT_NEAR(declared, 0.125, 1e-15);
  EXPECT_EQ(e.axes[1].kind, InterpolationKind::kCheckPoints);
  // Its check points see nothing but their noise (and the interpolated
  // nodes'), kept apart: sigma = se sqrt(1 + 4/16) times the margin, 0.8 µm.
  const double se = kReadingScatterMm / std::sqrt(static_cast<double>(kReadings));
  EXPECT_NEAR(e.axes[1].estimate_mm, 0, 1e-15);
  EXPECT_NEAR(e.axes[1].noise_mm, kCheckPointMargin * se * std::sqrt(1.25), 1e-12);
  EXPECT_FALSE(e.axes[1].declared_mm.has_value());
  const ErrorTable small = Measure(zero, zero, 5, 3, nullptr, false);
  EXPECT_NEAR(EstimateInterpolationError(small, roughness, 0).axes[0].estimate_mm,
              0.25 * (1 - std::cos(std::numbers::pi / 15)), 1e-15);  // 5.5 µm
  // Eleven nodes at 5 mm sample more than half a period of a 75 mm wave on
  // every line: a flat table rules the wave out, ...
  const ErrorTable flat = Measure(zero, zero, 5, 11, nullptr, false);
  const InterpolationEstimate none = EstimateInterpolationError(flat, roughness, 0);
  EXPECT_EQ(*none.axes[0].declared_mm, 0.0);
  EXPECT_EQ(none.axes[0].estimate_mm, 0.0);
  // ... and a table that shows such a wave bounds what it can hide.
  for (double direction : {0.0, 0.4, std::numbers::pi / 4, 1.2}) {
    const double kx = 2 * std::numbers::pi / 75 * std::cos(direction), ky = 2 * std::numbers::pi / 75 * std::sin(direction);
    const Field wave = [&](double x, double y) { return 0.1 * std::cos(kx * x + ky * y + 0.3); };
    const ErrorTable measured = Measure(wave, wave, 5, 11, nullptr, false);
    const InterpolationEstimate w = EstimateInterpolationError(measured, roughness, 0);
    EXPECT_GE(w.axes[0].estimate_mm, TrueDeparture(wave, 5, 11)) << "direction " << direction;
    EXPECT_LT(*w.axes[0].declared_mm, 0.25 * (1 - std::cos(std::numbers::pi / 15))) << "direction " << direction;
  }
  // At the pitch of the wavelength a wave can take the whole range.
  const ErrorTable widest = Measure(zero, zero, 75, 3, nullptr, false);
  EXPECT_NEAR(EstimateInterpolationError(widest, roughness, 0).axes[0].estimate_mm, 0.5, 1e-15);
}

TEST(InterpolationError, GridAdviceScalesWithThePitchSquared) {
  const Field zero = [](double, double) { return 0.0; };
  const ErrorTable table = Measure(zero, zero, 25, 3, nullptr, false);
  const InterpolationEstimate e = EstimateInterpolationError(table, DeclaredRoughness{0.25, 25}, 0);
  const GridAdvice advice = AdviseGrid(e, 0.1);
  EXPECT_TRUE(advice.coarse);
  EXPECT_NEAR(advice.share, e.NormMm() / 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(advice.pitch_mm, std::floor(10 * 25 * std::sqrt(0.01 / e.NormMm())) / 10);
  EXPECT_TRUE(advice.check_points_would_settle);  // the nodes themselves show nothing
  const ErrorTable fine = Measure(zero, zero, 5, 11, nullptr, false);
  EXPECT_FALSE(AdviseGrid(EstimateInterpolationError(fine, DeclaredRoughness{0.25, 25}, 0), 0.1).coarse);
  EXPECT_DOUBLE_EQ(PitchForShare(20, 0.04, 0.01), 10.0);
  EXPECT_DOUBLE_EQ(PitchForShare(20, 0.004, 0.01), 20.0);
  EXPECT_DOUBLE_EQ(PitchForShare(20, 0.04, -0.01), 0.0);
}

// Before the first measurement (measure plan's default pitch): the planned
// estimate is what EstimateInterpolationError gives a flat 3 x 3 table at
// that pitch (its nodes rule nothing out, as unmeasured ones do), and the
// planned pitch is the largest 0.1 mm step within the share of the
// tolerance. The example's robot: 0.25 mm over 25 mm, +-0.1 mm: 5.6 mm
// (0.0077 mm at 5 mm, the paper's pitch).
TEST(InterpolationError, ThePlannedPitchIsTheDeclaredEstimatesGridAdvice) {
  const Field zero = [](double, double) { return 0.0; };
  const DeclaredRoughness example{0.25, 25};
  EXPECT_DOUBLE_EQ(PlannedPitchMm(example, 0.1), 5.6);
  EXPECT_NEAR(PlannedInterpolationMm(example, 5), 0.0077, 5e-5);
  std::mt19937_64 rng(test::FixtureSeed());
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", test::FixtureSeed()));
  for (int trial = 0; trial < 200; ++trial) {
    const DeclaredRoughness r{test::Uniform(rng, 0.01, 0.5), test::Uniform(rng, 5, 100)};
    const double tolerance = test::Uniform(rng, 0.02, 0.2);
    const double pitch = PlannedPitchMm(r, tolerance);
    const double allowed = kInterpolationShareOfTolerance * tolerance;
    if (std::isinf(pitch)) {
      // No wave of the declared range departs more than the share.
      EXPECT_LE(2 * std::numbers::sqrt2 * r.accuracy_mm, allowed * (1 + 1e-12));
      continue;
    }
    EXPECT_LE(PlannedInterpolationMm(r, pitch), allowed * (1 + 1e-12)) << trial;
    EXPECT_GT(PlannedInterpolationMm(r, pitch + 0.1), allowed) << trial;
    const ErrorTable flat = Measure(zero, zero, pitch, 3, nullptr, false);
    EXPECT_NEAR(EstimateInterpolationError(flat, r, 0).NormMm(), PlannedInterpolationMm(r, pitch), 1e-15) << trial;
  }
  // Declared smoother than the share: any pitch.
  EXPECT_TRUE(std::isinf(PlannedPitchMm(DeclaredRoughness{0.001, 25}, 0.1)));
}

// The property: random smooth fields whose shortest wavelength is 2.5 to 8
// pitches, at 2, 5, 10 and 25 mm pitch, large (0.25 mm) and small (5 µm)
// amplitudes, measured as the paper did (20 readings of 2.5 µm) and with two
// repetitions; check points at every cell centre. Against the independent
// model's true departure, per axis table:
//   - the bound plus its noise at the budget's 4 sigma is never below the
//     truth, in the whole table and in every cell (a fixture's trips use the
//     cells' own figures);
//   - the bound is within twice the truth, or within twice the noise's 4
//     sigma when the truth is smaller than that (no measurement can tell a
//     departure from its own noise).
TEST(InterpolationErrorProperty, CheckPointsBoundTheTrueDepartureWithinTwice) {
  const std::uint64_t seed = test::FixtureSeed();
  std::printf("interpolation property seed: %llu (set SMTCAL_TEST_SEED to vary it)\n",
              static_cast<unsigned long long>(seed));
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  struct Grid {
    double pitch;
    int nodes;
  };
  int fields = 0;
  double worst_cover = 0, worst_cell_cover = 0, worst_sharp = 0, worst_sharp_share = 0;
  double bucket_worst[3] = {0, 0, 0};
  for (const Grid grid : {Grid{2, 11}, Grid{5, 11}, Grid{10, 6}, Grid{25, 3}}) {
    for (double amplitude : {0.25, 0.005}) {
      for (int readings : {20, 2}) {
        for (int trial = 0; trial < 12; ++trial) {
          const double shortest = test::Uniform(rng, 2.5, 8) * grid.pitch;
          const Field fx = RandomField(rng, shortest, amplitude);
          const Field fy = RandomField(rng, shortest, amplitude);
          const ErrorTable table =
              Measure(fx, fy, grid.pitch, grid.nodes, &rng, true, Measurement{readings, kReadingScatterMm});
          const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0);
          for (TableAxis axis : kTableAxes) {
            const AxisInterpolation& a = e[axis];
            const std::vector<double> truth_cells =
                TrueCellDepartures(axis == TableAxis::X ? fx : fy, table[axis].xs, table[axis].ys);
            const double truth = *std::max_element(truth_cells.begin(), truth_cells.end());
            const std::string what = fmt::format("pitch {} mm, shortest wavelength {:.1f} mm, amplitude {} mm, {} "
                                                 "readings, trial {}, axis {}: truth {:.6f}, bound {:.6f}, noise {:.6f}",
                                                 grid.pitch, shortest, amplitude, readings, trial, AxisName(axis),
                                                 truth, a.estimate_mm, a.noise_mm);
            EXPECT_EQ(a.kind, InterpolationKind::kCheckPoints) << what;
            const double covered = a.estimate_mm + kBudgetSigmas * a.noise_mm;
            EXPECT_LE(truth, covered) << what;
            worst_cover = std::max(worst_cover, truth / covered);
            const std::vector<double>& xs = table[axis].xs;
            const std::vector<double>& ys = table[axis].ys;
            for (std::size_t c = 0; c < truth_cells.size(); ++c) {
              // What a trip in the cell's middle looks up.
              const std::size_t i = c % (xs.size() - 1), j = c / (xs.size() - 1);
              const double xm = 0.5 * (xs[i] + xs[i + 1]), ym = 0.5 * (ys[j] + ys[j + 1]);
              const LocalInterpolation local = a.Over(Rect{xm, xm, ym, ym});
              const double cell = local.bound_mm + kBudgetSigmas * local.noise_mm;
              worst_cell_cover = std::max(worst_cell_cover, truth_cells[c] / cell);
              const int bucket = shortest / grid.pitch < 3 ? 0 : shortest / grid.pitch < 4 ? 1 : 2;
              bucket_worst[bucket] = std::max(bucket_worst[bucket], truth_cells[c] / cell);
            }
            const double floor = std::max(truth, kBudgetSigmas * a.noise_mm);
            EXPECT_LE(a.estimate_mm, 2 * floor) << what;
            worst_sharp = std::max(worst_sharp, a.estimate_mm / floor);
            if (truth > kBudgetSigmas * a.noise_mm) worst_sharp_share = std::max(worst_sharp_share, a.estimate_mm / truth);
          }
          ++fields;
        }
      }
    }
  }
  RecordProperty("worst_truth_over_covered", fmt::format("{:.3f}", worst_cover));
  RecordProperty("worst_bound_over_truth", fmt::format("{:.3f}", worst_sharp));
  std::printf("largest true departure / (bound + 4 sigma): table %.3f, cell %.3f; largest bound / max(truth, 4 "
              "sigma): %.3f; bound / truth where the truth is above 4 sigma: at most %.3f\n",
              worst_cover, worst_cell_cover, worst_sharp, worst_sharp_share);
  std::printf("cells by shortest wavelength / pitch: <3 %.3f, <4 %.3f, >=4 %.3f\n", bucket_worst[0], bucket_worst[1], bucket_worst[2]);
  EXPECT_EQ(fields, 192);
}

// Without check points the curvature figure is a lower bound: a field that
// the grid aliases (a wave of exactly two pitches, zero at every node) is
// invisible to it, and only the declared roughness or check points show it.
TEST(InterpolationError, CurvatureCannotSeeWhatTheGridAliases) {
  const double pitch = 10;
  const Field alias = [&](double x, double y) { return 0.02 * std::sin(std::numbers::pi * x / pitch) * std::cos(y / 100); };
  const ErrorTable table = Measure(alias, alias, pitch, 6, nullptr, false);
  const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0);
  EXPECT_LT(e.axes[0].estimate_mm, 1e-12);
  EXPECT_GT(TrueDeparture(alias, pitch, 6), 0.019);
  const ErrorTable checked = Measure(alias, alias, pitch, 6, nullptr, true);
  EXPECT_GE(EstimateInterpolationError(checked, std::nullopt, 0).axes[0].estimate_mm, TrueDeparture(alias, pitch, 6));
}

// An estimate whose every cell has this bound and noise (a table's grid).
InterpolationEstimate UniformEstimate(const ErrorTable& table, double bound, double noise) {
  InterpolationEstimate e;
  for (TableAxis axis : kTableAxes) {
    AxisInterpolation& a = e.axes[static_cast<int>(axis)];
    a.xs = table[axis].xs;
    a.ys = table[axis].ys;
    const std::size_t cells = (a.xs.size() - 1) * (a.ys.size() - 1);
    a.cell_bound_mm.assign(cells, bound);
    a.cell_noise_mm.assign(cells, noise);
    a.estimate_mm = bound;
    a.noise_mm = noise;
  }
  return e;
}

TEST(InterpolationBudget, WorstCaseSumIsTheLargestSignedSum) {
  EXPECT_DOUBLE_EQ(WorstCaseSumMm({}), 0.0);
  EXPECT_NEAR(WorstCaseSumMm({{3, 4}}), 5, 1e-12);
  EXPECT_NEAR(WorstCaseSumMm({{3, 0}, {0, 4}}), 5, 1e-12);     // perpendicular: the diagonal
  EXPECT_NEAR(WorstCaseSumMm({{3, 0}, {-2, 0}}), 5, 1e-12);    // parallel: they add
  EXPECT_NEAR(WorstCaseSumMm({{1, 1}, {1, -1}, {0, 0}}), 2, 1e-12);
  std::mt19937_64 rng(test::FixtureSeed());
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Eigen::Vector2d> terms;
    const int count = 1 + trial % 9;
    for (int k = 0; k < count; ++k) terms.emplace_back(test::Uniform(rng, -1, 1), test::Uniform(rng, -1, 1));
    double brute = 0;
    for (unsigned signs = 0; signs < (1u << count); ++signs) {
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      for (int k = 0; k < count; ++k) sum += (signs >> k & 1u) != 0 ? terms[static_cast<std::size_t>(k)] : -terms[static_cast<std::size_t>(k)];
      brute = std::max(brute, sum.norm());
    }
    EXPECT_NEAR(WorstCaseSumMm(terms), brute, 1e-12) << "trial " << trial;
  }
}

// The budget: a static target's `interpolation` part is its region's bound
// |(E_x, E_y)| plus the check points' noise as a random part; a fixture
// target's adds, per trip, its table's bound across the trip's edge through
// the estimator, all combined as the exact worst case of the linear map.
TEST(InterpolationBudget, IsABoundAtTheTargetAndThroughTheTrips) {
  std::mt19937_64 rng(test::FixtureSeed());
  cell::Cell cell;
  cell.robot.repeatability_mm = 0.005;
  cell.regions.push_back(test::RegionOf("layers", test::RandomSmoothTable(rng, 148, 58, 165, 55, 12, 0.15)));
  cell.regions.push_back(test::RegionOf("marker1", test::RandomSmoothTable(rng, 127.5, 31, 25, 25, 6, 0.15)));
  cell.regions.push_back(test::RegionOf("marker2", test::RandomSmoothTable(rng, 313.5, 114, 25, 25, 6, 0.15)));
  cell.fixtures.push_back(test::PaperFixture(cell::Estimator::kRigid));
  const double own = 0.003, trip = 0.002, noise = 0.0005;
  cell.regions[0].interpolation = UniformEstimate(cell.regions[0].table, own, noise);
  for (std::size_t r : {1u, 2u}) cell.regions[r].interpolation = UniformEstimate(cell.regions[r].table, trip, 0);
  const ErrorBudget fixed = StaticBudget(cell, &cell.regions[0], 0);
  const ErrorShare& part = fixed[ErrorSource::kInterpolation];
  EXPECT_DOUBLE_EQ(part.bound_mm, own * std::numbers::sqrt2);
  EXPECT_NEAR(part.SigmaMm(), noise, 1e-15);
  EXPECT_NEAR(part.BudgetMm(), own * std::numbers::sqrt2 + kBudgetSigmas * noise, 1e-15);

  const Eigen::Vector2d point(120, 45);
  const FixtureErrorModel model(cell, cell.fixtures.front());
  const ErrorBudget board = model.At(point, &cell.regions[0], 0);
  // The marker edges are axis-parallel: every trip's bound across its edge
  // is `trip`; through the estimator g_k.
  const std::vector<Eigen::Vector2d> gains = model.TripGains(point);
  std::vector<Eigen::Vector2d> terms = {{own, 0}, {0, own}};
  double each_at_worst = own * std::numbers::sqrt2;
  for (std::size_t k = 0; k < gains.size(); ++k) {
    EXPECT_NEAR(model.trip_interpolation()[k].bound_mm, trip, 1e-15);
    terms.push_back(trip * gains[k]);
    each_at_worst += trip * gains[k].norm();
  }
  const ErrorShare& joint = board[ErrorSource::kInterpolation];
  EXPECT_NEAR(joint.bound_mm, WorstCaseSumMm(terms), 1e-15);
  EXPECT_LE(joint.bound_mm, each_at_worst + 1e-15);
  EXPECT_GT(joint.bound_mm, own * std::numbers::sqrt2 + trip);
  // The same cell without tables under the markers, the robot off by `trip`
  // there: each trip at its worst, all the same way (no table bounds them).
  cell::Cell bare = cell;
  bare.regions.resize(1);
  bare.robot.uncalibrated_accuracy_mm = trip;
  const ErrorBudget outside = FixtureErrorModel(bare, bare.fixtures.front()).At(point, &bare.regions[0], 0);
  EXPECT_NEAR(outside[ErrorSource::kUncalibratedTrips].bound_mm + own * std::numbers::sqrt2, each_at_worst, 1e-12);
  // The trips' part alone, for reports that give it apart.
  EXPECT_NEAR(model.Interpolation(point, nullptr).bound_mm, WorstCaseSumMm({terms.begin() + 2, terms.end()}), 1e-15);
  ErrorBudget without = board;
  without[ErrorSource::kInterpolation] = ErrorShare{};
  without[ErrorSource::kInterpolation].covariance_mm2 = joint.covariance_mm2;
  EXPECT_NEAR(board.BudgetMm() - joint.bound_mm, without.BudgetMm(), 1e-12);
}

// A field's departure from the bilinear interpolation of its true values at
// an axis table's nodes, at a point inside the grid (the independent model's
// own lookup).
double DepartureAt(const Field& f, const AxisTable& t, const Eigen::Vector2d& p) {
  auto cell = [](const std::vector<double>& lines, double v) {
    std::size_t i = 0;
    while (i + 2 < lines.size() && v > lines[i + 1]) ++i;
    return i;
  };
  const std::size_t i = cell(t.xs, p.x()), j = cell(t.ys, p.y());
  const double s = (p.x() - t.xs[i]) / (t.xs[i + 1] - t.xs[i]), u = (p.y() - t.ys[j]) / (t.ys[j + 1] - t.ys[j]);
  const double bilinear = (1 - u) * ((1 - s) * f(t.xs[i], t.ys[j]) + s * f(t.xs[i + 1], t.ys[j])) +
                          u * ((1 - s) * f(t.xs[i], t.ys[j + 1]) + s * f(t.xs[i + 1], t.ys[j + 1]));
  return f(p.x(), p.y()) - bilinear;
}

// Through the trips, against the estimator itself: the marker tables
// measured at 5 and 10 mm with check points from random smooth fields (the
// example's marker regions), the board anywhere its limits allow, the
// trips moved by the true departure of the robot from the tables there,
// and the pose the fixture's estimator (rigid, rigid with scale, the
// paper's Eq. 4) makes of them: the displacement of every point of the
// layers never exceeds the budget's part through the trips (bound and
// noise at 4 sigma), and that bound is exact: moving each trip by its bound
// with the worst signs, the estimator moves the point by it (to 1 %).
TEST(InterpolationBudgetProperty, ThroughTheTripsBoundsTheEstimatorsTruePoseError) {
  const std::uint64_t seed = test::FixtureSeed();
  std::printf("through-the-trips property seed: %llu (set SMTCAL_TEST_SEED to vary it)\n",
              static_cast<unsigned long long>(seed));
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  double worst_cover = 0, worst_exact = 0;
  std::vector<double> ratios;
  for (cell::Estimator estimator : {cell::Estimator::kRigid, cell::Estimator::kRigidScale, cell::Estimator::kPaper}) {
    for (double pitch : {5.0, 10.0}) {
      for (int trial = 0; trial < 8; ++trial) {
        cell::Cell cell;
        cell.robot.repeatability_mm = 0.005;
        cell.fixtures.push_back(test::HairpinFixture(estimator));
        const cell::Fixture& fixture = cell.fixtures.front();
        std::array<Field, 4> fields;  // marker1 x, y, marker2 x, y
        for (Field& f : fields) f = RandomField(rng, test::Uniform(rng, 2.5, 8) * pitch, 0.15);
        const int nodes = static_cast<int>(std::round(30 / pitch)) + 1;
        const std::array<Eigen::Vector2d, 2> origins = {Eigen::Vector2d(124, 28), Eigen::Vector2d(311, 111)};
        for (int m = 0; m < 2; ++m) {
          const ErrorTable table = Measure(fields[2 * m], fields[2 * m + 1], pitch, nodes, &rng, true,
                                           Measurement{2, kReadingScatterMm}, origins[static_cast<std::size_t>(m)]);
          cell.regions.push_back(test::RegionOf(m == 0 ? "marker1" : "marker2", table));
          cell.regions.back().interpolation = EstimateInterpolationError(table, std::nullopt, 0);
        }
        const FixtureErrorModel model(cell, fixture);
        ASSERT_TRUE(model.defined());
        ASSERT_TRUE(model.UncalibratedTrips().empty());
        const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
        std::vector<Eigen::Vector2d> targets;
        for (double x : {12.0, 37.0, 62.0, 122.0, 172.0}) {
          for (double y : {20.0, 45.0, 70.0}) targets.emplace_back(x, y);
        }
        // Where the trips fall for a board at `pose`, each moved by `move`.
        auto estimate = [&](const std::vector<Eigen::Vector2d>& trips) {
          const std::optional<FixEstimate> fix = EstimateFix(fixture, expected, trips, estimator);
          EXPECT_TRUE(fix.has_value());
          return fix ? fix->fix : NominalFix(fixture);
        };
        for (int pose = 0; pose < 4; ++pose) {
          const double angle = test::Uniform(rng, 0, 2 * std::numbers::pi), shift = pose == 0 ? 0 : test::Uniform(rng, 0, 2);
          const Eigen::Affine3d board =
              PlanarFix(fixture.origin_mm + shift * Eigen::Vector2d(std::cos(angle), std::sin(angle)),
                        (pose == 0 ? 0 : test::Uniform(rng, -0.5, 0.5)) * kRadPerDeg);
          const std::vector<Eigen::Vector2d> trips = test::SimulateTrips(fixture, board);
          std::vector<Eigen::Vector2d> moved = trips;
          for (std::size_t k = 0; k < trips.size(); ++k) {
            const int r = model.trip_regions()[k];
            ASSERT_GE(r, 0);
            const ErrorTable& t = cell.regions[static_cast<std::size_t>(r)].table;
            moved[k] += Eigen::Vector2d(DepartureAt(fields[2 * static_cast<std::size_t>(r)], t[TableAxis::X], trips[k]),
                                        DepartureAt(fields[2 * static_cast<std::size_t>(r) + 1], t[TableAxis::Y], trips[k]));
          }
          const Eigen::Affine3d clean = estimate(trips), off = estimate(moved);
          for (const Eigen::Vector2d& f : targets) {
            const double truth = (ToBase(off, f) - ToBase(clean, f)).norm();
            const ErrorShare part = model.Interpolation(f, nullptr);
            const double covered = part.bound_mm + kBudgetSigmas * part.SigmaMm();
            EXPECT_LE(truth, covered) << fmt::format("{} estimator, pitch {} mm, trial {}, pose {}, point ({}, {})",
                                                     EstimatorName(estimator), pitch, trial, pose, f.x(), f.y());
            worst_cover = std::max(worst_cover, truth / covered);
            ratios.push_back(truth / part.bound_mm);
          }
        }
        // Exact: the worst signs, each trip moved by its bound across its edge.
        const Eigen::Affine3d nominal = NominalFix(fixture);
        const std::vector<Eigen::Vector2d> trips = test::SimulateTrips(fixture, nominal);
        for (const Eigen::Vector2d& f : targets) {
          const std::vector<Eigen::Vector2d> gains = model.TripGains(f);
          Eigen::Vector2d best_sum = Eigen::Vector2d::Zero();
          unsigned best = 0;
          for (unsigned signs = 0; signs < (1u << gains.size()); ++signs) {
            Eigen::Vector2d sum = Eigen::Vector2d::Zero();
            for (std::size_t k = 0; k < gains.size(); ++k) {
              sum += ((signs >> k & 1u) != 0 ? 1.0 : -1.0) * model.trip_interpolation()[k].bound_mm * gains[k];
            }
            if (sum.norm() > best_sum.norm()) best_sum = sum, best = signs;
          }
          // Scaled to a micrometre at the largest, where the estimator is
          // linear (the figures of a rough field on a paper estimator reach
          // millimetres, where it is not).
          double largest = 0;
          for (const LocalInterpolation& t : model.trip_interpolation()) largest = std::max(largest, t.bound_mm);
          const double scale = 0.001 / largest;
          std::vector<Eigen::Vector2d> moved = trips;
          for (std::size_t k = 0; k < trips.size(); ++k) {
            const Eigen::Vector2d normal =
                nominal.linear().topLeftCorner<2, 2>() * EdgeLineOf(fixture.edges[static_cast<std::size_t>(expected[k].edge)]).normal;
            moved[k] += ((best >> k & 1u) != 0 ? 1.0 : -1.0) * scale * model.trip_interpolation()[k].bound_mm * normal;
          }
          const double attained = (ToBase(estimate(moved), f) - ToBase(estimate(trips), f)).norm() / scale;
          const double bound = model.Interpolation(f, nullptr).bound_mm;
          EXPECT_NEAR(attained, bound, 0.01 * bound) << EstimatorName(estimator) << " point " << f.transpose();
          worst_exact = std::max(worst_exact, std::abs(attained / bound - 1));
        }
      }
    }
  }
  std::sort(ratios.begin(), ratios.end());
  std::printf("through the trips: largest true pose error / (bound + 4 sigma) %.3f; true / bound: median %.3f, "
              "90th percentile %.3f, largest %.3f; the worst signs attain the bound to %.2e\n",
              worst_cover, ratios[ratios.size() / 2], ratios[ratios.size() * 9 / 10], ratios.back(), worst_exact);
}

}  // namespace
}  // namespace smtcal
