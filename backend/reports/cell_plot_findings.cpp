// Where the picture of a cell marks each diagnostic (LocateFindings,
// cell_plot.h). A diagnostic carries a place in a file, not in the cell: the
// kinds that concern one point of the cell (a trip, a leg, a corner of a
// pocket, a point outside the travel) are placed by the same calibration
// functions that found them; the rest by the table of the cell file they
// point into, or by the program statement whose targets they concern.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "backend/reports/cell_plot.h"
#include "calibration/fixture_geometry.h"
#include "calibration/placement_budget.h"
#include "calibration/region_fit.h"
#include "calibration/scan_plan.h"
#include "frontend/cell_toml.h"

namespace smtcal {
namespace {

using Points = std::vector<Eigen::Vector2d>;

// What part of the cell file a line belongs to: the table that begins last
// before it (a scan path only up to its last point).
struct Owner {
  enum class Kind { kRegion, kFixture, kScanPath, kFeeder } kind;
  std::size_t index = 0;  // into regions, fixtures or feeders
  std::size_t path = 0;   // a scan path: its index in the fixture
  std::uint32_t first = 0, last = std::numeric_limits<std::uint32_t>::max();  // lines
};

std::vector<Owner> Owners(const cell::Cell& cell) {
  std::vector<Owner> owners;
  for (std::size_t r = 0; r < cell.regions.size(); ++r) {
    owners.push_back({Owner::Kind::kRegion, r, 0, cell.regions[r].range.begin.line});
  }
  for (std::size_t f = 0; f < cell.fixtures.size(); ++f) {
    const cell::Fixture& fixture = cell.fixtures[f];
    owners.push_back({Owner::Kind::kFixture, f, 0, fixture.range.begin.line});
    for (std::size_t p = 0; p < fixture.scan_paths.size(); ++p) {
      const cell::ScanPath& path = fixture.scan_paths[p];
      std::uint32_t last = path.range.begin.line;
      for (const SourceRange& point : path.point_ranges) last = std::max(last, point.begin.line);
      owners.push_back({Owner::Kind::kScanPath, f, p, path.range.begin.line, last});
    }
  }
  for (std::size_t f = 0; f < cell.feeders.size(); ++f) {
    owners.push_back({Owner::Kind::kFeeder, f, 0, cell.feeders[f].range.begin.line});
  }
  return owners;
}

// The owner of `line` of the cell file: the latest table begun at or
// before it (a scan path that ended before it gives way to its fixture).
const Owner* OwnerOf(const std::vector<Owner>& owners, std::uint32_t line) {
  const Owner* best = nullptr;
  for (const Owner& owner : owners) {
    if (owner.first == 0 || owner.first > line) continue;
    if (owner.kind == Owner::Kind::kScanPath && line > owner.last) continue;
    if (best == nullptr || owner.first > best->first ||
        (owner.first == best->first && owner.kind == Owner::Kind::kScanPath)) {
      best = &owner;
    }
  }
  return best;
}

Points RegionCorners(const cell::Region& region) {
  return {{region.x_mm.lo, region.y_mm.lo},
          {region.x_mm.hi, region.y_mm.lo},
          {region.x_mm.hi, region.y_mm.hi},
          {region.x_mm.lo, region.y_mm.hi}};
}

Points FeederPoints(const cell::Feeder& feeder) {
  Points points;
  for (int k = 1; k <= feeder.pick_points(); ++k) {
    const std::array<double, 4> p = feeder.PickPoint(k);
    points.emplace_back(p[0], p[1]);
  }
  return points;
}

bool InTravel(const cell::Robot& robot, const Eigen::Vector2d& p) {
  return robot.limits[0].Contains(p.x()) && robot.limits[1].Contains(p.y());
}

// The points of `points` outside the robot's travel, or all of them when
// none is (the diagnostic is then about z or u).
Points OutsideTravel(const cell::Robot& robot, const Points& points) {
  Points out;
  for (const Eigen::Vector2d& p : points) {
    if (!InTravel(robot, p)) out.push_back(p);
  }
  return out.empty() ? points : out;
}

// The point of segment a-b nearest to segment c-d (their crossing when
// they cross).
Eigen::Vector2d NearestOnSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                                 const Eigen::Vector2d& d) {
  const Eigen::Vector2d u = b - a, v = d - c, w = a - c;
  const double cross = u.x() * v.y() - u.y() * v.x();
  if (std::abs(cross) > 1e-12) {
    const double s = (v.x() * w.y() - v.y() * w.x()) / cross, t = (u.x() * w.y() - u.y() * w.x()) / cross;
    if (s >= 0 && s <= 1 && t >= 0 && t <= 1) return a + s * u;
  }
  // No crossing: the nearest of the four end-to-segment distances.
  auto project = [](const Eigen::Vector2d& p, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
    const Eigen::Vector2d along = to - from;
    const double t = std::clamp((p - from).dot(along) / std::max(along.squaredNorm(), 1e-18), 0.0, 1.0);
    return Eigen::Vector2d(from + t * along);
  };
  const std::array<std::pair<Eigen::Vector2d, Eigen::Vector2d>, 4> pairs = {
      {{a, project(a, c, d)}, {b, project(b, c, d)}, {project(c, a, b), c}, {project(d, a, b), d}}};
  const auto nearest = std::min_element(pairs.begin(), pairs.end(), [](const auto& x, const auto& y) {
    return (x.first - x.second).squaredNorm() < (y.first - y.second).squaredNorm();
  });
  return nearest->first;
}

std::string Quoted(const std::string& name) { return fmt::format("'{}'", name); }

class Locator {
 public:
  Locator(const cell::Cell& cell, const std::vector<PlottedTarget>& targets) : cell_(cell), targets_(targets) {
    owners_ = Owners(cell);
  }

  PlotFinding Locate(const Diagnostic& diag, const SourceManager& sources) {
    PlotFinding finding;
    finding.kind = diag.kind;
    finding.severity = diag.severity;
    finding.message = diag.message;
    const SourceLoc& at = diag.range.begin;
    if (at.file != 0) {
      finding.where = std::filesystem::path(sources.File(at.file).name).filename().string();
      if (at.line != 0) finding.where += fmt::format(":{}:{}", at.line, at.column);
    }
    if (at.file == cell_.file && at.line != 0) {
      InCell(diag, finding);
    } else if (at.known()) {
      InTableFile(at, finding) || AtTargets(diag.range, finding);
    }
    return finding;
  }

 private:
  void InCell(const Diagnostic& diag, PlotFinding& finding) {
    const Owner* owner = OwnerOf(owners_, diag.range.begin.line);
    if (owner == nullptr) return;  // [robot], the file itself
    switch (owner->kind) {
      case Owner::Kind::kRegion: {
        const cell::Region& region = cell_.regions[owner->index];
        finding.subject = "region " + Quoted(region.name);
        finding.outline_mm = RegionCorners(region);
        finding.marks_mm = diag.kind == DiagKind::CellOutsideRobotLimits ? OutsideTravel(cell_.robot, finding.outline_mm)
                                                                         : Points{finding.outline_mm[3]};
        return;
      }
      case Owner::Kind::kFeeder: {
        const cell::Feeder& feeder = cell_.feeders[owner->index];
        finding.subject = "feeder " + Quoted(feeder.name);
        const Points points = FeederPoints(feeder);
        finding.marks_mm = diag.kind == DiagKind::CellOutsideRobotLimits ? OutsideTravel(cell_.robot, points) : points;
        return;
      }
      case Owner::Kind::kScanPath:
      case Owner::Kind::kFixture:
        InFixture(diag, *owner, finding);
        return;
    }
  }

  void InFixture(const Diagnostic& diag, const Owner& owner, PlotFinding& finding) {
    const cell::Fixture& fixture = cell_.fixtures[owner.index];
    const Eigen::Affine3d nominal = NominalFix(fixture);
    finding.subject = "fixture " + Quoted(fixture.name);
    if (diag.kind == DiagKind::CellTripUncalibrated && owner.kind == Owner::Kind::kScanPath) {
      // One diagnostic per trip outside every table, in trip order: the
      // n-th of this path's is its n-th uncalibrated trip.
      const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
      const std::vector<int> regions = TripRegions(fixture, cell_.regions);
      const std::vector<Eigen::Vector2d> trips = NominalTrips(fixture, nominal);
      std::size_t& seen = uncalibrated_seen_[{owner.index, owner.path}];
      std::size_t n = 0;
      for (std::size_t k = 0; k < expected.size(); ++k) {
        if (expected[k].path != owner.path || regions[k] >= 0) continue;
        if (n++ != seen) continue;
        finding.subject = fmt::format("trip {} of fixture {}", TripName(k), Quoted(fixture.name));
        finding.marks_mm = {trips[k]};
        break;
      }
      ++seen;
      return;
    }
    if (diag.kind == DiagKind::CellScanCaptureRange) {
      const CaptureRange capture = ScanCaptureRange(fixture);
      if (capture.trip >= 0) {
        const std::size_t k = static_cast<std::size_t>(capture.trip);
        finding.subject = fmt::format("trip {} of fixture {}", TripName(k), Quoted(fixture.name));
        finding.marks_mm = {NominalTrips(fixture, nominal)[k]};
        return;
      }
      if (capture.leg >= 0) {
        const cell::ScanPath& path = fixture.scan_paths[static_cast<std::size_t>(capture.leg_path)];
        const std::size_t i = static_cast<std::size_t>(capture.leg);
        const cell::MarkerEdge& edge = fixture.edges[static_cast<std::size_t>(capture.edge)];
        finding.subject =
            fmt::format("leg {} of scan path {} and edge {}", i + 1, Quoted(path.name), edge.name);
        finding.marks_mm = {NearestOnSegment(ToBase(nominal, path.points[i]), ToBase(nominal, path.points[i + 1]),
                                             ToBase(nominal, edge.from), ToBase(nominal, edge.to))};
        return;
      }
    }
    if (diag.kind == DiagKind::CellPocketOverRegion && fixture.pocket_mm) {
      const std::array<Eigen::Vector2d, 4> corners = cell::PocketCornersInBase(fixture);
      finding.subject = fmt::format("the pocket of fixture {}", Quoted(fixture.name));
      finding.outline_mm.assign(corners.begin(), corners.end());
      finding.marks_mm = {FitInRegion(cell_, finding.outline_mm).worst_point};
      return;
    }
    if (owner.kind == Owner::Kind::kScanPath) {
      const cell::ScanPath& path = fixture.scan_paths[owner.path];
      finding.subject = fmt::format("scan path {} of fixture {}", Quoted(path.name), Quoted(fixture.name));
      Points points;
      for (const Eigen::Vector2d& p : path.points) points.push_back(ToBase(nominal, p));
      // A point's own diagnostic (outside the travel) marks that point.
      for (std::size_t k = 0; k < path.point_ranges.size(); ++k) {
        if (path.point_ranges[k].begin.line == diag.range.begin.line &&
            path.point_ranges[k].begin.column == diag.range.begin.column) {
          finding.marks_mm = {points[k]};
          return;
        }
      }
      finding.marks_mm = diag.kind == DiagKind::CellOutsideRobotLimits ? OutsideTravel(cell_.robot, points)
                                                                       : Points{points.front()};
      return;
    }
    // The fixture's own keys: its frame's corner S1 (or what leaves the travel).
    const Eigen::Vector2d s1 = ToBase(nominal, {0, 0});
    finding.marks_mm = {s1};
    if (diag.kind == DiagKind::CellOutsideRobotLimits) {
      Points all = {s1};
      for (const auto& path : ScanPathsInBase(fixture, nominal)) all.insert(all.end(), path.begin(), path.end());
      finding.marks_mm = OutsideTravel(cell_.robot, all);
    }
  }

  // A diagnostic in a region's table file marks the region.
  bool InTableFile(const SourceLoc& at, PlotFinding& finding) {
    for (const cell::Region& region : cell_.regions) {
      if (region.table_file != at.file) continue;
      finding.subject = "the table of region " + Quoted(region.name);
      finding.outline_mm = RegionCorners(region);
      finding.marks_mm = {finding.outline_mm[3]};
      return true;
    }
    return false;
  }

  // A program's diagnostic marks the targets of its statement: of a
  // statement reached several times (a loop's passes), those in the region
  // the diagnostic names ("region 'layer2'"), or all of them when it names
  // none of theirs.
  bool AtTargets(const SourceRange& range, PlotFinding& finding) {
    const SourceLoc& at = range.begin;
    std::vector<const PlottedTarget*> of_statement;
    for (const PlottedTarget& target : targets_) {
      const SourceLoc& begin = target.statement.begin;
      if (begin.file == at.file && begin.line == at.line && at.column >= begin.column &&
          at.column < begin.column + target.statement.length) {
        of_statement.push_back(&target);
      }
    }
    std::vector<const PlottedTarget*> named;
    for (const PlottedTarget* target : of_statement) {
      const cell::Region* region = cell_.RegionAt({target->x_mm, target->y_mm});
      if (region != nullptr && finding.message.find("region '" + region->name + "'") != std::string::npos) {
        named.push_back(target);
      }
    }
    const std::vector<const PlottedTarget*>& marked = named.empty() ? of_statement : named;
    for (const PlottedTarget* target : marked) {
      if (finding.subject.empty()) {
        finding.subject = target->runs > 1 && marked.size() == 1
                              ? fmt::format("{} ({}/{})", target->name, target->run, target->runs)
                              : target->name;
      }
      finding.marks_mm.emplace_back(target->x_mm, target->y_mm);
    }
    return !finding.marks_mm.empty();
  }

  const cell::Cell& cell_;
  const std::vector<PlottedTarget>& targets_;
  std::vector<Owner> owners_;
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> uncalibrated_seen_;  // (fixture, path) -> reported
};

}  // namespace

std::vector<PlotFinding> LocateFindings(const cell::Cell& cell, const std::vector<PlottedTarget>& targets,
                                        const Diagnostics& diags) {
  Locator locator(cell, targets);
  std::vector<PlotFinding> findings;
  for (const Diagnostic& diag : diags.all()) {
    if (diag.severity == Severity::Note) continue;
    findings.push_back(locator.Locate(diag, diags.sources()));
  }
  return findings;
}

}  // namespace smtcal
