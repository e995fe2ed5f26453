// The measurement plan (calibration/measurement_plan.h, docs/measure.md).
#include "calibration/measurement_plan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

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
std::vector<double> GridLines(const cell::Interval& bounds, double margin, double pitch, const cell::Interval& limit) {
  const double span = bounds.hi - bounds.lo + 2 * margin;
  const int cells = std::max(1, static_cast<int>(std::ceil(span / pitch - 1e-9)));
  double first = 0.5 * (bounds.lo + bounds.hi) - 0.5 * cells * pitch;
  first = std::min(first, bounds.lo - margin);  // rounding never uncovers the margin
  if (first < limit.lo) first = std::min(limit.lo, bounds.lo - margin);
  if (first + cells * pitch > limit.hi) first = std::max(limit.hi - cells * pitch, bounds.hi + margin - cells * pitch);
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

// The index ranges [begin, end) of the lines one mounting of the plate
// reaches: its grooves span (grooves - 1) groove pitches.
std::vector<std::pair<std::size_t, std::size_t>> Stations(std::size_t lines, const cell::MeasureTransducer& plate,
                                                          double pitch) {
  std::vector<std::pair<std::size_t, std::size_t>> chunks;
  const double reach = (plate.grooves - 1) * plate.groove_pitch_mm;
  const std::size_t per = std::max<std::size_t>(2, static_cast<std::size_t>(std::floor(reach / pitch + 1e-9)) + 1);
  const std::size_t count = (lines + per - 1) / per;
  // Spread the lines evenly over the mountings.
  std::size_t begin = 0;
  for (std::size_t k = 0; k < count; ++k) {
    std::size_t size = (lines - begin) / (count - k);
    chunks.push_back({begin, begin + size});
    begin += size;
  }
  return chunks;
}

struct PointOfRegion {
  Eigen::Vector2d at;
  VisitKind kind;
  int node;
};

// Serpentine order: rows by y, alternating x direction; every point is
// reached by the same final approach, so the order only saves travel.
void Serpentine(std::vector<PointOfRegion>& points) {
  std::sort(points.begin(), points.end(), [](const PointOfRegion& a, const PointOfRegion& b) {
    return a.at.y() != b.at.y() ? a.at.y() < b.at.y() : a.at.x() < b.at.x();
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

std::string_view VisitKindName(VisitKind kind) { return kind == VisitKind::kNode ? "node" : "check"; }

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
    // Per axis: to the slow start, the probe move, back to the approach point and in.
    const double slow = 2 * m.probe.overtravel_mm;
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
    if (groups.empty() || groups.back().region != v.region || groups.back().axes != v.axes ||
        groups.back().station != v.station) {
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
  if (m.device == cell::MeasureDevice::kProbe) {
    const double room = ProbeContactRadiusMm(m.probe);
    if (room <= plan.approach_mm.norm() + accuracy + m.probe.overtravel_mm) {
      diags.Report(DiagKind::MeasureProbeHoleTooSmall, m.range, Mm(room), Mm(plan.approach_mm.norm()), Mm(accuracy),
                   Mm(m.probe.overtravel_mm));
      return std::nullopt;
    }
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
    region.xs = GridLines(region.x_mm, region.margin_mm, region.pitch_mm, usable[0]);
    region.ys = GridLines(region.y_mm, region.margin_mm, region.pitch_mm, usable[1]);
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

    // The points: nodes numbered row by row, then the check points.
    std::vector<PointOfRegion> nodes;
    for (double y : region.ys) {
      for (double x : region.xs) nodes.push_back({Eigen::Vector2d(x, y), VisitKind::kNode, next_node++});
    }
    region.nodes = static_cast<int>(nodes.size());
    std::vector<MeasuredAxes> runs;
    if (m.device == cell::MeasureDevice::kTransducer) {
      runs = {MeasuredAxes::kX, MeasuredAxes::kY};
    } else {
      runs = {MeasuredAxes::kXY};
    }
    const auto x_stations = m.device == cell::MeasureDevice::kTransducer
                                ? Stations(region.xs.size(), m.transducer, region.pitch_mm)
                                : std::vector<std::pair<std::size_t, std::size_t>>{{0, region.xs.size()}};
    const auto y_stations = m.device == cell::MeasureDevice::kTransducer
                                ? Stations(region.ys.size(), m.transducer, region.pitch_mm)
                                : std::vector<std::pair<std::size_t, std::size_t>>{{0, region.ys.size()}};
    region.stations = static_cast<int>(x_stations.size() * y_stations.size());
    for (MeasuredAxes run : runs) {
      int station = 0;
      int checks = 0;
      for (const auto& [y0, y1] : y_stations) {
        for (const auto& [x0, x1] : x_stations) {
          ++station;
          std::vector<PointOfRegion> points;
          for (const PointOfRegion& node : nodes) {
            const auto i = static_cast<std::size_t>(std::find(region.xs.begin(), region.xs.end(), node.at.x()) -
                                                    region.xs.begin());
            const auto j = static_cast<std::size_t>(std::find(region.ys.begin(), region.ys.end(), node.at.y()) -
                                                    region.ys.begin());
            if (i >= x0 && i < x1 && j >= y0 && j < y1) points.push_back(node);
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
                points.push_back({Eigen::Vector2d(RoundUm(x), RoundUm(y)), VisitKind::kCheck, next_node++});
                ++checks;
              }
            }
          }
          Serpentine(points);
          for (int set = 1; set <= options.sets; ++set) {
            for (const PointOfRegion& point : points) {
              Visit visit;
              visit.number = static_cast<int>(plan.visits.size()) + 1;
              visit.region = plan.regions.size();
              visit.axes = run;
              visit.station = station;
              visit.kind = point.kind;
              visit.node = point.node;
              visit.at = point.at;
              visit.set = set;
              visit.repetitions = options.repetitions;
              plan.visits.push_back(visit);
            }
          }
        }
      }
      region.check_points = std::max(region.check_points, checks);
    }
    plan.regions.push_back(std::move(region));
  }
  if (diags.error_count() != errors_before) return std::nullopt;
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
