// Tests of the interpolation error between an error table's nodes
// (calibration/interpolation_error.h): exact figures on fields whose answer
// is known, and the property the budget relies on: over random smooth fields
// at several pitches, the estimate from check points at the cell centres
// bounds the true departure of the field from the bilinear interpolation of
// its nodes, at 4 sigma of the measurement noise. Seed: SMTCAL_TEST_SEED
// (printed on failure).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/interpolation_error.h"
#include "calibration/placement_budget.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

using Field = std::function<double(double, double)>;

// The paper's measurement: 20 readings of 2.5 µm scatter per node.
constexpr double kReadingScatterMm = 0.0025;
constexpr int kReadings = 20;

// A table of `nodes` x `nodes` at `pitch` from (0, 0) whose Delta-x and
// Delta-y nodes are the field plus a normal draw of the mean's standard
// error (none when rng is null), with a check point at every cell centre
// measured the same way.
ErrorTable Measure(const Field& fx, const Field& fy, double pitch, int nodes, std::mt19937_64* rng,
                   bool checks = true) {
  const double se = kReadingScatterMm / std::sqrt(static_cast<double>(kReadings));
  std::normal_distribution<double> normal(0, se);
  auto noise = [&] { return rng != nullptr ? normal(*rng) : 0.0; };
  ErrorTable table;
  table.name = "measured";
  for (TableAxis axis : kTableAxes) {
    const Field& f = axis == TableAxis::X ? fx : fy;
    AxisTable& t = table[axis];
    for (int i = 0; i < nodes; ++i) t.xs.push_back(pitch * i);
    for (int j = 0; j < nodes; ++j) t.ys.push_back(pitch * j);
    for (int j = 0; j < nodes; ++j) {
      for (int i = 0; i < nodes; ++i) {
        t.error_mm.push_back(f(t.xs[static_cast<std::size_t>(i)], t.ys[static_cast<std::size_t>(j)]) + noise());
        t.stddev_mm.push_back(kReadingScatterMm);
        t.count.push_back(kReadings);
      }
    }
    if (!checks) continue;
    for (int j = 0; j + 1 < nodes; ++j) {
      for (int i = 0; i + 1 < nodes; ++i) {
        TableNode check;
        check.kind = ReadingKind::kCheck;
        check.axis = axis;
        check.x_mm = pitch * (i + 0.5);
        check.y_mm = pitch * (j + 0.5);
        check.error_mm = f(check.x_mm, check.y_mm) + noise();
        check.stddev_mm = kReadingScatterMm;
        check.count = kReadings;
        t.checks.push_back(check);
      }
    }
  }
  return table;
}

// The largest |f - bilinear(f at the nodes)| over the table, sampled at 16
// points per cell and direction (the true nodes: the noise is the budget's
// `table` part, not this one).
double TrueDeparture(const Field& f, double pitch, int nodes) {
  const int per_cell = 16;
  double largest = 0;
  for (int a = 0; a <= per_cell * (nodes - 1); ++a) {
    for (int b = 0; b <= per_cell * (nodes - 1); ++b) {
      const double x = pitch * a / per_cell, y = pitch * b / per_cell;
      const int i = std::min(a / per_cell, nodes - 2), j = std::min(b / per_cell, nodes - 2);
      const double s = x / pitch - i, t = y / pitch - j;
      const double x0 = pitch * i, x1 = pitch * (i + 1), y0 = pitch * j, y1 = pitch * (j + 1);
      const double bilinear = (1 - t) * ((1 - s) * f(x0, y0) + s * f(x1, y0)) + t * ((1 - s) * f(x0, y1) + s * f(x1, y1));
      largest = std::max(largest, std::abs(f(x, y) - bilinear));
    }
  }
  return largest;
}

// A smooth random field: six plane waves of wavelengths from `shortest` to
// 3 x `shortest`, random directions, phases and weights, scaled so that the
// weights sum to `amplitude`.
Field RandomField(std::mt19937_64& rng, double shortest, double amplitude) {
  struct Wave {
    double kx, ky, phase, weight;
  };
  std::vector<Wave> waves;
  double total = 0;
  for (int m = 0; m < 6; ++m) {
    const double k = 2 * std::numbers::pi / test::Uniform(rng, shortest, 3 * shortest);
    const double direction = test::Uniform(rng, 0, 2 * std::numbers::pi);
    waves.push_back({k * std::cos(direction), k * std::sin(direction), test::Uniform(rng, 0, 2 * std::numbers::pi),
                     test::Uniform(rng, 0.5, 1)});
    total += waves.back().weight;
  }
  return [waves, scale = amplitude / total](double x, double y) {
    double sum = 0;
    for (const Wave& w : waves) sum += w.weight * std::cos(w.kx * x + w.ky * y + w.phase);
    return scale * sum;
  };
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
  // At a centre the four nodes weigh 1/4 each: sigma = se sqrt(1 + 4/16).
  const double noise = kCheckPointMargin * kCheckPointSigmas * se * std::sqrt(1.25);
  for (const AxisInterpolation& axis : e.axes) {
    EXPECT_NEAR(axis.curvature_mm, 0, 1e-12);
    EXPECT_EQ(axis.kind, InterpolationKind::kCheckPoints);
    EXPECT_NEAR(axis.estimate_mm, noise, 1e-12);
    EXPECT_EQ(axis.check_points, 25u);
    EXPECT_EQ(axis.checked_cells, 25u);
    EXPECT_NEAR(axis.largest_residual_mm, 0, 1e-15);
  }
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
    for (TableNode& check : t.checks) check.stddev_mm.reset();  // noise 0: unknown_noise_mm below
  }
  const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0);
  for (const AxisInterpolation& axis : e.axes) {
    EXPECT_NEAR(axis.curvature_mm, 0, 1e-15);
    EXPECT_EQ(axis.kind, InterpolationKind::kCheckPoints);
    const double se = kReadingScatterMm / std::sqrt(static_cast<double>(kReadings));
    EXPECT_NEAR(axis.estimate_mm, kCheckPointMargin * (bump + kCheckPointSigmas * se / 2), 1e-12);
    EXPECT_NEAR(axis.largest_residual_mm, bump, 1e-15);
  }
  EXPECT_GE(e.axes[0].estimate_mm, TrueDeparture(f, pitch, 4));
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
  EXPECT_NEAR(e.axes[0].estimate_mm, kCheckPointMargin * 0.003 / 0.75, 1e-15);
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
  // nodes'): se sqrt(1 + 4/16) at 4 sigma, times the margin: 3.1 µm.
  const double se = kReadingScatterMm / std::sqrt(static_cast<double>(kReadings));
  EXPECT_NEAR(e.axes[1].estimate_mm, kCheckPointMargin * kCheckPointSigmas * se * std::sqrt(1.25), 1e-12);
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

// The property: random smooth fields whose shortest wavelength is 2.5
// pitches or more, at 2, 5, 10 and 25 mm pitch, measured with the paper's
// noise, large (0.25 mm) and small (5 µm) amplitudes; check points at every
// cell centre. The estimate from them must bound the true departure.
TEST(InterpolationErrorProperty, CheckPointsBoundTheTrueDepartureAtFourSigma) {
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
  double worst_ratio = 0;
  for (const Grid grid : {Grid{2, 11}, Grid{5, 11}, Grid{10, 6}, Grid{25, 3}}) {
    for (double amplitude : {0.25, 0.005}) {
      for (int trial = 0; trial < 12; ++trial) {
        const double shortest = test::Uniform(rng, 2.5, 8) * grid.pitch;
        const Field fx = RandomField(rng, shortest, amplitude);
        const Field fy = RandomField(rng, shortest, amplitude);
        const ErrorTable table = Measure(fx, fy, grid.pitch, grid.nodes, &rng);
        const InterpolationEstimate e = EstimateInterpolationError(table, std::nullopt, 0);
        for (TableAxis axis : kTableAxes) {
          const double truth = TrueDeparture(axis == TableAxis::X ? fx : fy, grid.pitch, grid.nodes);
          EXPECT_EQ(e[axis].kind == InterpolationKind::kCheckPoints || e[axis].kind == InterpolationKind::kCurvature,
                    true);
          EXPECT_GE(e[axis].estimate_mm, truth)
              << fmt::format("pitch {} mm, shortest wavelength {:.1f} mm, amplitude {} mm, trial {}, axis {}",
                             grid.pitch, shortest, amplitude, trial, AxisName(axis));
          worst_ratio = std::max(worst_ratio, truth / e[axis].estimate_mm);
        }
        ++fields;
      }
    }
  }
  RecordProperty("worst_truth_over_estimate", fmt::format("{:.3f}", worst_ratio));
  std::printf("largest true departure / estimate: %.3f\n", worst_ratio);
  EXPECT_EQ(fields, 96);
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

// The budget: a static target's `interpolation` part is its region's
// estimate as a bound; a fixture target's adds, per trip, its table's
// estimate across the trip's edge through the estimator: the same
// propagation as a trip outside every table with that accuracy.
TEST(InterpolationBudget, IsABoundAtTheTargetAndThroughTheTrips) {
  std::mt19937_64 rng(test::FixtureSeed());
  cell::Cell cell;
  cell.robot.repeatability_mm = 0.005;
  cell.regions.push_back(test::RegionOf("layers", test::RandomSmoothTable(rng, 148, 58, 165, 55, 12, 0.15)));
  cell.regions.push_back(test::RegionOf("marker1", test::RandomSmoothTable(rng, 127.5, 31, 25, 25, 6, 0.15)));
  cell.regions.push_back(test::RegionOf("marker2", test::RandomSmoothTable(rng, 313.5, 114, 25, 25, 6, 0.15)));
  cell.fixtures.push_back(test::PaperFixture(cell::Estimator::kRigid));
  const double own = 0.003, trip = 0.002;
  cell.regions[0].interpolation.axes[0].estimate_mm = own;
  cell.regions[0].interpolation.axes[1].estimate_mm = own;
  for (std::size_t r : {1u, 2u}) {
    cell.regions[r].interpolation.axes[0].estimate_mm = trip;
    cell.regions[r].interpolation.axes[1].estimate_mm = trip;
  }
  const ErrorBudget fixed = StaticBudget(cell, &cell.regions[0], 0);
  EXPECT_DOUBLE_EQ(fixed[ErrorSource::kInterpolation].bound_mm, own * std::numbers::sqrt2);
  EXPECT_DOUBLE_EQ(fixed[ErrorSource::kInterpolation].BudgetMm(), own * std::numbers::sqrt2);
  EXPECT_EQ(fixed[ErrorSource::kInterpolation].covariance_mm2, Eigen::Matrix2d::Zero());

  const Eigen::Vector2d point(120, 45);
  const ErrorBudget board = FixtureErrorModel(cell, cell.fixtures.front()).At(point, &cell.regions[0], 0);
  // The same cell without tables under the markers, the robot off by `trip`
  // there: the marker edges are axis-parallel, so |n_x| E_x + |n_y| E_y = trip.
  cell::Cell bare = cell;
  bare.regions.resize(1);
  bare.robot.uncalibrated_accuracy_mm = trip;
  const ErrorBudget outside = FixtureErrorModel(bare, bare.fixtures.front()).At(point, &bare.regions[0], 0);
  EXPECT_NEAR(board[ErrorSource::kInterpolation].bound_mm,
              own * std::numbers::sqrt2 + outside[ErrorSource::kUncalibratedTrips].bound_mm, 1e-12);
  EXPECT_GT(board[ErrorSource::kInterpolation].bound_mm, own * std::numbers::sqrt2 + trip);
  ErrorBudget without = board;
  without[ErrorSource::kInterpolation] = ErrorShare{};
  EXPECT_NEAR(board.BudgetMm() - board[ErrorSource::kInterpolation].bound_mm, without.BudgetMm(), 1e-12);
}

}  // namespace
}  // namespace smtcal
