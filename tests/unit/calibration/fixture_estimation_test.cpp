// The periphery calibration's math: every estimator exact on noise-free
// trips, every fault injected gives its fault code and no pose, the per-cycle
// delta, the trips' direct calibration, the closed form of Eq. 9 against
// 1000 cycles of the recursion, and the sensor's share of the error.
// Randomized tests print their seed; SMTCAL_TEST_SEED varies it.
#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/error_table_check.h"
#include "calibration/fixture_estimation.h"
#include "calibration/placement_budget.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

using test::PaperFixture;
using test::Present;
using test::SimulateTrips;
using test::Uniform;

constexpr cell::Estimator kEstimators[] = {cell::Estimator::kPaper, cell::Estimator::kRigid,
                                           cell::Estimator::kRigidScale};

// The largest distance between two FIX's images of the board's corners.
double BoardError(const cell::Fixture& fixture, const Eigen::Affine3d& a, const Eigen::Affine3d& b) {
  double worst = 0;
  for (double x : {0.0, fixture.l1_mm}) {
    for (double y : {0.0, fixture.l2_mm}) {
      worst = std::max(worst, (ToBase(a, Eigen::Vector2d(x, y)) - ToBase(b, Eigen::Vector2d(x, y))).norm());
    }
  }
  return worst;
}

ScanResult Scan(const cell::Fixture& fixture, const std::vector<Eigen::Vector2d>& trips,
                std::optional<Eigen::Affine3d> previous = std::nullopt) {
  ScanOptions options;
  options.estimator = fixture.estimator;
  options.previous = previous;
  return ScanFixture(fixture, Present(trips), options);
}

void ExpectFault(const ScanResult& result, ScanCheck code) {
  ASSERT_NE(result.FirstFailure(), nullptr) << "expected " << ScanCheckName(code);
  EXPECT_EQ(result.FirstFailure()->check, code) << ScanCheckName(result.FirstFailure()->check);
  EXPECT_FALSE(result.fix.has_value());
  EXPECT_FALSE(result.ok());
}

TEST(FixtureEstimation, NominalScanPassesEveryCheck) {
  for (cell::Estimator estimator : kEstimators) {
    SCOPED_TRACE(std::string(cell::EstimatorName(estimator)));
    const cell::Fixture fixture = PaperFixture(estimator);
    const ScanResult result = Scan(fixture, SimulateTrips(fixture, NominalFix(fixture)));
    ASSERT_TRUE(result.ok()) << DescribeFailure(result, fixture);
    EXPECT_LT(BoardError(fixture, *result.fix, NominalFix(fixture)), 1e-9);
    EXPECT_NEAR((result.estimate->s[1] - Eigen::Vector2d(328, 40)).norm(), 0, 1e-9);
    EXPECT_NEAR((result.estimate->s[2] - Eigen::Vector2d(138, 130)).norm(), 0, 1e-9);
    for (const CheckResult& check : result.checks) {
      const bool cycle = check.check == ScanCheck::kCycleShift || check.check == ScanCheck::kCycleRotation;
      EXPECT_EQ(check.evaluated, !cycle) << ScanCheckName(check.check);
    }
  }
}

// Exactness: noise-free trips of a random true pose, each estimator on the
// poses it models (paper: any affine board; rigid: rotation + translation;
// rigid-scale: plus a scale) recovers FIX to 1e-9.
TEST(FixtureEstimation, EveryEstimatorIsExactOnNoiseFreeTrips) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  for (int i = 0; i < 2000; ++i) {
    const cell::Estimator estimator = kEstimators[i % 3];
    cell::Fixture fixture = PaperFixture(estimator);
    fixture.origin_mm = {Uniform(rng, -300, 300), Uniform(rng, -300, 300)};
    fixture.angle_deg = Uniform(rng, -180, 180);
    const double scale = estimator == cell::Estimator::kRigid ? 1 : 1 + Uniform(rng, -1e-3, 1e-3);
    Eigen::Affine3d truth = PlanarFix(fixture.origin_mm + Eigen::Vector2d(Uniform(rng, -1, 1), Uniform(rng, -1, 1)),
                                      (fixture.angle_deg + Uniform(rng, -0.4, 0.4)) * kRadPerDeg, scale);
    if (estimator == cell::Estimator::kPaper) {  // a slightly sheared board too
      truth.linear()(0, 1) += Uniform(rng, -1e-3, 1e-3);
    }
    const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
    std::string why;
    std::optional<FixEstimate> estimate =
        EstimateFix(fixture, expected, SimulateTrips(fixture, truth), estimator, &why);
    ASSERT_TRUE(estimate) << why << " at case " << i;
    ASSERT_LT((estimate->fix.matrix() - truth.matrix()).cwiseAbs().maxCoeff(), 1e-9)
        << cell::EstimatorName(estimator) << " case " << i;
    ASSERT_LT(BoardError(fixture, estimate->fix, truth), 1e-9) << cell::EstimatorName(estimator) << " case " << i;
    for (double r : estimate->residual_mm) ASSERT_LT(r, 1e-9);
  }
}

TEST(FixtureEstimation, RigidScaleMeasuresTheScale) {
  cell::Fixture fixture = PaperFixture(cell::Estimator::kRigidScale);
  fixture.length_tolerance_mm = 0.05;
  const double scale = 1 + 2e-4;  // a board 38 um longer over L1
  const Eigen::Affine3d truth = PlanarFix(fixture.origin_mm, 0.1 * kRadPerDeg, scale);
  ScanResult result = Scan(fixture, SimulateTrips(fixture, truth));
  ASSERT_TRUE(result.ok()) << DescribeFailure(result, fixture);
  EXPECT_NEAR(result.estimate->scale, scale, 1e-12);
  EXPECT_NEAR(result.Check(ScanCheck::kLengthL1).value, 190 * 2e-4, 1e-9);
  // The rigid estimator cannot follow the growth: it shows as residuals.
  fixture.estimator = cell::Estimator::kRigid;
  result = Scan(fixture, SimulateTrips(fixture, PlanarFix(fixture.origin_mm, 0, 1 + 1e-3)));
  ExpectFault(result, ScanCheck::kLineResidual);
}

TEST(FixtureEstimation, RigidLeastSquaresBeatsEq4OnNoisyTrips) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  double paper_sum = 0, rigid_sum = 0;
  for (int i = 0; i < 300; ++i) {
    const cell::Fixture fixture = PaperFixture();
    const Eigen::Affine3d truth = PlanarFix(
        fixture.origin_mm + Eigen::Vector2d(Uniform(rng, -0.5, 0.5), Uniform(rng, -0.5, 0.5)),
        Uniform(rng, -0.1, 0.1) * kRadPerDeg);
    std::vector<double> sensor;
    for (int k = 0; k < 8; ++k) sensor.push_back(Uniform(rng, -0.05, 0.05));
    const std::vector<Eigen::Vector2d> trips = SimulateTrips(fixture, truth, sensor);
    const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
    auto paper = EstimateFix(fixture, expected, trips, cell::Estimator::kPaper);
    auto rigid = EstimateFix(fixture, expected, trips, cell::Estimator::kRigid);
    ASSERT_TRUE(paper && rigid);
    paper_sum += BoardError(fixture, paper->fix, truth);
    rigid_sum += BoardError(fixture, rigid->fix, truth);
  }
  // The least-squares fit uses the 200 mm between the markers; Eq. 4 the
  // few millimetres between trips on one marker edge.
  EXPECT_LT(rigid_sum, paper_sum / 10);
}

// --- fault injection: each gives its code and never a pose --------------------

class FaultInjection : public testing::TestWithParam<cell::Estimator> {
 protected:
  cell::Fixture fixture_ = PaperFixture(GetParam());
  Eigen::Affine3d truth_ = PlanarFix(Eigen::Vector2d(138.3, 39.8), 0.05 * kRadPerDeg);
  std::vector<Eigen::Vector2d> trips_ = SimulateTrips(fixture_, truth_);
};

TEST_P(FaultInjection, CleanScanPasses) {
  const ScanResult result = Scan(fixture_, trips_);
  ASSERT_TRUE(result.ok()) << DescribeFailure(result, fixture_);
  EXPECT_LT(BoardError(fixture_, *result.fix, truth_), 1e-9);
}

TEST_P(FaultInjection, MissingTrip) {
  for (std::size_t k = 0; k < trips_.size(); ++k) {
    std::vector<std::optional<Eigen::Vector2d>> trips = Present(trips_);
    trips[k].reset();
    ScanOptions options;
    options.estimator = GetParam();
    const ScanResult result = ScanFixture(fixture_, trips, options);
    ExpectFault(result, ScanCheck::kMissingTrip);
    EXPECT_EQ(result.FirstFailure()->trip, static_cast<int>(k));
    EXPECT_FALSE(result.estimate.has_value());
  }
}

TEST_P(FaultInjection, TripOutsideItsWindow) {
  std::vector<Eigen::Vector2d> trips = trips_;
  // The sensor tripped late, 3.5 mm further along T6's leg (a dirty marker).
  const ExpectedTrip t6 = ExpectedTrips(fixture_)[5];
  trips[5] += 3.5 * t6.leg_direction;
  const ScanResult result = Scan(fixture_, trips);
  ExpectFault(result, ScanCheck::kTripWindow);
  EXPECT_EQ(result.FirstFailure()->trip, 5);
  EXPECT_NEAR(result.FirstFailure()->value, (trips[5] - result.nominal[5]).norm(), 1e-12);
}

TEST_P(FaultInjection, OutlierTrip) {
  // T5 (on p3) 0.4 mm across its edge: inside its window, but off the line.
  std::vector<double> sensor(8, 0.0);
  sensor[4] = 0.4;
  const ScanResult result = Scan(fixture_, SimulateTrips(fixture_, truth_, sensor));
  ASSERT_FALSE(result.ok());
  // Eq. 4 uses p3 only through S2 (its crossing with p1), so the outlier
  // stretches |S2 - S1|; rigid-scale takes part of it as a longer board; the
  // rigid fit cannot, and sees it as a residual.
  EXPECT_EQ(ScanCheckName(result.FirstFailure()->check),
            ScanCheckName(GetParam() == cell::Estimator::kRigid ? ScanCheck::kLineResidual : ScanCheck::kLengthL1));
  EXPECT_FALSE(result.fix.has_value());
}

TEST_P(FaultInjection, SwappedMarkers) {
  // The two V paths' trips swapped (the trip lists of the markers exchanged):
  // every trip is 190 mm from its window.
  std::vector<Eigen::Vector2d> trips = trips_;
  std::rotate(trips.begin(), trips.begin() + 4, trips.end());
  ExpectFault(Scan(fixture_, trips), ScanCheck::kTripWindow);
  // Two trips of one marker swapped (T1 on p2 with T2 on p1), the window
  // wide enough to take them: the lines no longer fit.
  cell::Fixture wide = fixture_;
  wide.trip_window_mm = 10;
  trips = trips_;
  std::swap(trips[0], trips[1]);
  const ScanResult result = Scan(wide, trips);
  ASSERT_FALSE(result.ok());
  EXPECT_FALSE(result.fix.has_value());
  const ScanCheck code = result.FirstFailure()->check;
  EXPECT_TRUE(code == ScanCheck::kDegenerate || code == ScanCheck::kLengthL1 || code == ScanCheck::kLengthL2 ||
              code == ScanCheck::kSquareness || code == ScanCheck::kLineResidual)
      << ScanCheckName(code);
}

TEST_P(FaultInjection, BoardBeyondTheShiftLimit) {
  cell::Fixture wide = fixture_;
  wide.trip_window_mm = 10;  // so the trips are found at all
  const Eigen::Affine3d far = PlanarFix(wide.origin_mm + Eigen::Vector2d(1.8, 1.2), 0);  // 2.16 mm
  const ScanResult result = Scan(wide, SimulateTrips(wide, far));
  ExpectFault(result, ScanCheck::kNominalShift);
  EXPECT_NEAR(result.FirstFailure()->value, std::hypot(1.8, 1.2), 1e-9);
}

TEST_P(FaultInjection, BoardBeyondTheRotationLimit) {
  cell::Fixture wide = fixture_;
  wide.trip_window_mm = 10;
  wide.squareness_deg = 5;
  const Eigen::Affine3d turned = PlanarFix(wide.origin_mm, 0.6 * kRadPerDeg);
  ExpectFault(Scan(wide, SimulateTrips(wide, turned)), ScanCheck::kNominalRotation);
}

TEST_P(FaultInjection, BoardJumpedSinceThePreviousCycle) {
  const Eigen::Affine3d previous = PlanarFix(fixture_.origin_mm - Eigen::Vector2d(1.0, 1.0), 0);  // |d| = 1.96 mm
  ScanResult result = Scan(fixture_, trips_, previous);
  ASSERT_TRUE(result.ok()) << DescribeFailure(result, fixture_);
  ASSERT_TRUE(result.delta.has_value());
  // delta . previous = FIX_n.
  EXPECT_LT(((*result.delta * previous).matrix() - result.fix->matrix()).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::Affine3d jumped = PlanarFix(fixture_.origin_mm - Eigen::Vector2d(1.8, 1.0), 0);
  result = Scan(fixture_, trips_, jumped);
  ExpectFault(result, ScanCheck::kCycleShift);
  const Eigen::Affine3d turned = PlanarFix(truth_.translation().head<2>(), -0.5 * kRadPerDeg);
  ExpectFault(Scan(fixture_, trips_, turned), ScanCheck::kCycleRotation);
}

TEST_P(FaultInjection, CoincidentTripsAreDegenerate) {
  cell::Fixture wide = fixture_;
  wide.trip_window_mm = 10;
  std::vector<Eigen::Vector2d> trips = trips_;
  trips[2] = trips[1];  // T3 = T2: p1 has one point twice
  const ScanResult result = Scan(wide, trips);
  if (GetParam() == cell::Estimator::kPaper) {
    ExpectFault(result, ScanCheck::kDegenerate);
    EXPECT_NE(result.FirstFailure()->why.find("p1"), std::string::npos) << result.FirstFailure()->why;
  } else {
    // The least-squares fits still have 7 distinct trips on 4 lines.
    EXPECT_FALSE(result.Check(ScanCheck::kDegenerate).evaluated && !result.Check(ScanCheck::kDegenerate).passed);
  }
}

INSTANTIATE_TEST_SUITE_P(Estimators, FaultInjection, testing::ValuesIn(kEstimators),
                         [](const testing::TestParamInfo<cell::Estimator>& info) {
                           return info.param == cell::Estimator::kPaper   ? std::string("paper")
                                  : info.param == cell::Estimator::kRigid ? std::string("rigid")
                                                                          : std::string("rigid_scale");
                         });

TEST(FixtureEstimation, FaultDescriptionsNameTheCheckAndItsLimit) {
  cell::Fixture fixture = PaperFixture(cell::Estimator::kRigid);
  std::vector<Eigen::Vector2d> trips = SimulateTrips(fixture, NominalFix(fixture));
  trips[5] += 3.5 * ExpectedTrips(fixture)[5].leg_direction;
  const ScanResult result = Scan(fixture, trips);
  EXPECT_EQ(DescribeFailure(result, fixture),
            "trip_window: trip T6 (edge p4 of scan path 'V2') is 3.500 mm from where the nominal pose puts it, "
            "more than trip_window_mm = 3.000");
  EXPECT_EQ(DescribeFailure(Scan(fixture, SimulateTrips(fixture, NominalFix(fixture))), fixture), "");
}

// --- direct calibration of the trips ------------------------------------------

TEST(FixtureEstimation, TripsAreDirectCalibratedWhereATableCoversThem) {
  std::mt19937_64 rng(test::FixtureSeed());
  const cell::Fixture fixture = PaperFixture(cell::Estimator::kRigid);
  // A table over marker 1 only: its trips are where the robot really was,
  // F(commanded); marker 2's trips are used as commanded.
  std::vector<cell::Region> regions;
  regions.push_back(test::RegionOf("marker1", test::RandomSmoothTable(rng, 120, 25, 40, 40, 9, 0.15)));
  const CalibrationMap map(regions[0].table);
  // Commanded trips such that F(commanded) lies exactly on the true edges.
  const Eigen::Affine3d truth = PlanarFix(Eigen::Vector2d(138.2, 40.1), 0.02 * kRadPerDeg);
  std::vector<Eigen::Vector2d> actual = SimulateTrips(fixture, truth);
  InverseSolver solver(regions[0].table);
  std::vector<std::optional<Eigen::Vector2d>> commanded;
  for (std::size_t k = 0; k < actual.size(); ++k) {
    commanded.push_back(k < 4 ? solver.Solve(actual[k], OutsidePolicy::kError).point : actual[k]);
  }
  ScanOptions options;
  options.estimator = fixture.estimator;
  options.regions = &regions;
  const ScanResult result = ScanFixture(fixture, commanded, options);
  ASSERT_TRUE(result.ok()) << DescribeFailure(result, fixture);
  EXPECT_LT(BoardError(fixture, *result.fix, truth), 1e-9);
  for (std::size_t k = 0; k < 8; ++k) EXPECT_EQ(result.region[k], k < 4 ? 0 : -1);
  // Without the tables the same trips give a different (wrong) pose.
  options.regions = nullptr;
  const ScanResult raw = ScanFixture(fixture, commanded, options);
  ASSERT_TRUE(raw.estimate.has_value());
  EXPECT_GT(BoardError(fixture, raw.estimate->fix, truth), 0.01);
}

// --- corrections -----------------------------------------------------------------

TEST(FixtureCorrections, ClosedFormEqualsThePapersRecursionOver1000Cycles) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  const cell::Fixture fixture = PaperFixture(cell::Estimator::kPaper);
  // FIX_n from noisy scans through Eq. 4: not exactly orthonormal, so the
  // inverses are general ones.
  auto scan = [&] {
    const Eigen::Affine3d truth = PlanarFix(
        fixture.origin_mm + Eigen::Vector2d(Uniform(rng, -0.5, 0.5), Uniform(rng, -0.5, 0.5)),
        Uniform(rng, -0.2, 0.2) * kRadPerDeg);
    std::vector<double> sensor;
    for (int k = 0; k < 8; ++k) sensor.push_back(Uniform(rng, -0.005, 0.005));
    return EstimateFix(fixture, ExpectedTrips(fixture), SimulateTrips(fixture, truth, sensor),
                       cell::Estimator::kPaper)
        ->fix;
  };
  const Eigen::Affine3d fix0 = scan();
  const Eigen::Affine3d reached0 = PoseMatrix(171.204, 97.311, -3.0, 12.5);  // F(ROBOT_0)
  Eigen::Affine3d recursive = reached0, previous = fix0;
  double worst = 0;
  for (int n = 1; n <= 1000; ++n) {
    const Eigen::Affine3d fix_n = scan();
    recursive = fix_n * previous.inverse() * recursive;  // Eq. 9
    previous = fix_n;
    const Eigen::Affine3d closed = TaughtTarget(fix_n, fix0, reached0);
    worst = std::max(worst, (closed.matrix() - recursive.matrix()).cwiseAbs().maxCoeff());
    // And Eq. 6 with FIXPOS_0 from Eq. 7 is the same point.
    const Eigen::Affine3d offline = OfflineTarget(fix_n, TaughtFixturePosition(fix0, reached0));
    ASSERT_LT((closed.matrix() - offline.matrix()).cwiseAbs().maxCoeff(), 1e-11);
  }
  EXPECT_LT(worst, 1e-9) << "the recursion drifted from the closed form";
  RecordProperty("recursion_drift_mm", fmt::format("{:.3e}", worst));
}

TEST(FixtureCorrections, PoseValuesRoundTrip) {
  const std::array<double, 4> values = PoseValues(PoseMatrix(12.7, 8.25, -3, 90));
  EXPECT_NEAR(values[0], 12.7, 1e-12);
  EXPECT_NEAR(values[1], 8.25, 1e-12);
  EXPECT_NEAR(values[2], -3, 1e-12);
  EXPECT_NEAR(values[3], 90, 1e-12);
}

TEST(FixtureCorrections, CorrectedPointLandsWhereThePartMustGo) {
  std::mt19937_64 rng(test::FixtureSeed());
  std::vector<cell::Region> regions;
  regions.push_back(test::RegionOf("layer1", test::RandomSmoothTable(rng, 150, 60, 50, 50, 11, 0.15)));
  const PointCorrector corrector(regions);
  const CalibrationMap map(regions[0].table);
  const Eigen::Affine3d fix = PlanarFix(Eigen::Vector2d(138.3, 39.8), 0.1 * kRadPerDeg);
  const CorrectedPoint point = corrector.Correct(fix, Eigen::Vector2d(30, 40));
  ASSERT_EQ(point.region, 0);
  EXPECT_EQ(point.solution.status, SolveStatus::kOk);
  EXPECT_NEAR((point.required - ToBase(fix, Eigen::Vector2d(30, 40))).norm(), 0, 1e-12);
  EXPECT_LT((point.command + map.Delta(point.command) - point.required).norm(), 1e-9);
  // Outside every region: commanded as required, and said so.
  const CorrectedPoint outside = corrector.Correct(fix, Eigen::Vector2d(150, 5));
  EXPECT_EQ(outside.region, -1);
  EXPECT_EQ(outside.solution.status, SolveStatus::kUncorrected);
  EXPECT_EQ(outside.command, outside.required);
}

// --- the scan's share of the error budget (calibration/placement_budget.h) ---------

// A cell around one fixture, no tables: the budget's scan parts alone.
cell::Cell CellOf(const cell::Fixture& fixture) {
  cell::Cell cell;
  cell.robot.repeatability_mm = 0.005;
  cell.fixtures.push_back(fixture);
  return cell;
}

TEST(FixtureErrorBudget, SensorPartMatchesTheSpreadOfSimulatedScans) {
  // Linear propagation against a Monte Carlo of the same model: each trip
  // uniform in +-a across its edge, a small enough for the linear regime.
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  for (cell::Estimator estimator : kEstimators) {
    SCOPED_TRACE(std::string(cell::EstimatorName(estimator)));
    const cell::Cell cell = CellOf(PaperFixture(estimator));
    const cell::Fixture& fixture = cell.fixtures.front();
    const FixtureErrorModel model(cell, fixture);
    ASSERT_TRUE(model.defined());
    const Eigen::Vector2d point(120, 60);
    const Eigen::Affine3d nominal = NominalFix(fixture);
    double sum = 0;
    const int scans = 4000;
    const double a = 1e-3;
    for (int i = 0; i < scans; ++i) {
      std::vector<double> sensor;
      for (int k = 0; k < 8; ++k) sensor.push_back(Uniform(rng, -a, a));
      auto estimate = EstimateFix(fixture, ExpectedTrips(fixture), SimulateTrips(fixture, nominal, sensor), estimator);
      ASSERT_TRUE(estimate);
      sum += (ToBase(estimate->fix, point) - ToBase(nominal, point)).squaredNorm();
    }
    const double measured = std::sqrt(sum / scans);
    // The model's covariance is for +-sensor_accuracy_mm; scale it to +-a.
    const Eigen::Matrix2d covariance = model.At(point, nullptr, 0)[ErrorSource::kSensor].covariance_mm2;
    const double predicted = std::sqrt(covariance.trace()) * a / fixture.sensor_accuracy_mm;
    EXPECT_NEAR(measured / predicted, 1, 0.06);
  }
}

TEST(FixtureErrorBudget, LeastSquaresSensorPartIsFarBelowEq4s) {
  const Eigen::Vector2d layer(120, 45);
  auto sensor = [&](cell::Estimator estimator) {
    const cell::Cell cell = CellOf(PaperFixture(estimator));
    return FixtureErrorModel(cell, cell.fixtures.front()).At(layer, nullptr, 0)[ErrorSource::kSensor].BudgetMm();
  };
  const double paper = sensor(cell::Estimator::kPaper), rigid = sensor(cell::Estimator::kRigid),
               scaled = sensor(cell::Estimator::kRigidScale);
  EXPECT_LT(rigid, paper / 10);
  EXPECT_LE(rigid, scaled * (1 + 1e-6));
  EXPECT_GT(rigid, 0);
  RecordProperty("sensor_part_mm", fmt::format("paper {:.4f} rigid {:.4f} rigid-scale {:.4f}", paper, rigid, scaled));
}

TEST(FixtureErrorBudget, UnboundedWhenTheNominalTripsDefineNoPose) {
  cell::Fixture fixture = PaperFixture();
  fixture.edges[2] = {"p3", {182, 90}, {190, 90}, {}};  // p3 parallel to p1: S2 undefined
  fixture.edges[3] = {"p4", {190, 82}, {190, 90}, {}};
  const cell::Cell cell = CellOf(fixture);
  const FixtureErrorModel model(cell, cell.fixtures.front());
  EXPECT_FALSE(model.defined());
  EXPECT_FALSE(model.At(Eigen::Vector2d(10, 10), nullptr, 0).bounded);
  EXPECT_TRUE(std::isinf(model.At(Eigen::Vector2d(10, 10), nullptr, 0).BudgetMm()));
}

TEST(FixtureErrorBudget, UncalibratedTripsNeedTheRobotsDeclaredAccuracy) {
  cell::Cell cell = CellOf(PaperFixture(cell::Estimator::kRigid));
  const Eigen::Vector2d point(120, 45);
  EXPECT_FALSE(FixtureErrorModel(cell, cell.fixtures.front()).At(point, nullptr, 0).bounded);
  cell.robot.uncalibrated_accuracy_mm = 0.25;
  const ErrorBudget budget = FixtureErrorModel(cell, cell.fixtures.front()).At(point, nullptr, 0);
  ASSERT_TRUE(budget.bounded);
  EXPECT_EQ(budget.Largest(), ErrorSource::kUncalibratedTrips);
  EXPECT_GT(budget[ErrorSource::kUncalibratedTrips].bound_mm, 0.25);  // a rotation error grows with the arm
}

}  // namespace
}  // namespace smtcal
