// The measurement plan (calibration/measurement_plan.h) and what a reading
// means (calibration/measurement_reading.h). The property tests print their
// seed on failure; SMTCAL_TEST_SEED reruns with another.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <random>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/measurement_plan.h"
#include "calibration/measurement_reading.h"

namespace smtcal::measure {
namespace {

std::uint64_t BaseSeed() {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : 20261126;
}

double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// A cell like the paper's: its robot, one region, a probe with a hole plate.
cell::Cell TestCell(cell::MeasureDevice device, cell::Interval x, cell::Interval y) {
  cell::Cell c;
  c.name = "test";
  c.robot.limits = {cell::Interval{0, 400}, cell::Interval{0, 300}, cell::Interval{-30, 0}, cell::Interval{-360, 360}};
  c.robot.xy_speed_mm_s = 800;
  c.robot.xy_accel_mm_s2 = 3000;
  c.robot.z_speed_mm_s = 300;
  c.robot.z_accel_mm_s2 = 2000;
  c.robot.uncalibrated_accuracy_mm = 0.25;
  c.robot.uncalibrated_correlation_mm = 25;
  c.robot.final_approach_mm = Eigen::Vector2d(0.5, 0.5);
  cell::Region region;
  region.name = "r";
  region.x_mm = x;
  region.y_mm = y;
  region.tolerance_mm = 0.1;
  region.has_table = false;
  c.regions.push_back(region);
  cell::Measure m;
  m.device = device;
  m.z_mm = -8;
  m.clear_z_mm = -5;
  m.dwell_s = 0.1;
  m.noise_mm = 0.001;
  m.probe.hole_diameter_mm = 4;
  m.probe.stylus_diameter_mm = 1;
  m.probe.hole_pitch_mm = 5;
  m.probe.speed_mm_s = 2;
  m.probe.overtravel_mm = 0.8;  // more than the robot's error, the plate's placement and turn (0.75 mm at most here)
  m.placement_deg = 0.05;
  m.transducer.groove_pitch_mm = 5;
  m.transducer.grooves = 11;
  c.measure = m;
  return c;
}

TEST(MeasurementPlan, ThePapersCellGetsItsGridAndDefaults) {
  SourceManager sources_diags;
  Diagnostics diags(sources_diags);
  cell::Cell c = TestCell(cell::MeasureDevice::kProbe, {150.5, 199.5}, {60.5, 109.5});
  PlanOptions options;
  options.pitch_mm = 5;
  options.check_points = false;
  std::optional<Plan> plan = MakePlan(c, options, diags);
  ASSERT_TRUE(plan) << diags.RenderText();
  const PlanRegion& r = plan->regions.at(0);
  // 50 x 50 mm at 5 mm: the paper's 11 x 11 nodes, 150..200 and 60..110.
  EXPECT_EQ(r.xs.size(), 11u);
  EXPECT_EQ(r.ys.size(), 11u);
  EXPECT_DOUBLE_EQ(r.xs.front(), 150);
  EXPECT_DOUBLE_EQ(r.ys.back(), 110);
  EXPECT_EQ(r.nodes, 121);
  // Two sets of ten: every node visited once per set, ten readings a
  // visit, and each set closed by its first node again.
  EXPECT_EQ(plan->visits.size(), 244u);
  EXPECT_EQ(plan->visits[121].kind, VisitKind::kClosure);
  EXPECT_EQ(plan->visits[121].node, plan->visits[0].node);
  for (const Visit& v : plan->visits) EXPECT_EQ(v.repetitions, 10);
  EXPECT_GT(plan->time_s, 0);
}

TEST(MeasurementPlan, DefaultPitchIsTheInterpolationEstimatesGridAdvice) {
  SourceManager sources_diags;
  Diagnostics diags(sources_diags);
  cell::Cell c = TestCell(cell::MeasureDevice::kProbe, {150.5, 199.5}, {60.5, 109.5});
  std::optional<Plan> plan = MakePlan(c, PlanOptions{}, diags);
  ASSERT_TRUE(plan) << diags.RenderText();
  // No table yet: the declared roughness (0.25 mm over 25 mm) at 10 % of
  // 0.1 mm, PlannedPitchMm 5.6 mm, rounded to 5 mm (a lattice step).
  const DeclaredRoughness declared{0.25, 25};
  EXPECT_DOUBLE_EQ(PlannedPitchMm(declared, 0.1), 5.6);
  EXPECT_DOUBLE_EQ(plan->regions[0].pitch_mm, 5);
  EXPECT_NE(plan->regions[0].pitch_reason.find("declared roughness"), std::string::npos);
  // A previous table: verify's estimate of it (the region's interpolation)
  // and its grid advice. A flat 3 x 3 table at 25 mm rules nothing out: the
  // advice names 5.9 mm, the plan 5 mm.
  cell::Region& region = c.regions[0];
  region.has_table = true;
  region.table_path = "previous.csv";
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = region.table[axis];
    t.xs = {150, 175, 200};
    t.ys = {60, 85, 110};
    t.error_mm.assign(9, 0);
    for (std::size_t j = 0; j < 3; ++j) {
      for (std::size_t i = 0; i < 3; ++i) t.error_mm[t.Index(i, j)] = 1e-6 * std::pow(t.xs[i] - 175, 2);
    }
  }
  region.interpolation = cell::RegionInterpolation(c.robot, region.table);
  const GridAdvice advice = AdviseGrid(region.interpolation, region.tolerance_mm);
  ASSERT_TRUE(advice.coarse);
  EXPECT_DOUBLE_EQ(advice.pitch_mm, 5.9);
  plan = MakePlan(c, PlanOptions{}, diags);
  ASSERT_TRUE(plan) << diags.RenderText();
  EXPECT_DOUBLE_EQ(plan->regions[0].pitch_mm, 5);
  EXPECT_NE(plan->regions[0].pitch_reason.find("previous table previous.csv"), std::string::npos);
  // Without a declared roughness the same gentle table is fine at its own
  // curvature (2e-6 /mm: 0.16 µm mid-cell): its pitch again.
  c.robot.uncalibrated_accuracy_mm.reset();
  region.interpolation = cell::RegionInterpolation(c.robot, region.table);
  EXPECT_FALSE(AdviseGrid(region.interpolation, region.tolerance_mm).coarse);
  plan = MakePlan(c, PlanOptions{}, diags);
  ASSERT_TRUE(plan) << diags.RenderText();
  EXPECT_DOUBLE_EQ(plan->regions[0].pitch_mm, 25);
  EXPECT_NE(plan->regions[0].pitch_reason.find("its pitch again"), std::string::npos);
}

// Over random regions and pitches: the grid covers the bounds and the
// margin, its lines lie on the artefact's lattice, every point is a node or
// a check point strictly inside a cell, and every node is visited once per
// set with its number.
TEST(MeasurementPlan, GridsCoverTheirRegionsOnTheLattice) {
  const std::uint64_t seed = BaseSeed();
  std::mt19937_64 rng(seed);
  for (int round = 0; round < 60; ++round) {
    SCOPED_TRACE(fmt::format("seed {} round {}", seed, round));
    const auto device = round % 2 == 0 ? cell::MeasureDevice::kProbe : cell::MeasureDevice::kTransducer;
    const double x0 = Uniform(rng, 20, 200), y0 = Uniform(rng, 20, 150);
    cell::Cell c = TestCell(device, {x0, x0 + Uniform(rng, 5, 120)}, {y0, y0 + Uniform(rng, 5, 100)});
    PlanOptions options;
    options.pitch_mm = 5.0 * std::floor(Uniform(rng, 1, 6));
    options.sets = 2;
    options.repetitions = 3;
    SourceManager sources_diags;
    Diagnostics diags(sources_diags);
    std::optional<Plan> plan = MakePlan(c, options, diags);
    ASSERT_TRUE(plan) << diags.RenderText();
    const PlanRegion& r = plan->regions[0];
    EXPECT_LE(r.xs.front(), c.regions[0].x_mm.lo - r.margin_mm + 1e-9);
    EXPECT_GE(r.xs.back(), c.regions[0].x_mm.hi + r.margin_mm - 1e-9);
    EXPECT_LE(r.ys.front(), c.regions[0].y_mm.lo - r.margin_mm + 1e-9);
    EXPECT_GE(r.ys.back(), c.regions[0].y_mm.hi + r.margin_mm - 1e-9);
    for (std::size_t i = 1; i < r.xs.size(); ++i) EXPECT_NEAR(r.xs[i] - r.xs[i - 1], r.pitch_mm, 1e-9);
    EXPECT_NEAR(std::remainder(r.pitch_mm, 5.0), 0, 1e-9);  // grooves and holes are 5 mm apart
    std::map<int, Eigen::Vector2d> node_at;
    std::map<std::tuple<int, int, int>, int> visits_of;  // (node, axes, set)
    for (const Visit& v : plan->visits) {
      auto [it, fresh] = node_at.try_emplace(v.node, v.at);
      EXPECT_EQ(it->second, v.at) << "node " << v.node;
      if (v.kind == VisitKind::kNode || v.kind == VisitKind::kCheck) ++visits_of[{v.node, static_cast<int>(v.axes), v.set}];
      const bool on_x = std::find(r.xs.begin(), r.xs.end(), v.at.x()) != r.xs.end();
      const bool on_y = std::find(r.ys.begin(), r.ys.end(), v.at.y()) != r.ys.end();
      if (v.kind != VisitKind::kCheck) {
        EXPECT_TRUE(on_x && on_y);
      } else if (device == cell::MeasureDevice::kProbe) {
        EXPECT_FALSE(on_x || on_y);  // a cell's centre
      } else {
        // On a groove of the measured axis, between the lines of the other.
        EXPECT_EQ(on_x, v.axes == MeasuredAxes::kX);
        EXPECT_EQ(on_y, v.axes == MeasuredAxes::kY);
      }
    }
    for (const auto& [key, count] : visits_of) EXPECT_EQ(count, 1);
    const int runs = device == cell::MeasureDevice::kTransducer ? 2 : 1;
    int nodes = 0;
    for (const Visit& v : plan->visits) nodes += v.kind == VisitKind::kNode;
    EXPECT_EQ(nodes, r.nodes * runs * options.sets);
    // The transducer's plate reaches 10 groove pitches: every mounting's
    // nodes span at most 50 mm.
    if (device == cell::MeasureDevice::kTransducer) {
      std::map<std::pair<int, int>, std::pair<Eigen::Vector2d, Eigen::Vector2d>> span;
      for (const Visit& v : plan->visits) {
        auto [it, fresh] = span.try_emplace({static_cast<int>(v.axes), v.station}, v.at, v.at);
        it->second.first = it->second.first.cwiseMin(v.at);
        it->second.second = it->second.second.cwiseMax(v.at);
      }
      for (const auto& [key, box] : span) EXPECT_LE((box.second - box.first).maxCoeff(), 50 + 1e-9);
    }
  }
}

// The paper cell's regions with a plate of 18 x 18 holes: the markers'
// regions share a station with the layers they serve, a region wider than
// the plate is split over stations sharing a line, and ties join every
// station into one group; every set of a station ends at its first point.
TEST(MeasurementPlan, StationsOfThePaperCellAreTied) {
  cell::Cell c = TestCell(cell::MeasureDevice::kProbe, {150.5, 199.5}, {60.5, 109.5});
  auto region = [&](std::string name, cell::Interval x, cell::Interval y) {
    cell::Region r = c.regions[0];
    r.name = std::move(name);
    r.x_mm = x;
    r.y_mm = y;
    c.regions.push_back(r);
  };
  c.regions[0].name = "layer1";
  region("layer2", {205.5, 254.5}, {60.5, 109.5});
  region("layer3", {260.5, 309.5}, {60.5, 109.5});
  region("feeders", {155.5, 244.5}, {5.5, 29.5});
  region("marker1", {128, 152}, {31.5, 55.5});
  region("marker2", {314, 338}, {114.5, 138.5});
  c.measure->probe.holes = 18;
  c.measure->placement_deg = 0.1;
  PlanOptions options;
  options.pitch_mm = 5;
  options.sets = 1;
  options.repetitions = 1;
  SourceManager sources;
  Diagnostics diags(sources);
  std::optional<Plan> plan = MakePlan(c, options, diags);
  ASSERT_TRUE(plan) << diags.RenderText();
  // One group: a walk over the ties reaches every station.
  std::set<int> reached = {1}, frontier = {1};
  while (!frontier.empty()) {
    const int s = *frontier.begin();
    frontier.erase(frontier.begin());
    for (int t : plan->stations[static_cast<std::size_t>(s - 1)].tied_to) {
      if (reached.insert(t).second) frontier.insert(t);
    }
  }
  EXPECT_EQ(reached.size(), plan->stations.size());
  for (const PlanStation& station : plan->stations) {
    // The plate (85 mm) reaches every point of its station.
    EXPECT_LE((station.far - station.origin).maxCoeff(), 85 + 1e-9) << "station " << station.number;
  }
  // marker1 shares its station with layer1.
  bool shared = false;
  for (const PlanStation& station : plan->stations) {
    shared = shared || (station.regions.size() >= 2 &&
                        std::count(station.regions.begin(), station.regions.end(), std::size_t{0}) == 1 &&
                        std::count(station.regions.begin(), station.regions.end(), std::size_t{4}) == 1);
  }
  EXPECT_TRUE(shared);
  // One measuring program per station (the probe measures x and y
  // together): a station's regions never split it.
  const std::vector<VisitGroup> groups = GroupVisits(plan->visits);
  ASSERT_EQ(groups.size(), plan->stations.size());
  for (std::size_t g = 0; g < groups.size(); ++g) EXPECT_EQ(groups[g].station, static_cast<int>(g) + 1);
  // Every set of every station: its last visit is its first point again.
  std::map<int, std::vector<const Visit*>> of_station;
  for (const Visit& v : plan->visits) of_station[v.station].push_back(&v);
  for (const auto& [station, visits] : of_station) {
    EXPECT_EQ(visits.back()->kind, VisitKind::kClosure);
    EXPECT_EQ(visits.back()->node, visits.front()->node);
  }
  // The probe's clearances: a wall may be the robot's error, the plate's
  // placement and its turn over the station's diagonal off.
  EXPECT_GT(plan->probe_reach_mm, 0.5);
  EXPECT_LT(plan->probe_reach_mm, c.measure->probe.overtravel_mm - kProbeSafetyMarginMm);
}

TEST(MeasurementPlan, RefusesAnOvertravelShorterThanWhatTheCellDeclares) {
  cell::Cell c = TestCell(cell::MeasureDevice::kProbe, {150.5, 199.5}, {60.5, 109.5});
  c.measure->probe.overtravel_mm = 0.2;
  SourceManager sources;
  Diagnostics diags(sources);
  EXPECT_FALSE(MakePlan(c, PlanOptions{}, diags));
  EXPECT_NE(diags.RenderText().find("overtravel_mm = 0.2 mm is less than"), std::string::npos) << diags.RenderText();
}

TEST(MeasurementPlan, RefusesACellWithoutDeviceOrApproach) {
  cell::Cell c = TestCell(cell::MeasureDevice::kProbe, {150, 160}, {60, 70});
  c.robot.final_approach_mm.reset();
  SourceManager sources_diags;
  Diagnostics diags(sources_diags);
  EXPECT_FALSE(MakePlan(c, PlanOptions{}, diags));
  EXPECT_NE(diags.RenderText().find("final_approach_mm"), std::string::npos);
  c = TestCell(cell::MeasureDevice::kProbe, {150, 160}, {60, 70});
  c.measure.reset();
  SourceManager sources_diags2;
  Diagnostics diags2(sources_diags2);
  EXPECT_FALSE(MakePlan(c, PlanOptions{}, diags2));
}

// The probe's trips, made from a known smooth field as the controller would
// latch them (the stylus on the chord of the hole, the trip 0 to 1 servo
// period late), read back: the error at every node within half a period of
// travel and a curvature remainder of the truth.
TEST(MeasurementReading, ProbeErrorsAreTheFieldAtTheNodes) {
  const std::uint64_t seed = BaseSeed();
  std::mt19937_64 rng(seed);
  for (int round = 0; round < 20; ++round) {
    SCOPED_TRACE(fmt::format("seed {} round {}", seed, round));
    const double a[2] = {Uniform(rng, -0.15, 0.15), Uniform(rng, -0.15, 0.15)};
    const double g[4] = {Uniform(rng, -3e-3, 3e-3), Uniform(rng, -3e-3, 3e-3), Uniform(rng, -3e-3, 3e-3),
                         Uniform(rng, -3e-3, 3e-3)};
    const double amp = Uniform(rng, 0, 0.05), wave = Uniform(rng, 150, 400), phase = Uniform(rng, 0, 6);
    auto field = [&](int axis, double x, double y) {
      return a[axis] + g[2 * axis] * (x - 175) + g[2 * axis + 1] * (y - 85) +
             amp * std::sin(2 * M_PI * (axis == 0 ? x : y) / wave + phase);
    };
    cell::Cell c = TestCell(cell::MeasureDevice::kProbe, {150.5, 199.5}, {60.5, 109.5});
    const Eigen::Vector2d s(round % 2 == 0 ? 1 : -1, round % 3 == 0 ? -1 : 1);
    c.robot.final_approach_mm = 0.5 * s;
    c.robot.servo_period_s = 0.001;
    const cell::MeasureProbe& probe = c.measure->probe;
    const double radius = ProbeContactRadiusMm(probe);
    const double period_travel = probe.speed_mm_s * c.robot.servo_period_s;
    const std::vector<double> xs = {150, 160, 170, 180, 190, 200}, ys = {60, 70, 80, 90, 100, 110};
    std::vector<Reading> readings;
    for (double y : ys) {
      for (double x : xs) {
        for (int rep = 1; rep <= 2; ++rep) {
          Reading r;
          r.at = Eigen::Vector2d(x, y);
          r.repetition = rep;
          // x: the command t with t + dx(t, y) on the wall of the hole at
          // (x, y), the stylus off-centre by dy(t, y); then latched late.
          double t = x + s.x() * radius;
          for (int k = 0; k < 50; ++k) {
            const double off = field(1, t, y);
            t = x + s.x() * std::sqrt(radius * radius - off * off) - field(0, t, y);
          }
          r.a = t + s.x() * Uniform(rng, 0, period_travel);
          double u = y + s.y() * radius;
          for (int k = 0; k < 50; ++k) {
            const double off = field(0, x, u);
            u = y + s.y() * std::sqrt(radius * radius - off * off) - field(1, x, u);
          }
          r.b = u + s.y() * Uniform(rng, 0, period_travel);
          readings.push_back(r);
        }
      }
    }
    std::vector<std::string> notes;
    PlanRegion grid;
    grid.xs = xs;
    grid.ys = ys;
    std::vector<ReadingError> errors = ErrorsOfReadings(*c.measure, c.robot, {grid}, readings, {}, notes);
    ASSERT_EQ(errors.size(), 2 * readings.size());
    // The field's largest second derivative (its sinusoid's).
    const double curvature = amp * std::pow(2 * M_PI / wave, 2);
    const double pitch = xs[1] - xs[0];
    for (const ReadingError& e : errors) {
      const int axis = e.axis == TableAxis::X ? 0 : 1;
      const double truth = field(axis, e.at.x(), e.at.y());
      // Half a period of travel (the latency's spread); the latency's
      // share through the stylus's off-centre correction and the trip's
      // move to its node (a slope up to |off| / r, off under 0.3 mm, these
      // fields' largest error: taken as 0.45 / r, what seeds 1 to 400 need,
      // an empirical bound); and what the bilinear estimate misses of the
      // field's curvature when it moves an error from the trip to its node
      // (about f'' r h for pitch h and contact radius r).
      const double bound = 0.5 * period_travel + period_travel * 0.45 / radius + curvature * radius * pitch;
      EXPECT_NEAR(e.error_mm, truth, bound) << "at " << e.at.transpose();
    }
    EXPECT_EQ(notes.size(), 1u);
  }
}

TEST(MeasurementReading, TransducerAndExternal) {
  cell::Cell c = TestCell(cell::MeasureDevice::kTransducer, {150, 160}, {60, 70});
  c.measure->transducer.slope = -2;
  c.measure->transducer.zero_mm = 0.1;
  Reading r;
  r.axes = MeasuredAxes::kY;
  r.at = Eigen::Vector2d(150, 60);
  r.a = 1.0;
  r.b = 0.95;
  std::vector<std::string> notes;
  PlanRegion grid;
  grid.xs = {150, 160};
  grid.ys = {60, 70};
  std::vector<ReadingError> e = ErrorsOfReadings(*c.measure, c.robot, {grid}, {r}, {}, notes);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].axis, TableAxis::Y);
  EXPECT_DOUBLE_EQ(e[0].error_mm, ((1.0 - 0.95) - 0.1) / -2);
  c.measure->device = cell::MeasureDevice::kExternal;
  r.external = Eigen::Vector2d(150.012, 59.99);
  e = ErrorsOfReadings(*c.measure, c.robot, {grid}, {r}, {}, notes);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NEAR(e[0].error_mm, 0.012, 1e-12);
  EXPECT_NEAR(e[1].error_mm, -0.01, 1e-12);
}

TEST(MeasurementReading, PlanDigestIsFnv1aStyle) {
  // The project's FNV-1a constants (frontend/cad/cad_to_program.cpp's too):
  // the empty text gives the offset basis.
  EXPECT_EQ(PlanDigest(""), "14650fb0739d0383");
  EXPECT_NE(PlanDigest("a"), PlanDigest("b"));
}

}  // namespace
}  // namespace smtcal::measure
