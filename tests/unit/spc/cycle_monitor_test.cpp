// What a log of cycle records says (spc/cycle_monitor.h), on scans
// simulated here: in control, nothing; a board that walks, a robot whose
// scale changes, a sensor whose threshold moves — each found by its own
// chart and named, after it began; a record that another cell's tables
// wrote, found.
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "spc/cycle_monitor.h"
#include "calibration/fixture_estimation.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

using test::Uniform;

// A table of the same error everywhere on [x0, x0 + w] x [y0, y0 + h].
ErrorTable Flat(double x0, double y0, double w, double h, double error_mm = 0) {
  ErrorTable table;
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = table[axis];
    for (int i = 0; i <= 6; ++i) t.xs.push_back(x0 + w * i / 6);
    for (int j = 0; j <= 6; ++j) t.ys.push_back(y0 + h * j / 6);
    t.error_mm.assign(t.xs.size() * t.ys.size(), error_mm);
  }
  return table;
}

// The paper board with flat tables under its markers and over its middle
// (a calibrated region on the board for the far corner).
cell::Cell BoardCell() {
  cell::Cell cell;
  cell.name = "test";
  cell.robot.repeatability_mm = 0.005;
  cell.fixtures.push_back(test::PaperFixture(cell::Estimator::kRigid));
  cell.fixtures[0].sensor_accuracy_mm = 0.01;
  cell.regions.push_back(test::RegionOf("middle", Flat(150, 55, 100, 60)));
  cell.regions.push_back(test::RegionOf("marker1", Flat(125, 30, 30, 30)));
  cell.regions.push_back(test::RegionOf("marker2", Flat(315, 110, 30, 30)));
  return cell;
}

// The wide board of tests/golden/simulate/data/wide.cell.toml: its edges
// are the board's sides, each crossed near both its ends, so the trips see
// the sensor's threshold apart from the pose and the scale.
cell::Cell WideCell() {
  cell::Cell cell;
  cell.name = "wide";
  cell.robot.repeatability_mm = 0.005;
  cell::Fixture f = test::PaperFixture(cell::Estimator::kRigid);
  f.edges[0] = {"p1", {0, 0}, {190, 0}, {}};
  f.edges[1] = {"p2", {0, 0}, {0, 90}, {}};
  f.edges[2] = {"p3", {190, 0}, {190, 90}, {}};
  f.edges[3] = {"p4", {0, 90}, {190, 90}, {}};
  f.scan_paths.clear();
  const std::vector<std::pair<cell::Point2, cell::Point2>> legs = {
      {{-3, 13}, {13, -3}}, {{177, -3}, {193, 13}}, {{193, 77}, {177, 93}}, {{13, 93}, {-3, 77}}};
  for (std::size_t i = 0; i < legs.size(); ++i) {
    cell::ScanPath path;
    path.name = fmt::format("S{}", i + 1);
    path.points = {legs[i].first, legs[i].second};
    f.scan_paths.push_back(path);
  }
  f.sensor_accuracy_mm = 0.01;
  f.max_line_residual_mm = 0.07;
  cell.fixtures.push_back(f);
  return cell;
}

struct Drift {
  double walk_mm = 0, scale_ppm = 0, threshold_mm = 0, scatter_mm = 0;
  Eigen::Vector2d about = Eigen::Vector2d(233, 85);  // the robot's scale grows about this point
  int start = 100;
  double refused_before = 0, refused_after = 0;  // the chance a trip is missed, before and from `start` on
};

// Which side of its edge each trip's marker lies on (+1: the normal's).
std::vector<double> Inward(const cell::Fixture& fixture) {
  std::vector<double> inward;
  std::vector<int> on_path(fixture.scan_paths.size(), 0);
  for (const ExpectedTrip& e : ExpectedTrips(fixture)) {
    const EdgeLine line = EdgeLineOf(fixture.edges[static_cast<std::size_t>(e.edge)]);
    const double across = line.normal.dot(e.leg_direction) >= 0 ? 1 : -1;
    inward.push_back(on_path[e.path]++ % 2 == 0 ? across : -across);
  }
  return inward;
}

std::vector<MonitoredCycle> Simulate(const cell::Cell& cell, const Drift& drift, int scans, std::uint64_t seed) {
  const cell::Fixture& fixture = cell.fixtures[0];
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> jitter(0, 0.02);
  const std::vector<double> inward = Inward(fixture);
  std::vector<MonitoredCycle> cycles;
  std::optional<Eigen::Affine3d> previous;
  ScanOptions options;
  options.estimator = fixture.estimator;
  options.regions = &cell.regions;
  for (int n = 1; n <= scans; ++n) {
    const double steps = std::max(0, n - drift.start);
    Eigen::Affine3d truth = PlanarFix(fixture.origin_mm + Eigen::Vector2d(jitter(rng) + steps * drift.walk_mm, jitter(rng)),
                                      0.002 * jitter(rng) * kRadPerDeg);
    // A robot scale s about c the tables do not know: it trips where
    // t + s (t - c) is on the edge, on the edges of c + (FIX f - c) / (1 + s).
    const double s = steps * drift.scale_ppm * 1e-6;
    const Eigen::Vector2d c = drift.about;
    Eigen::Affine3d seen = truth;
    seen.linear() /= 1 + s;
    seen.translation().head<2>() = c + (FixOrigin(truth) - c) / (1 + s);
    std::vector<double> sensor;
    const double scatter = 0.01 + steps * drift.scatter_mm;
    for (double side : inward) sensor.push_back(Uniform(rng, -scatter, scatter) + steps * drift.threshold_mm * side);
    const std::vector<Eigen::Vector2d> trips = test::SimulateTrips(fixture, seen, sensor);
    std::vector<std::optional<Eigen::Vector2d>> present = test::Present(trips);
    const double refused = n > drift.start ? drift.refused_after : drift.refused_before;
    if (refused > 0 && Uniform(rng, 0, 1) < refused) present[3].reset();
    options.previous = previous;
    const ScanResult scan = ScanFixture(fixture, present, options);
    if (scan.ok()) previous = scan.fix;
    cycles.push_back({"Board", RecordOfScan(0, n, 60.0 * n, scan), n == 1, 0, SourceRange()});
  }
  return cycles;
}

// Monitor with its own diagnostics.
struct Judged {
  SourceManager sources;
  Diagnostics diags{sources};
  MonitorResult result;
  Judged(const cell::Cell& cell, const std::vector<MonitoredCycle>& cycles, const MonitorOptions& options,
         const MonitorBaseline* stored = nullptr)
      : result(Monitor(cell, cycles, options, stored, diags)) {}
  std::string Text() const { return diags.RenderText(); }
};

std::vector<FindingKind> Kinds(const FixtureMonitor& f) {
  std::vector<FindingKind> kinds;
  for (const Finding& finding : f.findings) kinds.push_back(finding.kind);
  return kinds;
}

TEST(CycleMonitor, EachDriftIsFoundByItsOwnChartAfterItBegan) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  const cell::Cell cell = BoardCell();
  MonitorOptions options;

  const Judged judged_steady(cell, Simulate(cell, {}, 300, seed), options);
  const MonitorResult& steady = judged_steady.result;
  EXPECT_TRUE(steady.judged) << judged_steady.Text();
  ASSERT_EQ(steady.fixtures.size(), 1u);
  EXPECT_TRUE(steady.in_control) << "false alarm on an in-control log";
  EXPECT_EQ(steady.fixtures[0].disagreements, 0);
  EXPECT_EQ(steady.fixtures[0].accepted, 300);
  EXPECT_EQ(steady.fixtures[0].seconds_per_scan, 60.0);
  ASSERT_TRUE(steady.fixtures[0].far_corner);
  EXPECT_EQ(steady.fixtures[0].far_corner->region, "middle");
  EXPECT_GT(steady.fixtures[0].far_corner->um_per_ppm, 0.05) << "rigid leaves a scale error at the corner";

  struct Case {
    const char* name;
    Drift drift;
    FindingKind kind;
  };
  const cell::Cell wide = WideCell();
  const Case cases[] = {{"walk", {.walk_mm = 0.004}, FindingKind::kFixtureMoving},
                        {"scale", {.scale_ppm = 1.5}, FindingKind::kRobotScale},
                        {"scatter", {.scatter_mm = 0.0001}, FindingKind::kSensor},
                        {"threshold on the wide board", {.threshold_mm = 0.0002}, FindingKind::kSensor}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const cell::Cell& board = c.drift.threshold_mm != 0 ? wide : cell;
    const Judged judged(board, Simulate(board, c.drift, 300, seed), options);
    const MonitorResult& result = judged.result;
    const FixtureMonitor& f = result.fixtures.at(0);
    EXPECT_FALSE(result.in_control);
    ASSERT_EQ(Kinds(f), std::vector<FindingKind>{c.kind});
    const Finding& finding = f.findings[0];
    EXPECT_GT(finding.alarm_scan, c.drift.start);
    EXPECT_LT(finding.alarm_scan, 260);
    EXPECT_GE(finding.change_scan, c.drift.start - 20);
    EXPECT_LE(finding.change_scan, finding.alarm_scan);
    EXPECT_EQ(f.threshold_identifiable, &board == &wide);
  }
  // The scale's finding: the far corner's error grows as the drift does.
  const Judged judged_scale(cell, Simulate(cell, {.scale_ppm = 1.5}, 300, seed), options);
  const MonitorResult& scale = judged_scale.result;
  const Finding& finding = scale.fixtures[0].findings.at(0);
  const double at_end_ppm = 1.5 * 200, um_per_ppm = scale.fixtures[0].far_corner->um_per_ppm;
  EXPECT_NEAR(finding.now, at_end_ppm * um_per_ppm, 0.25 * at_end_ppm * um_per_ppm);
  EXPECT_NEAR(finding.per_scan, 1.5 * um_per_ppm, 0.4 * 1.5 * um_per_ppm);
  ASSERT_TRUE(finding.scans_to_limit);
  EXPECT_FALSE(finding.stale.empty()) << "300 ppm moves the tables beyond their noise";
}

TEST(CycleMonitor, RecordsOfOtherTablesAreFound) {
  cell::Cell cell = BoardCell();
  const std::vector<MonitoredCycle> cycles = Simulate(cell, {}, 40, 7);
  // This cell's table under marker 2 says 3 µm more than the controller's did.
  cell.regions[2] = test::RegionOf("marker2", Flat(315, 110, 30, 30, 0.003));
  const Judged judged(cell, cycles, MonitorOptions{});
  const MonitorResult& result = judged.result;
  EXPECT_EQ(result.fixtures.at(0).disagreements, 40);
  EXPECT_GT(result.fixtures[0].worst_disagreement_mm, 1e-4);
}


TEST(CycleMonitor, RefusalsRisingFromOneToThreePercentAlarmWithinAFewHundredScans) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  const cell::Cell cell = BoardCell();
  // A clean baseline, then 1 % of scans refused for 400 scans, then 3 %.
  Drift drift;
  drift.start = 500;
  drift.refused_before = 0.01;
  drift.refused_after = 0.03;
  std::vector<MonitoredCycle> cycles = Simulate(cell, drift, 2000, seed);
  const std::vector<MonitoredCycle> clean = Simulate(cell, {}, 100, seed + 1);
  std::copy(clean.begin(), clean.end(), cycles.begin());  // the clean baseline
  const Judged judged(cell, cycles, MonitorOptions{});
  ASSERT_TRUE(judged.result.judged) << judged.Text();
  const FixtureMonitor& f = judged.result.fixtures.at(0);
  ASSERT_FALSE(f.refusals.empty());
  const RefusalResult& all = f.refusals.front();
  EXPECT_FALSE(all.check.has_value());
  EXPECT_EQ(all.baseline_count, 0);
  EXPECT_EQ(all.design.p0, kRefusalRateFloor) << "a clean baseline: designed for the floor";
  ASSERT_TRUE(all.alarm_scan) << all.count << " refused";
  EXPECT_GT(*all.alarm_scan, 500);
  EXPECT_LT(*all.alarm_scan, 500 + 4 * all.design.arl1) << "within a few run lengths at 3 %";
  ASSERT_FALSE(f.findings.empty());
  EXPECT_EQ(f.findings.back().kind, FindingKind::kRefusals);
}

TEST(CycleMonitor, ABaselineThatDriftsIsRefusedWithTheScansToExcludeAndOutliersAreLeftOut) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  const cell::Cell cell = BoardCell();
  // The board walks from scan 30 on, inside the baseline of 50.
  const Judged drifting(cell, Simulate(cell, {.walk_mm = 0.01, .start = 30}, 200, seed), MonitorOptions{});
  EXPECT_FALSE(drifting.result.judged);
  EXPECT_NE(drifting.Text().find("error: fixture 'Board''s baseline (scans 1 to 50) drifts"), std::string::npos)
      << drifting.Text();
  EXPECT_NE(drifting.Text().find("exclude scans "), std::string::npos) << drifting.Text();
  // Started after the drift's start the baseline is refused too; a steady one
  // of the same log's first 25 scans is not.
  MonitorOptions short_window;
  short_window.baseline = 25;
  const Judged steady(cell, Simulate(cell, {.walk_mm = 0.01, .start = 30}, 200, seed), short_window);
  EXPECT_TRUE(steady.result.judged) << steady.Text();
  EXPECT_FALSE(steady.result.in_control);

  // One wild pose in the baseline: left out, said, and the chart not blinded.
  std::vector<MonitoredCycle> cycles = Simulate(cell, {}, 200, seed);
  const Judged clean(cell, cycles, MonitorOptions{});
  auto& s1 = (*cycles[9].record.estimate)[0];
  s1.x() += 0.5;  // 500 µm, as an edited record might say
  const Judged wild(cell, cycles, MonitorOptions{});
  ASSERT_TRUE(wild.result.judged) << wild.Text();
  EXPECT_NE(wild.Text().find("warning: fixture 'Board''s baseline (scans 1 to 50) holds values far from their "
                             "neighbours"),
            std::string::npos)
      << wild.Text();
  const SeriesResult& x = wild.result.fixtures[0].series[0];
  EXPECT_EQ(x.outliers, std::vector<long>{10});
  EXPECT_LT(x.chart.sigma_estimate, 1.5 * clean.result.fixtures[0].series[0].chart.sigma_estimate);
}

TEST(CycleMonitor, AStoredBaselineJudgesAsTheWindowItCameFrom) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  const cell::Cell cell = BoardCell();
  const std::vector<MonitoredCycle> cycles = Simulate(cell, {.walk_mm = 0.004}, 300, seed);
  const Judged window(cell, cycles, MonitorOptions{});
  ASSERT_TRUE(window.result.judged) << window.Text();
  const MonitorBaseline baseline = BaselineOf(window.result, cell, {"a.log"});
  const Judged stored(cell, cycles, MonitorOptions{}, &baseline);
  ASSERT_TRUE(stored.result.judged) << stored.Text();
  const FixtureMonitor &a = window.result.fixtures[0], &b = stored.result.fixtures[0];
  for (std::size_t q = 0; q < kQuantities; ++q) {
    EXPECT_EQ(a.series[q].chart.center, b.series[q].chart.center);
    EXPECT_EQ(a.series[q].chart.sigma, b.series[q].chart.sigma);
    EXPECT_EQ(a.series[q].chart.alarm, b.series[q].chart.alarm);
  }
  EXPECT_EQ(Kinds(a), Kinds(b));
  EXPECT_TRUE(b.baseline_stored);
}

TEST(CycleMonitor, ARobotScaleAboutItsOriginExplainsThePoseDriftItCauses) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  const cell::Cell cell = BoardCell();
  // About the robot's origin: the board's measured origin walks by s times
  // its distance from it, and both the scale and the pose charts alarm.
  const Judged judged(cell, Simulate(cell, {.scale_ppm = 3, .about = Eigen::Vector2d(0, 0)}, 300, seed),
                      MonitorOptions{});
  ASSERT_TRUE(judged.result.judged) << judged.Text();
  const FixtureMonitor& f = judged.result.fixtures[0];
  ASSERT_FALSE(f.findings.empty());
  EXPECT_EQ(f.findings.front().kind, FindingKind::kRobotScale) << "the cause first";
  EXPECT_FALSE(f.findings.front().explains.empty()) << "the pose drift it causes, under it";
  for (const ExplainedDrift& e : f.findings.front().explains) {
    EXPECT_FALSE(e.alarms_without) << QuantityName(e.quantity);
    EXPECT_NEAR(e.explained_per_100, e.observed_per_100, 0.5 * std::abs(e.observed_per_100)) << QuantityName(e.quantity);
  }
  for (const Finding& finding : f.findings) EXPECT_NE(finding.kind, FindingKind::kFixtureMoving);
}

}  // namespace
}  // namespace smtcal
