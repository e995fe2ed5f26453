// The measurement plan (calibration/measurement_plan.h, docs/measure.md).
#include "calibration/measurement_plan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "base/check.h"
#include "base/field_text.h"
#include "calibration/fixture_geometry.h"
#include "calibration/interpolation_error.h"
#include "calibration/motion_time.h"

namespace smtcal::measure {
namespace {

// Grid lines are written with 3 decimals (micrometres): rounded there, they
// read back exactly and the table's lines are the plan's.
double RoundUm(double mm) { return std::round(mm * 1000.0) / 1000.0; }

// The largest "round" pitch (1, 2, 2.5, 5 x 10^k) not above `limit`.
double RoundPitchDown(double limit) {
  const double decade = std::pow(10.0, std::floor(std::log10(limit)));
  double best = decade;
  for (double step : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (step * decade <= limit * (1 + 1e-12)) best = step * decade;
  }
  return best;
}

// Grid lines covering [lo - margin, hi + margin] at `pitch`, centred on the
// bounds, and moved inside the robot's range `limit` when the centred grid
// would reach past it (it still covers the bounds and the margin then,
// unless the range itself is too short).
std::vector<double> GridLines(const cell::Interval& bounds, double margin, double pitch, const cell::Interval& limit,
                              double lattice = 0) {
  const double span = bounds.hi - bounds.lo + 2 * margin;
  int cells = std::max(1, static_cast<int>(std::ceil(span / pitch - 1e-9)));
  double first = 0.5 * (bounds.lo + bounds.hi) - 0.5 * cells * pitch;
  first = std::min(first, bounds.lo - margin);  // rounding never uncovers the margin
  if (lattice > 0) {
    // Down onto the lattice; one more cell when that uncovers the top.
    first = std::floor(first / lattice + 1e-9) * lattice;
    if (first + cells * pitch < bounds.hi + margin - 1e-9) ++cells;
    // Inside the robot's range when that still covers the bounds and the
    // margin (else the grid stays, and is reported).
    const double inside_lo = std::ceil(limit.lo / lattice - 1e-9) * lattice;
    if (first < limit.lo && inside_lo <= bounds.lo - margin + 1e-9) first = inside_lo;
    const double inside_hi = std::floor((limit.hi - cells * pitch) / lattice + 1e-9) * lattice;
    if (first + cells * pitch > limit.hi && inside_hi + cells * pitch >= bounds.hi + margin - 1e-9) first = inside_hi;
  } else {
    if (first < limit.lo) first = std::min(limit.lo, bounds.lo - margin);
    if (first + cells * pitch > limit.hi) first = std::max(limit.hi - cells * pitch, bounds.hi + margin - cells * pitch);
  }
  first = RoundUm(first);
  std::vector<double> lines;
  for (int i = 0; i <= cells; ++i) lines.push_back(RoundUm(first + i * pitch));
  return lines;
}

// The cell indices that get a check point: every second one (1, 3, 5, ...),
// the only one when there is a single cell.
std::vector<std::size_t> CheckCells(std::size_t lines) {
  std::vector<std::size_t> cells;
  if (lines < 2) return cells;
  if (lines == 2) return {0};
  for (std::size_t c = 1; c + 1 < lines; c += 2) cells.push_back(c);
  return cells;
}

// The index ranges [begin, end) of the lines one placement of the artefact
// reaches (`reach` mm; all of them without one), neighbours sharing one
// line so the placements can be tied; spread evenly.
std::vector<std::pair<std::size_t, std::size_t>> Chunks(std::size_t lines, std::optional<double> reach,
                                                        double pitch) {
  if (!reach) return {{0, lines}};
  const std::size_t per = std::max<std::size_t>(2, static_cast<std::size_t>(std::floor(*reach / pitch + 1e-9)) + 1);
  if (lines <= per) return {{0, lines}};
  const std::size_t count = (lines - 1 + per - 2) / (per - 1);  // count (per - 1) + 1 >= lines
  std::vector<std::pair<std::size_t, std::size_t>> chunks;
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t begin = k * (lines - 1) / count;
    const std::size_t end = (k + 1) * (lines - 1) / count + 1;
    chunks.push_back({begin, end});
  }
  return chunks;
}

constexpr double kPi = 3.14159265358979323846;

struct PointOfRegion {
  Eigen::Vector2d at;
  VisitKind kind;
  int node;
  std::size_t region = 0;
};

// An axis-aligned box of points.
struct Box {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty = true;
  Box Union(const Box& other) const {
    if (empty) return other;
    if (other.empty) return *this;
    return {std::min(x0, other.x0), std::min(y0, other.y0), std::max(x1, other.x1), std::max(y1, other.y1), false};
  }
  Box With(const Eigen::Vector2d& p) const { return Union(Box{p.x(), p.y(), p.x(), p.y(), false}); }
};

Box BoxOf(const std::vector<PointOfRegion>& points) {
  Box box;
  for (const PointOfRegion& p : points) box = box.With(p.at);
  return box;
}

// The plate reaches the box.
bool Fits(const Box& box, double reach) { return box.x1 - box.x0 <= reach + 1e-9 && box.y1 - box.y0 <= reach + 1e-9; }

// How far apart two boxes are (0 when they touch or overlap).
double Gap(const Box& a, const Box& b) {
  const double dx = std::max({0.0, a.x0 - b.x1, b.x0 - a.x1});
  const double dy = std::max({0.0, a.y0 - b.y1, b.y0 - a.y1});
  return std::hypot(dx, dy);
}

// The part of the region's points one placement measures.
struct Piece {
  std::size_t region = 0;
  MeasuredAxes axes = MeasuredAxes::kXY;
  std::vector<PointOfRegion> points;  // nodes, check points, and the line shared with the previous piece (ties)
};

struct StationBuild {
  MeasuredAxes axes = MeasuredAxes::kXY;
  std::vector<std::size_t> pieces;
  std::vector<PointOfRegion> points;
  std::set<int> tied_to;  // 0-based
  Box Bounds() const { return BoxOf(points); }
};

// A line of one station's nodes that another measures to tie the two.
struct TieLine {
  std::vector<PointOfRegion> points;
  double spread = 0;    // along the line: how well it fixes the turn
  double distance = 0;  // from the measuring station's box
  bool Better(const TieLine& other) const {
    if (std::abs(spread - other.spread) > 1e-9) return spread > other.spread;
    return distance < other.distance;
  }
};

// The longest line (a column or a row) of `of`'s own nodes that `by` can
// measure with its plate still reaching all its points; nullopt when none of
// two nodes or more fits.
std::optional<TieLine> BestTieLine(const StationBuild& by, const StationBuild& of, double reach) {
  const Box box = by.Bounds();
  std::optional<TieLine> best;
  for (int axis = 0; axis < 2; ++axis) {  // 0: columns (x = c), 1: rows (y = c)
    std::map<double, std::vector<PointOfRegion>> lines;
    for (const PointOfRegion& p : of.points) {
      if (p.kind == VisitKind::kNode) lines[p.at[axis]].push_back(p);
    }
    for (auto& [c, members] : lines) {
      const int other = 1 - axis;
      std::sort(members.begin(), members.end(),
                [&](const PointOfRegion& a, const PointOfRegion& b) { return a.at[other] < b.at[other]; });
      TieLine line;
      Box grown = box;
      for (const PointOfRegion& p : members) {
        const Box with = grown.With(p.at);
        if (!Fits(with, reach)) continue;
        grown = with;
        line.points.push_back(p);
      }
      if (line.points.size() < 2) continue;
      line.spread = line.points.back().at[other] - line.points.front().at[other];
      line.distance = Gap(box, BoxOf(line.points));
      if (!best || line.Better(*best)) best = line;
    }
  }
  return best;
}

// Micrometres up, for a bound in a message.
std::string CeilUm(double mm) { return fmt::format("{}", std::ceil(mm * 1000 - 1e-9) / 1000); }

// Serpentine order: rows by y, alternating x direction; every point is
// reached by the same final approach, so the order only saves travel.
void Serpentine(std::vector<PointOfRegion>& points) {
  std::sort(points.begin(), points.end(), [](const PointOfRegion& a, const PointOfRegion& b) {
    if (a.at.y() != b.at.y()) return a.at.y() < b.at.y();
    return a.at.x() != b.at.x() ? a.at.x() < b.at.x() : a.node < b.node;
  });
  std::size_t row = 0;
  for (std::size_t begin = 0; begin < points.size(); ++row) {
    std::size_t end = begin;
    while (end < points.size() && points[end].at.y() == points[begin].at.y()) ++end;
    if (row % 2 == 1) std::reverse(points.begin() + static_cast<long>(begin), points.begin() + static_cast<long>(end));
    begin = end;
  }
}

std::string Mm(double mm) { return fmt::format("{}", RoundUm(mm)); }

// Regions under a fixture's markers that the cell lacks: one per scan path
// whose trips no region covers, the trips' windows with the fixture's
// max_shift_mm around them.
std::vector<PlanRegion> MarkerRegions(const cell::Cell& cell) {
  std::vector<PlanRegion> proposed;
  for (const cell::Fixture& fixture : cell.fixtures) {
    const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
    const std::vector<TripWindow> windows = TripWindows(fixture);
    // A trip window is covered when a region's bounds (which the plan's grid
    // covers, with its margin) hold it; tables need not exist yet.
    auto covered = [&](const TripWindow& w) {
      for (const cell::Region& region : cell.regions) {
        if (region.Contains(w.from) && region.Contains(w.to)) return true;
      }
      return false;
    };
    std::map<std::size_t, std::pair<Eigen::Vector2d, Eigen::Vector2d>> boxes;  // per path: min, max
    for (std::size_t k = 0; k < expected.size(); ++k) {
      if (covered(windows[k])) continue;
      auto [it, fresh] = boxes.try_emplace(expected[k].path, windows[k].from, windows[k].from);
      for (const Eigen::Vector2d& p : {windows[k].from, windows[k].to}) {
        it->second.first = it->second.first.cwiseMin(p);
        it->second.second = it->second.second.cwiseMax(p);
      }
    }
    for (const auto& [path, box] : boxes) {
      PlanRegion region;
      region.name = fmt::format("{}_{}", fixture.name, fixture.scan_paths[path].name);
      region.proposed = true;
      region.x_mm = {std::floor(box.first.x() - fixture.max_shift_mm), std::ceil(box.second.x() + fixture.max_shift_mm)};
      region.y_mm = {std::floor(box.first.y() - fixture.max_shift_mm), std::ceil(box.second.y() + fixture.max_shift_mm)};
      region.tolerance_mm = fixture.sensor_accuracy_mm;
      proposed.push_back(region);
    }
  }
  return proposed;
}

}  // namespace

std::string_view MeasuredAxesName(MeasuredAxes axes) {
  switch (axes) {
    case MeasuredAxes::kX: return "x";
    case MeasuredAxes::kY: return "y";
    case MeasuredAxes::kXY: return "xy";
  }
  return "xy";
}

std::string_view VisitKindName(VisitKind kind) {
  switch (kind) {
    case VisitKind::kNode: return "node";
    case VisitKind::kCheck: return "check";
    case VisitKind::kTie: return "tie";
    case VisitKind::kClosure: return "closure";
  }
  return "node";
}

double ProbeContactRadiusMm(const cell::MeasureProbe& probe) {
  return 0.5 * (probe.hole_diameter_mm - probe.stylus_diameter_mm);
}

double VisitTimeS(const cell::Cell& cell, const Visit& visit, const Visit* previous) {
  const cell::Robot& robot = cell.robot;
  const cell::Measure& m = *cell.measure;
  const Eigen::Vector2d approach = robot.final_approach_mm.value_or(Eigen::Vector2d::Zero());
  auto xy = [&](double distance) { return MoveTime(distance, robot.xy_speed_mm_s, robot.xy_accel_mm_s2); };
  const double z = MoveTime(m.clear_z_mm - m.z_mm, robot.z_speed_mm_s, robot.z_accel_mm_s2);
  // One repetition: down, dwell, read, up, back to the approach point and in again.
  double device = 0;
  if (m.device == cell::MeasureDevice::kProbe) {
    // Per axis: to the slow start, the probe move to the wall (where it is
    // expected: overtravel_mm on), back to the approach point and in.
    const double slow = m.probe.overtravel_mm;
    const double rapid = ProbeContactRadiusMm(m.probe) - m.probe.overtravel_mm;
    device = 2 * (xy(rapid) + slow / m.probe.speed_mm_s + xy(rapid + slow) + xy(approach.norm()));
  }
  const double repetition = 2 * z + m.dwell_s + m.reading_time_s + device + xy(approach.norm()) * 2;
  double travel = 0;
  if (previous != nullptr) travel = xy((visit.at - approach - (previous->at)).norm());
  return travel + visit.repetitions * repetition;
}

std::vector<VisitGroup> GroupVisits(const std::vector<Visit>& visits) {
  std::vector<VisitGroup> groups;
  for (std::size_t k = 0; k < visits.size(); ++k) {
    const Visit& v = visits[k];
    if (groups.empty() || groups.back().axes != v.axes || groups.back().station != v.station) {
      groups.push_back({v.region, v.axes, v.station, k, 0});
    }
    ++groups.back().count;
  }
  return groups;
}

std::optional<Plan> MakePlan(const cell::Cell& cell, const PlanOptions& options, Diagnostics& diags) {
  const SourceRange cell_file(SourceLoc{cell.file, 0, 0});
  if (!cell.measure) {
    diags.Report(DiagKind::MeasureNoDevice, cell_file, cell.name);
    return std::nullopt;
  }
  if (!cell.robot.final_approach_mm) {
    diags.Report(DiagKind::MeasureNoApproach, cell.robot.range);
    return std::nullopt;
  }
  const cell::Measure& m = *cell.measure;
  const cell::Robot& robot = cell.robot;
  Plan plan;
  plan.cell_name = cell.name;
  plan.device = m.device;
  plan.approach_mm = *robot.final_approach_mm;

  const double accuracy = robot.uncalibrated_accuracy_mm.value_or(kPlanAssumedAccuracyMm);
  if (!robot.uncalibrated_accuracy_mm) {
    plan.notes.push_back(fmt::format(
        "the robot's uncalibrated_accuracy_mm is not declared: the plan assumes {} mm for its margins and pitch",
        kPlanAssumedAccuracyMm));
  }

  // The regions: the cell's, and those its markers lack.
  std::vector<PlanRegion> candidates;
  std::vector<const cell::Region*> sources;
  for (const cell::Region& region : cell.regions) {
    PlanRegion r;
    r.name = region.name;
    r.x_mm = region.x_mm;
    r.y_mm = region.y_mm;
    r.tolerance_mm = region.tolerance_mm;
    candidates.push_back(r);
    sources.push_back(&region);
  }
  for (PlanRegion& proposed : MarkerRegions(cell)) {
    plan.notes.push_back(fmt::format(
        "the trips of {} lie outside every region: the plan measures a region '{}' under them, x {}..{}, y {}..{} mm; "
        "add it to the cell as a [[region]] with the table this measurement builds",
        proposed.name, proposed.name, Mm(proposed.x_mm.lo), Mm(proposed.x_mm.hi), Mm(proposed.y_mm.lo),
        Mm(proposed.y_mm.hi)));
    candidates.push_back(std::move(proposed));
    sources.push_back(nullptr);
  }
  std::vector<std::size_t> chosen;
  if (options.regions.empty()) {
    for (std::size_t i = 0; i < candidates.size(); ++i) chosen.push_back(i);
  } else {
    for (const std::string& name : options.regions) {
      auto it = std::find_if(candidates.begin(), candidates.end(), [&](const PlanRegion& r) {
        return AsciiLowercase(r.name) == AsciiLowercase(name);
      });
      if (it == candidates.end()) {
        std::vector<std::string> names;
        for (const PlanRegion& r : candidates) names.push_back(r.name);
        std::string closest = ClosestName(name, names);
        diags.Report(DiagKind::MeasureUnknownRegion, cell_file, cell.name, name,
                     closest.empty() ? "" : fmt::format("; did you mean '{}'?", closest));
        continue;
      }
      chosen.push_back(static_cast<std::size_t>(it - candidates.begin()));
    }
    if (chosen.size() != options.regions.size()) return std::nullopt;
  }

  const std::size_t errors_before = diags.error_count();
  int next_node = 1;
  std::vector<Piece> pieces;
  for (std::size_t c : chosen) {
    PlanRegion region = candidates[c];
    const cell::Region* source = sources[c];
    region.sets = options.sets;
    region.repetitions = options.repetitions;
    region.margin_mm = accuracy;
    // The pitch: given, or from the interpolation-error estimate verify
    // uses (calibration/interpolation_error.h): the grid advice of the
    // previous table, or before any table the planned estimate of the
    // declared roughness; then the largest round pitch not above it.
    const double share = 100 * kInterpolationShareOfTolerance;
    if (options.pitch_mm) {
      region.pitch_mm = *options.pitch_mm;
      region.pitch_reason = "given (--pitch)";
    } else if (source != nullptr && source->has_table) {
      const InterpolationEstimate& previous = source->interpolation;
      const GridAdvice advice = AdviseGrid(previous, region.tolerance_mm);
      const double advised = advice.coarse ? advice.pitch_mm : previous.PitchMm();
      region.pitch_mm = RoundPitchDown(std::max(advised, kPlanSmallestPitchMm));
      region.pitch_reason = fmt::format(
          "from the previous table {}: between its nodes ({} mm apart) {:.4f} mm, {}, {:.0f} % of the tolerance "
          "±{} mm; {}",
          source->table_path, Mm(previous.PitchMm()), previous.NormMm(), InterpolationKindShortName(previous.Kind()),
          100 * advice.share, Mm(region.tolerance_mm),
          advice.coarse ? fmt::format("within {:.0f} % at {} mm or less", share, Mm(advice.pitch_mm))
                        : fmt::format("within {:.0f} %: its pitch again", share));
    } else {
      const DeclaredRoughness roughness{accuracy, robot.uncalibrated_correlation_mm};
      const double span = std::max(region.x_mm.hi - region.x_mm.lo, region.y_mm.hi - region.y_mm.lo) +
                          2 * region.margin_mm;
      const double planned = std::min(PlannedPitchMm(roughness, region.tolerance_mm), span);
      region.pitch_mm = RoundPitchDown(std::max(planned, kPlanSmallestPitchMm));
      region.pitch_reason = fmt::format(
          "from the declared roughness (robot.uncalibrated_* keys: {} mm over 3 x {} mm), which nodes not yet "
          "measured cannot rule out: between the nodes {:.4f} mm, within {:.0f} % of the tolerance ±{} mm",
          Mm(accuracy), Mm(robot.uncalibrated_correlation_mm), PlannedInterpolationMm(roughness, region.pitch_mm),
          share, Mm(region.tolerance_mm));
    }
    // The artefact's lattice: the transducer's grooves, the probe's holes.
    std::optional<double> lattice;
    if (m.device == cell::MeasureDevice::kTransducer) lattice = m.transducer.groove_pitch_mm;
    if (m.device == cell::MeasureDevice::kProbe) lattice = m.probe.hole_pitch_mm;
    if (lattice) {
      const double steps = std::max(1.0, std::floor(region.pitch_mm / *lattice + 1e-9));
      const double on_lattice = steps * *lattice;
      if (std::abs(on_lattice - region.pitch_mm) > 1e-9) {
        region.pitch_reason += fmt::format("; {} to the artefact's {} ({} mm apart)",
                                           on_lattice < region.pitch_mm ? "rounded down" : "raised",
                                           m.device == cell::MeasureDevice::kProbe ? "holes" : "grooves",
                                           Mm(*lattice));
        region.pitch_mm = on_lattice;
      }
    }
    // Probe check points sit at cell centres, which must be holes too.
    const bool centres_on_holes =
        m.device != cell::MeasureDevice::kProbe ||
        std::abs(std::remainder(0.5 * region.pitch_mm, m.probe.hole_pitch_mm)) < 1e-9;
    if (options.check_points && !centres_on_holes) {
      plan.notes.push_back(fmt::format(
          "region {}: no check points: at a pitch of {} mm the cell centres are not holes of the artefact ({} mm "
          "apart); a pitch of {} mm would have them",
          region.name, Mm(region.pitch_mm), Mm(m.probe.hole_pitch_mm), Mm(2 * m.probe.hole_pitch_mm)));
    }
    // Never coarser than the region: at least two lines each way.
    // Where nodes may lie: the approach point (node - approach) and the
    // probe's moves (towards the wall, in the approach's direction) stay
    // within the robot's range too.
    std::array<cell::Interval, 2> usable;
    for (int axis = 0; axis < 2; ++axis) {
      const double a = plan.approach_mm[axis];
      const double reach = m.device == cell::MeasureDevice::kProbe
                               ? ProbeContactRadiusMm(m.probe) + m.probe.overtravel_mm
                               : 0.0;
      const cell::Interval& limit = robot.limits[static_cast<std::size_t>(axis)];
      usable[static_cast<std::size_t>(axis)] = {limit.lo + std::max(a, 0.0) + (a < 0 ? reach : 0.0),
                                                limit.hi + std::min(a, 0.0) - (a > 0 ? reach : 0.0)};
    }
    // The probe's grids lie on one lattice of the plate's holes (multiples
    // of the hole pitch), so one placement of the plate can hold the nodes
    // of several regions, and a station can measure its neighbour's.
    const double snap = m.device == cell::MeasureDevice::kProbe ? m.probe.hole_pitch_mm : 0.0;  // 0: no lattice
    region.xs = GridLines(region.x_mm, region.margin_mm, region.pitch_mm, usable[0], snap);
    region.ys = GridLines(region.y_mm, region.margin_mm, region.pitch_mm, usable[1], snap);
    for (int axis = 0; axis < 2; ++axis) {
      const std::vector<double>& lines = axis == 0 ? region.xs : region.ys;
      const cell::Interval& limit = usable[static_cast<std::size_t>(axis)];
      if (lines.front() < limit.lo || lines.back() > limit.hi) {
        diags.Report(DiagKind::MeasureGridOutsideRobot, source != nullptr ? source->bounds_range : cell_file,
                     region.name, axis == 0 ? "x" : "y", Mm(lines.front()), Mm(lines.back()), Mm(region.margin_mm),
                     axis == 0 ? "x" : "y", Mm(limit.lo), Mm(limit.hi));
      }
    }
    if (diags.error_count() != errors_before) continue;

    // The points: nodes numbered row by row, then the check points; the
    // pieces one placement of the artefact holds.
    std::vector<PointOfRegion> nodes;
    for (double y : region.ys) {
      for (double x : region.xs) nodes.push_back({Eigen::Vector2d(x, y), VisitKind::kNode, next_node++});
    }
    region.nodes = static_cast<int>(nodes.size());
    const std::vector<MeasuredAxes> runs = m.device == cell::MeasureDevice::kTransducer
                                               ? std::vector<MeasuredAxes>{MeasuredAxes::kX, MeasuredAxes::kY}
                                               : std::vector<MeasuredAxes>{MeasuredAxes::kXY};
    // The lines one placement reaches: the transducer's grooves, the
    // probe's holes when the plate's size is declared.
    std::optional<double> reach_mm;
    if (m.device == cell::MeasureDevice::kTransducer) {
      reach_mm = (m.transducer.grooves - 1) * m.transducer.groove_pitch_mm;
    } else if (m.device == cell::MeasureDevice::kProbe && m.probe.holes > 0) {
      reach_mm = (m.probe.holes - 1) * m.probe.hole_pitch_mm;
    }
    const auto x_chunks = Chunks(region.xs.size(), reach_mm, region.pitch_mm);
    const auto y_chunks = Chunks(region.ys.size(), reach_mm, region.pitch_mm);
    const std::size_t region_index = plan.regions.size();
    for (MeasuredAxes run : runs) {
      int checks = 0;
      std::set<int> home;  // nodes already measured as nodes in an earlier piece of this run
      for (const auto& [y0, y1] : y_chunks) {
        for (const auto& [x0, x1] : x_chunks) {
          Piece piece;
          piece.region = region_index;
          piece.axes = run;
          for (const PointOfRegion& node : nodes) {
            const auto i = static_cast<std::size_t>(std::find(region.xs.begin(), region.xs.end(), node.at.x()) -
                                                    region.xs.begin());
            const auto j = static_cast<std::size_t>(std::find(region.ys.begin(), region.ys.end(), node.at.y()) -
                                                    region.ys.begin());
            if (i < x0 || i >= x1 || j < y0 || j >= y1) continue;
            const bool fresh = home.insert(node.node).second;
            piece.points.push_back({node.at, fresh ? VisitKind::kNode : VisitKind::kTie, node.node, region_index});
          }
          if (options.check_points && centres_on_holes) {
            // Probe and external: cell centres. Transducer: on a groove of
            // the measured axis, half way along the other (the groove runs
            // there), so x checks sit between two y lines and y checks
            // between two x lines.
            std::vector<std::size_t> ci = CheckCells(x1 - x0), cj = CheckCells(y1 - y0);
            for (std::size_t b : cj) {
              for (std::size_t a : ci) {
                const std::size_t i = x0 + a, j = y0 + b;
                double x = 0.5 * (region.xs[i] + region.xs[i + 1]);
                double y = 0.5 * (region.ys[j] + region.ys[j + 1]);
                if (run == MeasuredAxes::kX) x = region.xs[i + 1];
                if (run == MeasuredAxes::kY) y = region.ys[j + 1];
                piece.points.push_back({Eigen::Vector2d(RoundUm(x), RoundUm(y)), VisitKind::kCheck, next_node++,
                                        region_index});
                ++checks;
              }
            }
          }
          pieces.push_back(std::move(piece));
        }
      }
      region.check_points = std::max(region.check_points, checks);
    }
    plan.regions.push_back(std::move(region));
  }
  if (diags.error_count() != errors_before) return std::nullopt;

  // The stations: one placement of the artefact each. The probe's plate,
  // when its size is declared, holds every piece whose points fit on it
  // together; otherwise each piece is a station of its own.
  std::optional<double> plate_reach;
  if (m.device == cell::MeasureDevice::kProbe && m.probe.holes > 0) {
    plate_reach = (m.probe.holes - 1) * m.probe.hole_pitch_mm;
  }
  std::vector<StationBuild> stations;
  for (const Piece& piece : pieces) {
    StationBuild* into = nullptr;
    if (plate_reach) {
      for (StationBuild& station : stations) {
        const bool same_region = std::any_of(station.pieces.begin(), station.pieces.end(), [&](std::size_t p) {
          return pieces[p].region == piece.region;
        });
        if (!same_region && station.axes == piece.axes && Fits(station.Bounds().Union(BoxOf(piece.points)), *plate_reach)) {
          into = &station;
          break;
        }
      }
    }
    if (into == nullptr) {
      stations.emplace_back();
      into = &stations.back();
      into->axes = piece.axes;
    }
    into->pieces.push_back(static_cast<std::size_t>(&piece - pieces.data()));
    for (const PointOfRegion& point : piece.points) into->points.push_back(point);
  }
  // Ties: stations that share a node are tied; then, nearest pairs first,
  // a station not yet tied to another measures a line of the other's nodes
  // (or the other way round) when it still fits on the plate.
  std::vector<int> parent(stations.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)];
    return i;
  };
  auto join = [&](std::size_t a, std::size_t b) {
    parent[static_cast<std::size_t>(find(static_cast<int>(a)))] = find(static_cast<int>(b));
    stations[a].tied_to.insert(static_cast<int>(b));
    stations[b].tied_to.insert(static_cast<int>(a));
  };
  if (m.device != cell::MeasureDevice::kExternal) {
    std::map<std::pair<int, MeasuredAxes>, std::size_t> home_of;  // node -> its station
    for (std::size_t s = 0; s < stations.size(); ++s) {
      for (const PointOfRegion& p : stations[s].points) {
        if (p.kind != VisitKind::kTie) home_of.try_emplace({p.node, stations[s].axes}, s);
      }
    }
    for (std::size_t s = 0; s < stations.size(); ++s) {
      for (const PointOfRegion& p : stations[s].points) {
        if (p.kind != VisitKind::kTie) continue;
        auto it = home_of.find({p.node, stations[s].axes});
        if (it != home_of.end() && it->second != s) join(s, it->second);
      }
    }
  }
  if (plate_reach) {
    std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
    for (std::size_t a = 0; a < stations.size(); ++a) {
      for (std::size_t b = a + 1; b < stations.size(); ++b) pairs.emplace_back(Gap(stations[a].Bounds(), stations[b].Bounds()), a, b);
    }
    std::sort(pairs.begin(), pairs.end());
    for (const auto& [gap, a, b] : pairs) {
      if (find(static_cast<int>(a)) == find(static_cast<int>(b))) continue;
      std::optional<TieLine> best;
      std::size_t measurer = a, measured = b;
      for (const auto& [by, of] : {std::pair{b, a}, std::pair{a, b}}) {
        std::optional<TieLine> line = BestTieLine(stations[by], stations[of], *plate_reach);
        if (line && (!best || line->Better(*best))) {
          best = line;
          measurer = by;
          measured = of;
        }
      }
      if (!best) continue;
      for (PointOfRegion p : best->points) {
        p.kind = VisitKind::kTie;
        stations[measurer].points.push_back(p);
      }
      join(measurer, measured);
    }
  }
  // The groups of stations the ties join.
  std::map<int, int> groups;
  for (std::size_t s = 0; s < stations.size(); ++s) groups.try_emplace(find(static_cast<int>(s)), 0);
  if (groups.size() > 1 && m.device != cell::MeasureDevice::kExternal) {
    plan.notes.push_back(fmt::format(
        "the {} stations fall into {} groups that no tie joins{}: the artefact's placement relative to each other "
        "is not measured between them, so measure read carries it ({} mm, {} degree) in every table's registration "
        "uncertainty",
        stations.size(), groups.size(),
        m.device == cell::MeasureDevice::kProbe && m.probe.holes == 0
            ? " (declare the plate's size, [measure.probe] holes, so the plan can put several regions on one "
              "placement and tie the placements)"
            : m.device == cell::MeasureDevice::kTransducer
                  ? " (the grooved plate is mounted apart for x and y and for each region)"
                  : " (the plate cannot reach from one to the other)",
        Mm(m.placement_mm.value_or(accuracy)), Mm(m.placement_deg)));
  }

  // Each station: where the artefact goes, and how far a wall may be off.
  double worst_reach = 0, worst_extent = 0;
  for (std::size_t s = 0; s < stations.size(); ++s) {
    StationBuild& build = stations[s];
    // A point measured twice in one station (a tie that is also a node of
    // a region merged here) is measured once, as the node.
    std::stable_sort(build.points.begin(), build.points.end(), [](const PointOfRegion& a, const PointOfRegion& b) {
      return a.node != b.node ? a.node < b.node : a.kind < b.kind;
    });
    build.points.erase(std::unique(build.points.begin(), build.points.end(),
                                   [](const PointOfRegion& a, const PointOfRegion& b) { return a.node == b.node; }),
                       build.points.end());
    Serpentine(build.points);
    PlanStation station;
    station.number = static_cast<int>(s) + 1;
    station.axes = build.axes;
    for (std::size_t p : build.pieces) {
      if (std::find(station.regions.begin(), station.regions.end(), pieces[p].region) == station.regions.end()) {
        station.regions.push_back(pieces[p].region);
      }
    }
    const Box box = build.Bounds();
    station.origin = Eigen::Vector2d(box.x0, box.y0);
    station.far = Eigen::Vector2d(box.x1, box.y1);
    for (int t : build.tied_to) station.tied_to.push_back(t + 1);
    for (const PointOfRegion& p : build.points) station.ties += p.kind == VisitKind::kTie ? 1 : 0;
    const double extent = (station.far - station.origin).norm();
    worst_extent = std::max(worst_extent, extent);
    plan.stations.push_back(station);
  }
  for (PlanRegion& region : plan.regions) {
    region.stations = 0;
    for (const PlanStation& station : plan.stations) {
      region.stations += static_cast<int>(std::count(station.regions.begin(), station.regions.end(),
                                                      static_cast<std::size_t>(&region - plan.regions.data())));
    }
  }
  if (m.device == cell::MeasureDevice::kProbe) {
    // The probing cycle's clearances: a wall may lie the robot's error,
    // the plate's placement and its turn over the station away from where
    // it is expected.
    const double placement = m.placement_mm.value_or(accuracy);
    const double turn = m.placement_deg * kPi / 180 * worst_extent;
    worst_reach = accuracy + placement + turn;
    plan.probe_reach_mm = worst_reach;
    const double over_needed = worst_reach + kProbeSafetyMarginMm;
    if (m.probe.overtravel_mm < over_needed - 1e-9) {
      diags.Report(DiagKind::MeasureOvertravelTooSmall, m.range, Mm(m.probe.overtravel_mm), CeilUm(over_needed),
                   CeilUm(worst_reach), Mm(accuracy), Mm(placement), Mm(m.placement_deg), Mm(worst_extent),
                   Mm(kProbeSafetyMarginMm), CeilUm(over_needed));
    }
    const double room = ProbeContactRadiusMm(m.probe);
    const double room_needed = plan.approach_mm.norm() + worst_reach + kProbeSafetyMarginMm;
    if (room <= room_needed) {
      diags.Report(DiagKind::MeasureProbeHoleTooSmall, m.range, Mm(room), CeilUm(room_needed),
                   Mm(plan.approach_mm.norm()), CeilUm(worst_reach), Mm(kProbeSafetyMarginMm));
    }
    if (diags.error_count() != errors_before) return std::nullopt;
  }

  // The visits: station by station, set by set, each set closed by the
  // station's first point again.
  for (std::size_t s = 0; s < stations.size(); ++s) {
    const std::vector<PointOfRegion>& points = stations[s].points;
    for (int set = 1; set <= options.sets; ++set) {
      auto add = [&](const PointOfRegion& point, VisitKind kind, int direction) {
        Visit visit;
        visit.number = static_cast<int>(plan.visits.size()) + 1;
        visit.region = point.region;
        visit.axes = stations[s].axes;
        visit.station = static_cast<int>(s) + 1;
        visit.kind = kind;
        visit.node = point.node;
        visit.at = point.at;
        visit.set = set;
        visit.repetitions = options.repetitions;
        visit.direction = direction;
        plan.visits.push_back(visit);
      };
      for (const PointOfRegion& point : points) {
        add(point, point.kind, 1);
        if (options.bidirectional) add(point, point.kind, -1);
      }
      // An external system measures in the robot's frame: no artefact to move.
      if (m.device != cell::MeasureDevice::kExternal) add(points.front(), VisitKind::kClosure, 1);
    }
  }
  const Visit* previous = nullptr;
  for (const Visit& visit : plan.visits) {
    const double t = VisitTimeS(cell, visit, previous);
    plan.regions[visit.region].time_s += t;
    plan.time_s += t;
    previous = &visit;
  }
  return plan;
}

}  // namespace smtcal::measure
