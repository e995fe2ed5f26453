// The scan design report (scan_report.h). The numbers come from the
// calibration layer: ScanTime and ScanCaptureRange (calibration/scan_plan.h)
// and FixtureErrorModel (calibration/placement_budget.h), with the fixture's
// estimator swapped for each row of the estimator table. The picture is
// plain SVG 1.1, coordinates with 2 decimals: deterministic.
#include "backend/reports/scan_report.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "backend/reports/svg_text.h"
#include "base/field_text.h"
#include "base/json_text.h"
#include "calibration/fixture_geometry.h"
#include "calibration/placement_budget.h"

namespace smtcal {
namespace {

constexpr std::array<ErrorSource, 5> kScanSources = {ErrorSource::kSensor, ErrorSource::kScanRepeatability,
                                                     ErrorSource::kLatency, ErrorSource::kTripTables,
                                                     ErrorSource::kUncalibratedTrips};

// The scan's part of a placement's error: the sources that come from the trips.
ErrorShare ScanShare(const ErrorBudget& budget) {
  ErrorShare share;
  for (ErrorSource source : kScanSources) share += budget[source];
  if (!budget.bounded) share.bound_mm = share.worst_mm = std::numeric_limits<double>::infinity();
  return share;
}

std::string Fixed(double value, int decimals) {
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos && text.front() == '-') text.erase(0, 1);
  return text;
}

std::string Num(double value) { return fmt::format("{}", value); }

std::vector<ScanReportPoint> BoardGrid(const cell::Fixture& fixture) {
  std::vector<ScanReportPoint> points;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 5; ++i) {
      const Eigen::Vector2d f(fixture.l1_mm * i / 4, fixture.l2_mm * j / 2);
      points.push_back({fmt::format("({}, {})", Num(f.x()), Num(f.y())), f});
    }
  }
  return points;
}

// What to change where the drawn layout is weak.
std::vector<std::string> Suggestions(const cell::Cell& cell, const cell::Fixture& fixture, const ScanReport& report) {
  std::vector<std::string> out;
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const double rotation = fixture.max_rotation_deg * kRadPerDeg;
  if (report.capture.factor < 1) {
    out.push_back(fmt::format(
        "the paths measure boards within {} mm and {} deg of nominal only ({}), but the limits accept {} mm and "
        "{} deg: draw every leg across its edge at nearly a right angle and through the edge's middle",
        Fixed(report.capture.shift_mm, 2), Fixed(report.capture.rotation_deg, 3), report.capture.limited_by,
        Num(fixture.max_shift_mm), Num(fixture.max_rotation_deg)));
  }
  for (std::size_t k = 0; k < expected.size(); ++k) {
    // How far a board at the limits moves trip k along its edge.
    const double moves = fixture.max_shift_mm + rotation * expected[k].in_fixture.norm();
    const double along = moves / std::max(1e-9, std::sin(report.trip_angle_deg[k] * kRadPerDeg));
    if (report.trip_edge_margin_mm[k] < along) {
      const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(expected[k].edge)];
      out.push_back(fmt::format(
          "{} lies {} mm from an end of edge {}, but a board at the limits moves it up to {} mm along the edge "
          "(its leg crosses the edge at {} deg): move it towards the edge's middle ({} mm from either end) or "
          "cross the edge more steeply",
          TripName(k), Fixed(report.trip_edge_margin_mm[k], 2), edge.name, Fixed(along, 2),
          Fixed(report.trip_angle_deg[k], 1), Fixed((edge.to - edge.from).norm() / 2, 2)));
    }
  }
  // Eq. 4 extrapolates each edge from its own trips.
  const ScanReportEstimator* paper = nullptr;
  for (const ScanReportEstimator& e : report.estimators) {
    if (e.estimator == cell::Estimator::kPaper) paper = &e;
  }
  const double tolerance = cell.regions.empty() ? 0.1 : cell.regions.front().tolerance_mm;
  if (fixture.estimator == cell::Estimator::kPaper && paper != nullptr && paper->worst_mm > tolerance / 2) {
    for (std::size_t e = 0; e < fixture.edges.size(); ++e) {
      double lo = 1e300, hi = -1e300;
      for (const ExpectedTrip& trip : expected) {
        if (trip.edge != static_cast<int>(e)) continue;
        const cell::MarkerEdge& edge = fixture.edges[e];
        const double u = (trip.in_fixture - edge.from).dot((edge.to - edge.from).normalized());
        lo = std::min(lo, u);
        hi = std::max(hi, u);
      }
      const double spread = hi - lo, lever = std::max(fixture.l1_mm, fixture.l2_mm);
      out.push_back(fmt::format(
          "edge {}'s trips are {} mm apart and Eq. 4 extrapolates its line {} mm: the sensor's +-{} mm moves "
          "the far crossing by up to {} mm; spread them along longer edges, or use estimator = \"rigid\"",
          fixture.edges[e].name, Fixed(spread, 2), Num(lever), Num(fixture.sensor_accuracy_mm),
          Fixed(spread > 0 ? 2 * fixture.sensor_accuracy_mm * lever / spread : 1e9, 2)));
    }
  }
  if (fixture.latch_speed_mm_s == 0 && report.timing.search_s > 1) {
    out.push_back(fmt::format(
        "every trip is latched at the scan speed, {} mm/s, so the legs take {} s: probe in two stages "
        "(latch_speed_mm_s, e.g. a search at 40 mm/s and a latch at 8 mm/s: the latch's latency alone counts)",
        Num(fixture.scan_speed_mm_s), Fixed(report.timing.search_s, 2)));
  }
  if (report.latency_mm > 0.25 * fixture.sensor_accuracy_mm) {
    out.push_back(fmt::format("a trip is latched up to {} mm late, more than a quarter of the sensor's +-{} mm: "
                              "latch slower",
                              Fixed(report.latency_mm, 4), Num(fixture.sensor_accuracy_mm)));
  }
  // Legs that start farther before their first edge than the capture needs.
  const Eigen::Affine3d nominal = NominalFix(fixture);
  for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
    for (const ExpectedTrip& trip : expected) {
      if (trip.path != p) continue;
      const bool first_on_leg = &trip == &*std::find_if(expected.begin(), expected.end(), [&](const ExpectedTrip& t) {
        return t.path == trip.path && t.leg == trip.leg;
      });
      if (!first_on_leg || trip.leg != 0) continue;
      const double moves = fixture.max_shift_mm + rotation * ToBase(nominal, trip.in_fixture).norm();
      const std::size_t k = static_cast<std::size_t>(&trip - expected.data());
      const double needs = moves / std::max(1e-9, std::sin(report.trip_angle_deg[k] * kRadPerDeg)) + 0.5;
      if (trip.along_mm > needs + 1) {
        out.push_back(fmt::format("scan path '{}' starts {} mm before {}, the capture range needs about {} mm: "
                                  "start it closer and the search is shorter",
                                  fixture.scan_paths[p].name, Fixed(trip.along_mm, 2), TripName(k), Fixed(needs, 2)));
      }
    }
  }
  return out;
}

// One row of the estimator table: `fixture`'s pose from its nominal trips
// with its estimator, and the scan's part of the budget at `points` (their
// regions and tolerances filled).
ScanReportEstimator EstimatorRow(const cell::Cell& cell, const cell::Fixture& fixture,
                                 const std::vector<Eigen::Vector2d>& table_noise,
                                 const std::vector<ScanReportPoint>& points,
                                 const std::vector<ScanPointRegion>& regions) {
  const FixtureErrorModel model(cell, fixture, table_noise);
  ScanReportEstimator row;
  row.estimator = fixture.estimator;
  row.defined = model.defined();
  if (!row.defined) return row;
  const Eigen::Matrix3d covariance = model.PoseCovariance();
  row.sigma = covariance.diagonal().cwiseMax(0).cwiseSqrt();
  row.sigma.z() *= kDegPerRad;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ScanReportPoint& point = points[i];
    const double budget = ScanShare(model.At(point.in_fixture, nullptr, 0)).BudgetMm();
    if (budget > row.worst_mm || row.worst_at.empty()) {
      row.worst_mm = budget;
      row.worst_at = point.name;
    }
    if (regions[i].tolerance_mm <= 0) continue;
    const double share = budget / regions[i].tolerance_mm;
    if (share > row.worst_share) {
      row.worst_share = share;
      row.worst_share_at = fmt::format("{} in region {}", point.name, regions[i].region);
    }
  }
  return row;
}

// "T1, T4" or "T1..T4" for consecutive trips.
std::string TripList(const std::vector<std::size_t>& trips) {
  bool consecutive = trips.size() > 2;
  for (std::size_t i = 1; i < trips.size(); ++i) consecutive = consecutive && trips[i] == trips[i - 1] + 1;
  if (consecutive) return fmt::format("{}..{}", TripName(trips.front()), TripName(trips.back()));
  std::string text;
  for (std::size_t k : trips) text += (text.empty() ? "" : ", ") + TripName(k);
  return text;
}

// A share of the tolerance: "75 %", or "1867x" from ten times up.
std::string Percent(double share) {
  return share < 10 ? fmt::format("{:.0f} %", 100 * share) : fmt::format("{:.0f}x", share);
}

// A copy of `region` with its table (and so its bounds) moved by `move`.
cell::Region Moved(const cell::Region& region, const Eigen::Vector2d& move) {
  cell::Region moved = region;
  for (AxisTable& axis : moved.table.axes) {
    for (double& x : axis.xs) x += move.x();
    for (double& y : axis.ys) y += move.y();
    for (TableNode& check : axis.checks) {
      check.x_mm += move.x();
      check.y_mm += move.y();
    }
  }
  moved.domain = TableDomain(moved.table);
  moved.x_mm = {region.x_mm.lo + move.x(), region.x_mm.hi + move.x()};
  moved.y_mm = {region.y_mm.lo + move.y(), region.y_mm.hi + move.y()};
  return moved;
}

// Changes that take kWorthwhileShareCut or more off the fixture's
// estimator's worst share of the tolerance, each tried on a copy of the cell:
// a region under the trips no table calibrates (a copy of the region that
// calibrates the fixture's other trips, its table moved under them), each
// other estimator, and the markers and their paths spread farther about S1.
std::vector<ScanSuggestion> ToleranceSuggestions(const cell::Cell& cell, const cell::Fixture& fixture,
                                                 const ScanReport& report) {
  std::vector<ScanSuggestion> out;
  const ScanReportEstimator* current = nullptr;
  for (const ScanReportEstimator& e : report.estimators) {
    if (e.estimator == fixture.estimator) current = &e;
  }
  if (current == nullptr || !current->defined || current->worst_share <= 0 || !std::isfinite(current->worst_share)) {
    return out;
  }
  const double before = current->worst_share;
  auto worth = [&](double after) { return after <= before * (1 - kWorthwhileShareCut); };
  const std::string tolerance_text = fmt::format("of the tolerance at {}", current->worst_share_at);

  // 1. A table under the trips no table calibrates, one per scan path.
  const std::vector<int> regions = TripRegions(fixture, cell.regions);
  const std::vector<TripWindow> windows = TripWindows(fixture);
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  const cell::Region* model_region = nullptr;  // the region calibrating another trip, else the first with a table
  for (int r : regions) {
    if (r >= 0 && model_region == nullptr) model_region = &cell.regions[static_cast<std::size_t>(r)];
  }
  for (const cell::Region& region : cell.regions) {
    if (model_region == nullptr && region.has_table) model_region = &region;
  }
  if (model_region != nullptr) {
    cell::Cell calibrated = cell;
    std::vector<std::string> where;
    for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
      std::vector<std::size_t> trips;
      Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
      for (std::size_t k = 0; k < expected.size(); ++k) {
        if (expected[k].path != p || regions[k] >= 0) continue;
        trips.push_back(k);
        for (const Eigen::Vector2d& q : {windows[k].from, windows[k].to}) {
          lo = lo.cwiseMin(q);
          hi = hi.cwiseMax(q);
        }
      }
      if (trips.empty()) continue;
      // The model region's table, moved so its domain is centred on the windows.
      const Rect& domain = model_region->domain;
      cell::Region added = Moved(*model_region, (lo + hi) / 2 - Eigen::Vector2d((domain.x0 + domain.x1) / 2,
                                                                                (domain.y0 + domain.y1) / 2));
      added.name = fmt::format("under scan path '{}'", fixture.scan_paths[p].name);
      calibrated.regions.push_back(std::move(added));
      where.push_back(fmt::format("{} of scan path '{}' (x {:.1f}..{:.1f}, y {:.1f}..{:.1f} mm)", TripList(trips),
                                  fixture.scan_paths[p].name, lo.x(), hi.x(), lo.y(), hi.y()));
    }
    if (!where.empty()) {
      const ScanReportEstimator row = EstimatorRow(calibrated, fixture, RegionTableNoise(calibrated), report.points, report.point_regions);
      if (row.defined && worth(row.worst_share)) {
        out.push_back({fmt::format("calibrate a region under {}, as region '{}' is measured: the trips then take the "
                                   "robot's error from a table instead of up to its uncalibrated accuracy",
                                   fmt::join(where, " and "), model_region->name),
                       before, row.worst_share});
      }
    }
  }

  // 2. Another estimator.
  for (const ScanReportEstimator& e : report.estimators) {
    if (&e == current || !e.defined || e.worst_share < 0 || !worth(e.worst_share)) continue;
    out.push_back({fmt::format("estimator = \"{}\"", cell::EstimatorName(e.estimator)), before, e.worst_share});
  }

  // 3. A longer baseline: the markers and their paths spread about S1 (the
  // board's points stay), as far as the robot's travel allows; each region
  // that calibrates trips moved with them.
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const std::vector<Eigen::Vector2d> trips_now = NominalTrips(fixture, nominal);
  for (double factor : {2.0, 1.5, 1.25}) {
    cell::Fixture spread = fixture;
    spread.l1_mm *= factor;
    spread.l2_mm *= factor;
    for (cell::MarkerEdge& edge : spread.edges) {
      edge.from *= factor;
      edge.to *= factor;
    }
    bool reachable = true;
    for (cell::ScanPath& path : spread.scan_paths) {
      for (Eigen::Vector2d& q : path.points) {
        q *= factor;
        const Eigen::Vector2d base = ToBase(nominal, q);
        reachable = reachable && cell.robot.limits[0].Contains(base.x()) && cell.robot.limits[1].Contains(base.y());
      }
    }
    if (!reachable) continue;
    cell::Cell moved_cell = cell;
    const std::vector<Eigen::Vector2d> trips_then = NominalTrips(spread, nominal);
    for (std::size_t r = 0; r < cell.regions.size(); ++r) {
      Eigen::Vector2d move = Eigen::Vector2d::Zero();
      int n = 0;
      for (std::size_t k = 0; k < regions.size(); ++k) {
        if (regions[k] != static_cast<int>(r)) continue;
        move += trips_then[k] - trips_now[k];
        ++n;
      }
      if (n > 0) moved_cell.regions[r] = Moved(cell.regions[r], move / n);
    }
    const ScanReportEstimator row = EstimatorRow(moved_cell, spread, RegionTableNoise(moved_cell), report.points, report.point_regions);
    if (row.defined && worth(row.worst_share)) {
      out.push_back({fmt::format("a longer baseline: the markers and their scan paths {} x as far from S1 (L1 {} mm, "
                                 "L2 {} mm), still within the robot's travel, with their trips calibrated as now",
                                 factor, Num(spread.l1_mm), Num(spread.l2_mm)),
                     before, row.worst_share});
    }
    break;  // the longest spread that fits is the one to say
  }
  for (ScanSuggestion& s : out) {
    s.change += fmt::format(": the {} estimator's worst share {} would fall from {} to {}",
                            cell::EstimatorName(fixture.estimator), tolerance_text, Percent(s.share_before),
                            Percent(s.share_after));
  }
  return out;
}

}  // namespace

ScanReport MakeScanReport(const cell::Cell& cell, const cell::Fixture& fixture, std::vector<ScanReportPoint> points,
                          const std::optional<ScanPoint>& from) {
  ScanReport report;
  report.cell_name = cell.name;
  report.fixture = &fixture;
  report.timing = ScanTime(cell.robot, fixture, from);
  report.predicted = ScanTime(cell.robot, fixture, from, ScanSearch::kPredicted);
  report.floor = ScanFloor(cell.robot, fixture, from);
  report.timed_from_program = from.has_value();
  report.capture = ScanCaptureRange(fixture);
  report.latency_mm = fixture.TripLatchSpeedMmS() * cell.robot.servo_period_s;
  report.points = points.empty() ? BoardGrid(fixture) : std::move(points);
  // Each point's region and tolerance, at the fixture's nominal pose; a
  // region under the trips is where the scan is measured, not a placing
  // area, and gives no tolerance to share.
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const std::vector<int> trip_regions = TripRegions(fixture, cell.regions);
  for (const ScanReportPoint& point : report.points) {
    const cell::Region* region = cell.RegionAt(ToBase(nominal, point.in_fixture));
    const bool under_trips =
        region != nullptr && std::find(trip_regions.begin(), trip_regions.end(),
                                       static_cast<int>(region - cell.regions.data())) != trip_regions.end();
    report.point_regions.push_back(region == nullptr || under_trips ? ScanPointRegion{}
                                                                    : ScanPointRegion{region->name, region->tolerance_mm});
  }
  const std::vector<Eigen::Vector2d> table_noise = RegionTableNoise(cell);
  for (cell::Estimator estimator : {cell::Estimator::kPaper, cell::Estimator::kRigid, cell::Estimator::kRigidScale}) {
    cell::Fixture variant = fixture;
    variant.estimator = estimator;
    const ScanReportEstimator row = EstimatorRow(cell, variant, table_noise, report.points, report.point_regions);
    report.estimators.push_back(row);
    if (estimator != fixture.estimator || !row.defined) continue;
    const FixtureErrorModel model(cell, variant, table_noise);
    for (const ScanReportPoint& point : report.points) {
      const ErrorShare share = ScanShare(model.At(point.in_fixture, nullptr, 0));
      report.point_mean_mm.push_back(share.mean_mm);
      report.point_covariance_mm2.push_back(share.covariance_mm2);
      report.point_budget_mm.push_back(share.BudgetMm());
    }
  }
  for (const ExpectedTrip& trip : ExpectedTrips(fixture)) {
    const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(trip.edge)];
    const Eigen::Vector2d along = edge.to - edge.from;
    const double u = (trip.in_fixture - edge.from).dot(along) / along.squaredNorm();
    report.trip_edge_margin_mm.push_back(std::min(u, 1 - u) * along.norm());
    const double cosine = std::abs(trip.leg_direction.dot(along.normalized()));
    report.trip_angle_deg.push_back(std::acos(std::clamp(cosine, 0.0, 1.0)) * kDegPerRad);
  }
  for (int r : TripRegions(fixture, cell.regions)) {
    report.trip_table.push_back(r < 0 ? std::string() : cell.regions[static_cast<std::size_t>(r)].name);
  }
  report.suggestions = Suggestions(cell, fixture, report);
  report.tolerance_suggestions = ToleranceSuggestions(cell, fixture, report);
  for (const ScanSuggestion& s : report.tolerance_suggestions) report.suggestions.push_back(s.change);
  return report;
}

std::string ScanReportText(const ScanReport& report) {
  const cell::Fixture& fixture = *report.fixture;
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  std::string out = fmt::format("fixture '{}' of cell '{}': {} trips on {} scan path(s), estimator {}\n",
                                fixture.name, report.cell_name, expected.size(), fixture.scan_paths.size(),
                                cell::EstimatorName(fixture.estimator));
  out += fixture.latch_speed_mm_s > 0
             ? fmt::format("  two stages: each edge found at {} mm/s, crossed back and latched at {} mm/s\n",
                           Num(fixture.scan_speed_mm_s), Num(fixture.latch_speed_mm_s))
             : fmt::format("  one stage: every trip latched at the scan speed, {} mm/s\n", Num(fixture.scan_speed_mm_s));
  const ScanTiming& t = report.timing;
  out += fmt::format("time: {} s {} (jumps {} s, searches and the rest of the legs {} s, latches {} s, {} probe "
                     "moves x {} s)\n",
                     Fixed(t.seconds, 2),
                     report.timed_from_program ? "from where the program's cycle ends" : "from the first path's start",
                     Fixed(t.travel_s, 2), Fixed(t.search_s, 2), Fixed(t.latch_s, 2), t.probe_moves,
                     Fixed(t.probe_moves > 0 ? t.turnaround_s / t.probe_moves : 0, 3));
  const ScanTiming& f = report.floor;
  if (fixture.predicted_window_mm > 0) {
    const ScanTiming& p = report.predicted;
    out += fmt::format("  every cycle after the first, each trip latched within +-{} mm of where the last scan puts "
                       "it: {} s (jumps {} s, moves between trips {} s, latches {} s, {} probe moves); a path whose "
                       "trip is not there is searched in full\n",
                       Num(fixture.predicted_window_mm), Fixed(p.seconds, 2), Fixed(p.travel_s, 2),
                       Fixed(p.search_s, 2), Fixed(p.latch_s, 2), p.probe_moves);
  }
  out += fmt::format("  floor: {} s (jumps {} s, one latch a trip {} s, {} turnarounds), the moves between a path's "
                     "trips left out; the scan is {} x it{}\n",
                     Fixed(f.seconds, 2), Fixed(f.travel_s, 2), Fixed(f.latch_s, 2), f.probe_moves,
                     Fixed(f.seconds > 0 ? t.seconds / f.seconds : 0, 2),
                     fixture.predicted_window_mm > 0
                         ? fmt::format(" in full, {} x predicted",
                                       Fixed(f.seconds > 0 ? report.predicted.seconds / f.seconds : 0, 2))
                         : std::string());
  const CaptureRange& c = report.capture;
  out += fmt::format("capture range: boards within {} mm and {} deg of nominal, {} x the limits ({} mm, {} deg){}\n",
                     Fixed(c.shift_mm, 2), Fixed(c.rotation_deg, 3), Fixed(c.factor, 2), Num(fixture.max_shift_mm),
                     Num(fixture.max_rotation_deg),
                     c.factor >= 1 ? ": every board the checks accept is measured" : ": SMALLER than the limits");
  if (!c.limited_by.empty()) out += fmt::format("  beyond it: {}\n", c.limited_by);
  out += "trips (fixture frame): edge, crossing, leg's angle to the edge, distance from the edge's nearer end, "
         "the table that calibrates it\n";
  std::vector<std::size_t> uncalibrated;
  for (std::size_t k = 0; k < expected.size(); ++k) {
    if (report.trip_table[k].empty()) uncalibrated.push_back(k);
    out += fmt::format("  {:<4} {}  ({}, {})  {} deg  {} mm  {}\n", TripName(k),
                       fixture.edges[static_cast<std::size_t>(expected[k].edge)].name,
                       Fixed(expected[k].in_fixture.x(), 3), Fixed(expected[k].in_fixture.y(), 3),
                       Fixed(report.trip_angle_deg[k], 1), Fixed(report.trip_edge_margin_mm[k], 2),
                       report.trip_table[k].empty() ? std::string("NONE: outside every table")
                                                    : "region " + report.trip_table[k]);
  }
  if (!uncalibrated.empty()) {
    out += fmt::format("  {} outside every table: used as commanded, so the robot's own error there is in every "
                       "estimator's figure below\n",
                       uncalibrated.size() == 1 ? TripName(uncalibrated.front()) + " lies"
                                                : TripList(uncalibrated) + " lie");
  }
  out += fmt::format("latency: a trip is latched 0 to {} mm past its edge (the latch feed {} mm/s x the servo "
                     "period)\n",
                     Fixed(report.latency_mm, 4), Num(fixture.TripLatchSpeedMmS()));
  out += "pose per estimator, 1 sigma from the sensor, the repeatability at the trips, the latency and the tables\n"
         "under the trips; the scan's part of a placement's error at 4 sigma, worst over the points, and as a\n"
         "share of the point's tolerance (its region's), worst over the points in a region:\n";
  out += "  estimator     sigma x mm  sigma y mm  sigma angle deg  worst mm  share  at\n";
  for (const ScanReportEstimator& e : report.estimators) {
    const std::string name =
        fmt::format("{}{}", cell::EstimatorName(e.estimator), e.estimator == fixture.estimator ? " *" : "");
    if (!e.defined) {
      out += fmt::format("  {:<13} (the nominal trips give it no pose)\n", name);
      continue;
    }
    // An unbounded source (a trip where no table and no uncalibrated
    // accuracy bounds the robot's error) bounds nothing at any point.
    const bool bounded = std::isfinite(e.worst_mm);
    const bool shared = bounded && e.worst_share >= 0;
    out += fmt::format("  {:<13} {:>10}  {:>10}  {:>15}  {:>8}  {:>5}  {}\n", name, Fixed(e.sigma.x(), 4),
                       Fixed(e.sigma.y(), 4), Fixed(e.sigma.z(), 5), bounded ? Fixed(e.worst_mm, 4) : "unbounded",
                       shared ? Percent(e.worst_share) : "-",
                       !bounded  ? std::string("everywhere (`smtcal verify` names the source)")
                       : shared && e.worst_share_at.find(e.worst_at + " in region") != 0
                           ? fmt::format("{}; share at {}", e.worst_at, e.worst_share_at)
                       : shared ? e.worst_share_at
                                : e.worst_at + " (in no region: no tolerance)");
  }
  out += "  (* the fixture's estimator)\n";
  // The fixture's estimator at every point in a region: how the shares spread.
  std::vector<double> shares;
  for (std::size_t i = 0; i < report.point_budget_mm.size(); ++i) {
    const double tolerance = report.point_regions[i].tolerance_mm;
    if (tolerance > 0) shares.push_back(report.point_budget_mm[i] / tolerance);
  }
  if (!shares.empty() && std::all_of(shares.begin(), shares.end(), [](double s) { return std::isfinite(s); })) {
    std::sort(shares.begin(), shares.end());
    const std::size_t over = static_cast<std::size_t>(std::count_if(shares.begin(), shares.end(), [](double s) { return s > 1; }));
    out += fmt::format("the {} estimator's share of the tolerance at the {} point{} in a region: {} to {}, half of "
                       "them above {}{}\n",
                       cell::EstimatorName(fixture.estimator), shares.size(), shares.size() == 1 ? "" : "s",
                       Percent(shares.front()), Percent(shares.back()), Percent(shares[shares.size() / 2]),
                       over == 0 ? std::string()
                                 : fmt::format("; at {} of them the scan alone takes more than the whole tolerance", over));
  }
  if (report.suggestions.empty()) {
    out += "suggestions: none: the layout measures every board the limits accept, and no change tried (a table "
           "under the trips, another estimator, a longer baseline) takes 10 % of the scan's worst share of the "
           "tolerance off\n";
  } else {
    out += "suggestions:\n";
    for (const std::string& s : report.suggestions) out += fmt::format("  - {}\n", s);
  }
  return out;
}

std::string ScanReportJson(const ScanReport& report) {
  using nlohmann::ordered_json;
  const cell::Fixture& fixture = *report.fixture;
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  ordered_json out;
  out["cell"] = report.cell_name;
  out["fixture"] = fixture.name;
  out["stages"] = fixture.latch_speed_mm_s > 0 ? 2 : 1;
  out["scan_speed_mm_s"] = fixture.scan_speed_mm_s;
  out["latch_speed_mm_s"] = fixture.TripLatchSpeedMmS();
  const ScanTiming& t = report.timing;
  auto s4 = [](double v) { return RoundedToDecimals(v, 4); };
  out["time"] = {{"seconds", s4(t.seconds)},   {"from_program", report.timed_from_program},
                 {"travel_s", s4(t.travel_s)}, {"search_s", s4(t.search_s)},
                 {"latch_s", s4(t.latch_s)},   {"turnaround_s", s4(t.turnaround_s)},
                 {"probe_moves", t.probe_moves}};
  const ScanTiming& p = report.predicted;
  out["time"]["predicted"] = {{"window_mm", fixture.predicted_window_mm}, {"seconds", s4(p.seconds)},
                              {"travel_s", s4(p.travel_s)},              {"between_trips_s", s4(p.search_s)},
                              {"latch_s", s4(p.latch_s)},                {"turnaround_s", s4(p.turnaround_s)},
                              {"probe_moves", p.probe_moves}};
  const ScanTiming& f = report.floor;
  out["time"]["floor"] = {{"seconds", s4(f.seconds)},     {"travel_s", s4(f.travel_s)},
                          {"latch_s", s4(f.latch_s)},     {"turnaround_s", s4(f.turnaround_s)},
                          {"ratio_full", RoundedToDecimals(f.seconds > 0 ? t.seconds / f.seconds : 0, 3)},
                          {"ratio_predicted", RoundedToDecimals(f.seconds > 0 ? p.seconds / f.seconds : 0, 3)}};
  out["capture"] = {{"factor", s4(report.capture.factor)},
                    {"shift_mm", s4(report.capture.shift_mm)},
                    {"rotation_deg", RoundedToDecimals(report.capture.rotation_deg, 5)},
                    {"covers_limits", report.capture.factor >= 1},
                    {"limited_by", report.capture.limited_by}};
  out["latency_mm"] = RoundedToDecimals(report.latency_mm, 6);
  out["trips"] = ordered_json::array();
  for (std::size_t k = 0; k < expected.size(); ++k) {
    out["trips"].push_back({{"name", TripName(k)},
                            {"edge", fixture.edges[static_cast<std::size_t>(expected[k].edge)].name},
                            {"x_mm", expected[k].in_fixture.x()},
                            {"y_mm", expected[k].in_fixture.y()},
                            {"angle_to_edge_deg", RoundedToDecimals(report.trip_angle_deg[k], 3)},
                            {"edge_end_mm", RoundedToDecimals(report.trip_edge_margin_mm[k], 4)},
                            {"table", report.trip_table[k].empty() ? ordered_json() : ordered_json(report.trip_table[k])}});
  }
  out["estimators"] = ordered_json::array();
  for (const ScanReportEstimator& e : report.estimators) {
    ordered_json row = {{"estimator", cell::EstimatorName(e.estimator)},
                        {"fixture_estimator", e.estimator == fixture.estimator},
                        {"defined", e.defined}};
    if (e.defined) {
      row["sigma_x_mm"] = RoundedToDecimals(e.sigma.x(), 6);
      row["sigma_y_mm"] = RoundedToDecimals(e.sigma.y(), 6);
      row["sigma_angle_deg"] = RoundedToDecimals(e.sigma.z(), 7);
      if (std::isfinite(e.worst_mm)) {
        row["worst_mm"] = RoundedToDecimals(e.worst_mm, 6);
        row["worst_at"] = e.worst_at;
      } else {
        row["worst_mm"] = nullptr;  // unbounded
        row["worst_at"] = nullptr;
      }
      const bool shared = std::isfinite(e.worst_share) && e.worst_share >= 0;
      row["worst_share_of_tolerance"] = shared ? ordered_json(RoundedToDecimals(e.worst_share, 4)) : ordered_json();
      row["worst_share_at"] = shared ? ordered_json(e.worst_share_at) : ordered_json();
    }
    out["estimators"].push_back(row);
  }
  out["points"] = ordered_json::array();
  for (std::size_t i = 0; i < report.point_budget_mm.size(); ++i) {
    const ScanReportPoint& point = report.points[i];
    const ScanPointRegion& where = report.point_regions[i];
    const bool shared = where.tolerance_mm > 0 && std::isfinite(report.point_budget_mm[i]);
    out["points"].push_back(
        {{"name", point.name},
         {"x_mm", point.in_fixture.x()},
         {"y_mm", point.in_fixture.y()},
         {"budget_mm", RoundedToDecimals(report.point_budget_mm[i], 6)},
         {"region", where.region.empty() ? ordered_json() : ordered_json(where.region)},
         {"tolerance_mm", where.tolerance_mm > 0 ? ordered_json(where.tolerance_mm) : ordered_json()},
         {"share_of_tolerance",
          shared ? ordered_json(RoundedToDecimals(report.point_budget_mm[i] / where.tolerance_mm, 4)) : ordered_json()}});
  }
  out["suggestions"] = report.suggestions;
  out["tolerance_suggestions"] = ordered_json::array();
  for (const ScanSuggestion& s : report.tolerance_suggestions) {
    out["tolerance_suggestions"].push_back({{"change", s.change},
                                            {"worst_share_before", RoundedToDecimals(s.share_before, 4)},
                                            {"worst_share_after", RoundedToDecimals(s.share_after, 4)}});
  }
  return JsonText(out);
}

// ------------------------------------------------------------------ the picture

namespace {

std::string P(double v) {
  std::string text = fmt::format("{:.2f}", v);
  return text == "-0.00" ? "0.00" : text;
}

// A tick label: no "-0".
std::string TickLabel(double v) { return Num(std::abs(v) < 1e-9 ? 0.0 : v); }

// A panel: fixture coordinates [x0, x1] x [y0, y1] drawn into a rectangle of
// the picture, y up.
struct Panel {
  double x0, y0, x1, y1;        // fixture mm
  double left, top, scale;      // picture px
  double X(double x) const { return left + (x - x0) * scale; }
  double Y(double y) const { return top + (y1 - y) * scale; }
  double width() const { return (x1 - x0) * scale; }
  double height() const { return (y1 - y0) * scale; }
};

std::string Axes(const Panel& p, int ticks) {
  std::string out = fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#fbfbfb\" "
                                "stroke=\"#888\"/>\n",
                                P(p.left), P(p.top), P(p.width()), P(p.height()));
  const double step_x = SvgTickStep(p.x1 - p.x0, ticks), step_y = SvgTickStep(p.y1 - p.y0, ticks);
  for (double x : SvgTicks(p.x0, p.x1, step_x)) {
    out += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#888\"/>"
                       "<text x=\"{0}\" y=\"{3}\" font-size=\"11\" text-anchor=\"middle\">{4}</text>\n",
                       P(p.X(x)), P(p.top + p.height()), P(p.top + p.height() + 4), P(p.top + p.height() + 16),
                       TickLabel(x));
  }
  for (double y : SvgTicks(p.y0, p.y1, step_y)) {
    out += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#888\"/>"
                       "<text x=\"{3}\" y=\"{4}\" font-size=\"11\" text-anchor=\"end\">{5}</text>\n",
                       P(p.left - 4), P(p.Y(y)), P(p.left), P(p.left - 6), P(p.Y(y) + 4), TickLabel(y));
  }
  return out;
}

std::string Edges(const Panel& p, const cell::Fixture& fixture, double label_size) {
  std::string out;
  for (const cell::MarkerEdge& edge : fixture.edges) {
    out += fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#000\" stroke-width=\"3\"/>\n",
                       P(p.X(edge.from.x())), P(p.Y(edge.from.y())), P(p.X(edge.to.x())), P(p.Y(edge.to.y())));
    if (label_size > 0) {
      const Eigen::Vector2d mid = (edge.from + edge.to) / 2;
      const EdgeLine line = EdgeLineOf(edge);
      out += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"middle\" fill=\"#000\">{}</text>\n",
                         P(p.X(mid.x()) + 14 * line.normal.x()), P(p.Y(mid.y()) - 14 * line.normal.y() + 4),
                         Num(label_size), SvgEscape(edge.name));
    }
  }
  return out;
}

std::string Paths(const Panel& p, const cell::Fixture& fixture, bool arrows) {
  std::string out;
  for (const cell::ScanPath& path : fixture.scan_paths) {
    std::string points;
    for (const cell::Point2& q : path.points) points += fmt::format("{},{} ", P(p.X(q.x())), P(p.Y(q.y())));
    out += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\"{}/>\n", points,
                       arrows ? " marker-mid=\"url(#arrow)\" marker-end=\"url(#arrow)\"" : "");
  }
  return out;
}

std::string Trips(const Panel& p, const cell::Fixture& fixture, bool labels) {
  std::string out;
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const Eigen::Vector2d& f = expected[k].in_fixture;
    out += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"3\" fill=\"#d62728\"/>\n", P(p.X(f.x())), P(p.Y(f.y())));
    if (!labels) continue;
    // The label sits beside the trip along its edge, away from the edge's
    // other trips (two passes cross an edge 0.2 mm apart).
    const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(expected[k].edge)];
    const Eigen::Vector2d along = (edge.to - edge.from).normalized();
    double mean = 0;
    int count = 0;
    for (const ExpectedTrip& other : expected) {
      if (other.edge != expected[k].edge) continue;
      mean += other.in_fixture.dot(along);
      ++count;
    }
    const double sign = f.dot(along) >= mean / count ? 1 : -1;
    out += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"middle\" fill=\"#d62728\">{}</text>\n",
                       P(p.X(f.x()) + sign * 16 * along.x()), P(p.Y(f.y()) - sign * 16 * along.y() + 4), TripName(k));
  }
  return out;
}

}  // namespace

std::string ScanReportSvg(const ScanReport& report) {
  const cell::Fixture& fixture = *report.fixture;
  constexpr double kWidth = 900, kMargin = 60, kTop = 70;
  // The board: S1..S2 and S3, the markers and the points, 12 mm around.
  double x0 = 0, x1 = fixture.l1_mm, y0 = 0, y1 = fixture.l2_mm;
  for (const cell::MarkerEdge& e : fixture.edges) {
    for (const Eigen::Vector2d& q : {e.from, e.to}) {
      x0 = std::min(x0, q.x()), x1 = std::max(x1, q.x()), y0 = std::min(y0, q.y()), y1 = std::max(y1, q.y());
    }
  }
  for (const ScanReportPoint& point : report.points) {
    x0 = std::min(x0, point.in_fixture.x()), x1 = std::max(x1, point.in_fixture.x());
    y0 = std::min(y0, point.in_fixture.y()), y1 = std::max(y1, point.in_fixture.y());
  }
  x0 -= 12, x1 += 12, y0 -= 12, y1 += 12;
  const double scale = (kWidth - 2 * kMargin) / (x1 - x0);
  const Panel board{x0, y0, x1, y1, kMargin, kTop, scale};

  // The ellipses' exaggeration: the largest 4-sigma semi-axis about 10 mm of the board.
  double largest = 0;
  for (const Eigen::Matrix2d& c : report.point_covariance_mm2) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(c, Eigen::EigenvaluesOnly);
    largest = std::max(largest, 4 * std::sqrt(std::max(0.0, solver.eigenvalues().maxCoeff())));
  }
  double factor = 1;
  if (largest > 0) {
    const double rough = 10 / largest, base = std::pow(10.0, std::floor(std::log10(rough)));
    factor = base;
    for (double m : {2.0, 5.0, 10.0}) {
      if (m * base <= rough) factor = m * base;
    }
  }

  // The insets: each scan path enlarged, side by side under the board.
  const std::size_t paths = fixture.scan_paths.size();
  const double inset_width = (kWidth - 2 * kMargin - (paths - 1) * 50.0) / static_cast<double>(paths);
  std::vector<Panel> insets;
  double inset_height = 0;
  for (const cell::ScanPath& path : fixture.scan_paths) {
    double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
    for (const cell::Point2& q : path.points) {
      a0 = std::min(a0, q.x()), a1 = std::max(a1, q.x()), b0 = std::min(b0, q.y()), b1 = std::max(b1, q.y());
    }
    a0 -= 1.5, a1 += 1.5, b0 -= 1.5, b1 += 1.5;
    const double s = std::min(inset_width / (a1 - a0), 300 / (b1 - b0));
    insets.push_back({a0, b0, a1, b1, 0, 0, s});
    inset_height = std::max(inset_height, (b1 - b0) * s);
  }
  const double inset_top = kTop + board.height() + 130;
  double left = kMargin;
  for (Panel& inset : insets) {
    inset.left = left + (inset_width - inset.width()) / 2;
    inset.top = inset_top;
    left += inset_width + 50;
  }
  const double height = inset_top + inset_height + 60;

  std::string out = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"sans-serif\">\n"
      "<defs><marker id=\"arrow\" viewBox=\"0 0 10 10\" refX=\"5\" refY=\"5\" markerWidth=\"7\" markerHeight=\"7\" "
      "orient=\"auto\"><path d=\"M0,1 L9,5 L0,9 z\" fill=\"#1f77b4\"/></marker></defs>\n"
      "<rect width=\"{0}\" height=\"{1}\" fill=\"#fff\"/>\n",
      P(kWidth), P(height));
  out += fmt::format("<text x=\"{}\" y=\"26\" font-size=\"16\" font-weight=\"bold\">The marker scan of fixture {} "
                     "(cell {})</text>\n",
                     P(kMargin), SvgEscape(fixture.name), SvgEscape(report.cell_name));
  out += fmt::format(
      "<text x=\"{}\" y=\"46\" font-size=\"12\">The scan takes {} s a cycle and captures boards within {} mm "
      "and {} deg ({} x the limits);</text>\n<text x=\"{}\" y=\"60\" font-size=\"12\">its error at 4 sigma is "
      "up to {} mm ({})</text>\n",
      P(kMargin), Fixed(report.timing.seconds, 2), Fixed(report.capture.shift_mm, 2),
      Fixed(report.capture.rotation_deg, 3), Fixed(report.capture.factor, 2), P(kMargin),
      Fixed(report.point_budget_mm.empty() ? 0 : *std::max_element(report.point_budget_mm.begin(),
                                                                   report.point_budget_mm.end()),
            4),
      cell::EstimatorName(fixture.estimator));
  out += Axes(board, 10);
  out += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"12\" text-anchor=\"middle\">fixture x (mm)</text>\n",
                     P(board.left + board.width() / 2), P(board.top + board.height() + 34));
  out += fmt::format("<text x=\"{0}\" y=\"{1}\" font-size=\"12\" text-anchor=\"middle\" "
                     "transform=\"rotate(-90 {0} {1})\">fixture y (mm)</text>\n",
                     P(board.left - 40), P(board.top + board.height() / 2));
  // The frame: S1, S2, S3 and the edges' lines through them.
  out += fmt::format("<polyline points=\"{},{} {},{} {},{}\" fill=\"none\" stroke=\"#999\" "
                     "stroke-dasharray=\"5,4\"/>\n",
                     P(board.X(fixture.l1_mm)), P(board.Y(0)), P(board.X(0)), P(board.Y(0)), P(board.X(0)),
                     P(board.Y(fixture.l2_mm)));
  const std::array<std::pair<const char*, Eigen::Vector2d>, 3> corners = {
      {{"S1", {0, 0}}, {"S2", {fixture.l1_mm, 0}}, {"S3", {0, fixture.l2_mm}}}};
  for (const auto& [name, q] : corners) {
    out += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"12\" fill=\"#555\">{}</text>\n", P(board.X(q.x()) + 5),
                       P(board.Y(q.y()) + 15), name);
  }
  out += Edges(board, fixture, 0);
  out += Paths(board, fixture, false);
  out += Trips(board, fixture, false);
  for (std::size_t i = 0; i < report.point_covariance_mm2.size(); ++i) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(report.point_covariance_mm2[i]);
    const Eigen::Vector2d axis = solver.eigenvectors().col(1);
    const double a = 4 * std::sqrt(std::max(0.0, solver.eigenvalues()(1))) * factor * scale;
    const double b = 4 * std::sqrt(std::max(0.0, solver.eigenvalues()(0))) * factor * scale;
    const Eigen::Vector2d& f = report.points[i].in_fixture;
    const Eigen::Vector2d centre = f + report.point_mean_mm[i] * factor;
    const double angle = -std::atan2(axis.y(), axis.x()) * kDegPerRad;  // y is down in the picture
    out += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"2\" fill=\"#333\"/>\n", P(board.X(f.x())), P(board.Y(f.y())));
    out += fmt::format("<ellipse cx=\"{0}\" cy=\"{1}\" rx=\"{2}\" ry=\"{3}\" transform=\"rotate({4} {0} {1})\" "
                       "fill=\"#ff7f0e\" fill-opacity=\"0.25\" stroke=\"#ff7f0e\"/>\n",
                       P(board.X(centre.x())), P(board.Y(centre.y())), P(std::max(a, 0.5)), P(std::max(b, 0.5)),
                       P(angle));
  }
  // The legend, below the board's axis label.
  const double legend_y = board.top + board.height() + 56;
  out += fmt::format(
      "<ellipse cx=\"{}\" cy=\"{}\" rx=\"12\" ry=\"6\" fill=\"#ff7f0e\" fill-opacity=\"0.25\" stroke=\"#ff7f0e\"/>"
      "<text x=\"{}\" y=\"{}\" font-size=\"12\">the scan's error at each point at 4 sigma (sensor, repeatability "
      "at the trips, latency, tables under the trips),</text>"
      "<text x=\"{}\" y=\"{}\" font-size=\"12\">drawn {} x larger, its centre moved by the latency's mean (x {})"
      "</text>\n",
      P(kMargin + 12), P(legend_y), P(kMargin + 30), P(legend_y + 4), P(kMargin + 30), P(legend_y + 19), Num(factor),
      Num(factor));
  out += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#000\" stroke-width=\"3\"/>"
                     "<text x=\"{3}\" y=\"{4}\" font-size=\"12\">marker edges</text>"
                     "<line x1=\"{5}\" y1=\"{1}\" x2=\"{6}\" y2=\"{1}\" stroke=\"#1f77b4\" stroke-width=\"1.5\"/>"
                     "<text x=\"{7}\" y=\"{4}\" font-size=\"12\">scan paths</text>"
                     "<circle cx=\"{8}\" cy=\"{1}\" r=\"3\" fill=\"#d62728\"/>"
                     "<text x=\"{9}\" y=\"{4}\" font-size=\"12\">nominal trips</text>\n",
                     P(kMargin), P(legend_y + 38), P(kMargin + 24), P(kMargin + 30), P(legend_y + 42),
                     P(kMargin + 140), P(kMargin + 164), P(kMargin + 170), P(kMargin + 272), P(kMargin + 280));
  // The insets.
  for (std::size_t i = 0; i < insets.size(); ++i) {
    const Panel& inset = insets[i];
    out += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"13\" font-weight=\"bold\">scan path {} (fixture mm)"
                       "</text>\n",
                       P(inset.left), P(inset.top - 12), SvgEscape(fixture.scan_paths[i].name));
    out += Axes(inset, 6);
    out += fmt::format("<g>\n{}{}{}</g>\n", Edges(inset, fixture, 12), Paths(inset, fixture, true),
                       Trips(inset, fixture, true));
  }
  // Clip nothing: the insets draw the whole fixture, but only their window is
  // inside their frame; cover what falls outside with white.
  std::string clipped;
  for (std::size_t i = 0; i < insets.size(); ++i) {
    const Panel& inset = insets[i];
    clipped += fmt::format("<clipPath id=\"inset{}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n",
                           i, P(inset.left), P(inset.top), P(inset.width()), P(inset.height()));
  }
  out.insert(out.find("</defs>"), clipped);
  // Apply the clip paths to the insets' groups, in order.
  std::size_t at = out.find("<g>\n");
  for (std::size_t i = 0; i < insets.size() && at != std::string::npos; ++i) {
    out.replace(at, 4, fmt::format("<g clip-path=\"url(#inset{})\">\n", i));
    at = out.find("<g>\n", at);
  }
  out += "</svg>\n";
  return out;
}

}  // namespace smtcal
