// From readings to errors at the nodes (calibration/measurement_reading.h).
#include "calibration/measurement_reading.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>

#include <fmt/format.h>

#include "calibration/reading_screen.h"

namespace smtcal::measure {
namespace {

// The mean error per node of one axis over a grid, and its bilinear
// interpolation, extrapolated linearly beyond the outer lines (a probe's
// trip lies up to the contact radius past the grid's edge).
class NodeField {
 public:
  NodeField(const std::vector<double>& xs, const std::vector<double>& ys) : xs_(xs), ys_(ys) {
    sum_.assign(xs.size() * ys.size(), 0);
    count_.assign(xs.size() * ys.size(), 0);
  }
  void Add(const Eigen::Vector2d& at, double value) {
    auto i = Find(xs_, at.x()), j = Find(ys_, at.y());
    if (!i || !j) return;  // a check point: not a node
    sum_[*j * xs_.size() + *i] += value;
    ++count_[*j * xs_.size() + *i];
  }
  double At(const Eigen::Vector2d& p) const {
    const auto [i, s] = Cell(xs_, p.x());
    const auto [j, t] = Cell(ys_, p.y());
    return (1 - t) * ((1 - s) * Mean(i, j) + s * Mean(i + 1, j)) + t * ((1 - s) * Mean(i, j + 1) + s * Mean(i + 1, j + 1));
  }

 private:
  static std::optional<std::size_t> Find(const std::vector<double>& lines, double v) {
    auto it = std::find(lines.begin(), lines.end(), v);
    if (it == lines.end()) return std::nullopt;
    return static_cast<std::size_t>(it - lines.begin());
  }
  // The cell [i, i+1] of v (the first or last beyond the ends) and v's
  // fraction in it (outside [0, 1] beyond the ends).
  static std::pair<std::size_t, double> Cell(const std::vector<double>& lines, double v) {
    if (lines.size() < 2) return {0, 0};
    std::size_t i = 0;
    while (i + 2 < lines.size() && v > lines[i + 1]) ++i;
    return {i, (v - lines[i]) / (lines[i + 1] - lines[i])};
  }
  double Mean(std::size_t i, std::size_t j) const {
    if (i >= xs_.size() || j >= ys_.size()) return 0;
    const std::size_t k = j * xs_.size() + i;
    return count_[k] > 0 ? sum_[k] / count_[k] : 0;
  }
  std::vector<double> xs_, ys_;
  std::vector<double> sum_;
  std::vector<int> count_;
};

double Sign(double v) { return v < 0 ? -1.0 : 1.0; }

}  // namespace

std::vector<ReadingError> ErrorsOfReadings(const cell::Measure& measure, const cell::Robot& robot,
                                           const std::vector<PlanRegion>& regions,
                                           const std::vector<Reading>& readings,
                                           const std::vector<Eigen::Vector2d>& registered,
                                           std::vector<std::string>& notes) {
  std::vector<ReadingError> errors;
  auto add = [&](std::size_t k, TableAxis axis, double error) {
    const Reading& r = readings[k];
    errors.push_back({axis, r.at, r.kind, r.set, r.repetition, error, r.where, k});
  };
  if (measure.device == cell::MeasureDevice::kTransducer) {
    const cell::MeasureTransducer& t = measure.transducer;
    for (std::size_t k = 0; k < readings.size(); ++k) {
      const Reading& r = readings[k];
      add(k, r.axes == MeasuredAxes::kY ? TableAxis::Y : TableAxis::X, ((r.a - r.b) - t.zero_mm) / t.slope);
    }
    return errors;
  }
  if (measure.device == cell::MeasureDevice::kExternal) {
    for (std::size_t k = 0; k < readings.size(); ++k) {
      add(k, TableAxis::X, readings[k].external.x() - readings[k].at.x());
      add(k, TableAxis::Y, readings[k].external.y() - readings[k].at.y());
    }
    return errors;
  }
  // The probe.
  const Eigen::Vector2d approach = robot.final_approach_mm.value_or(Eigen::Vector2d(1, 1));
  const double radius = ProbeContactRadiusMm(measure.probe);
  const double late = 0.5 * measure.probe.speed_mm_s * robot.servo_period_s;
  std::vector<double> ex(readings.size()), ey(readings.size());
  auto signs = [&](const Reading& r) {
    return Eigen::Vector2d(Sign(approach.x()) * r.direction, Sign(approach.y()) * r.direction);
  };
  // First: each error where it was measured, taken as the node's.
  for (std::size_t k = 0; k < readings.size(); ++k) {
    const Reading& r = readings[k];
    const Eigen::Vector2d s = signs(r);
    ex[k] = r.at.x() + s.x() * radius - (r.a - s.x() * late);
    ey[k] = r.at.y() + s.y() * radius - (r.b - s.y() * late);
  }
  double largest_offset = 0, largest_move = 0;
  for (int pass = 0; pass < 4; ++pass) {
    // The field of each region from its registered errors, approached as
    // the tables are (the reversed readings carry the backlash besides).
    std::vector<NodeField> fx, fy;
    for (const PlanRegion& region : regions) {
      fx.emplace_back(region.xs, region.ys);
      fy.emplace_back(region.xs, region.ys);
    }
    for (std::size_t k = 0; k < readings.size(); ++k) {
      if (readings[k].direction < 0) continue;
      const Eigen::Vector2d shift = k < registered.size() ? registered[k] : Eigen::Vector2d::Zero();
      fx[readings[k].region].Add(readings[k].at, ex[k] + shift.x());
      fy[readings[k].region].Add(readings[k].at, ey[k] + shift.y());
    }
    largest_move = 0;
    for (std::size_t k = 0; k < readings.size(); ++k) {
      const Reading& r = readings[k];
      const Eigen::Vector2d s = signs(r);
      const NodeField& gx = fx[r.region];
      const NodeField& gy = fy[r.region];
      const Eigen::Vector2d qx(r.a - s.x() * late, r.at.y());  // where the x trip was commanded
      const Eigen::Vector2d qy(r.at.x(), r.b - s.y() * late);
      // The stylus sits off the hole's centre by the other axis's error
      // (this reading's, in its own placement of the plate, moved along
      // the field): it meets the wall on a chord.
      const double off_y = ey[k] + gy.At(qx) - gy.At(r.at);
      const double off_x = ex[k] + gx.At(qy) - gx.At(r.at);
      const double wall_x = r.at.x() + s.x() * std::sqrt(std::max(0.0, radius * radius - off_y * off_y));
      const double wall_y = r.at.y() + s.y() * std::sqrt(std::max(0.0, radius * radius - off_x * off_x));
      const double x = wall_x - qx.x() - (gx.At(qx) - gx.At(r.at));
      const double y = wall_y - qy.y() - (gy.At(qy) - gy.At(r.at));
      largest_move = std::max({largest_move, std::abs(x - ex[k]), std::abs(y - ey[k])});
      largest_offset = std::max({largest_offset, (qx - r.at).norm(), (qy - r.at).norm()});
      ex[k] = x;
      ey[k] = y;
    }
  }
  for (std::size_t k = 0; k < readings.size(); ++k) {
    add(k, TableAxis::X, ex[k]);
    add(k, TableAxis::Y, ey[k]);
  }
  notes.push_back(fmt::format(
      "probe: the trips lay up to {:.3f} mm from their nodes; each error was moved to its node through the measured "
      "field and the stylus's chord (last change {:.1e} mm), and half a servo period of travel ({:.4f} mm) taken "
      "off each trip",
      largest_offset, largest_move, late));
  return errors;
}

namespace {

// The readings of one node along one axis, screened against each other
// (calibration/reading_screen.h): `values[k]` is what the device read for
// readings[index[k]].
void ScreenNode(const std::vector<double>& values, const std::vector<const Reading*>& readings,
                const std::vector<SourceRange>& where, std::string_view what, double noise_mm,
                std::string_view plan_name, Diagnostics& diags) {
  std::vector<long long> sets;
  for (const Reading* r : readings) sets.push_back(r->set);
  const ReadingScreen screen = ScreenReadings(values, sets, noise_mm);
  for (const ReadingOutlier& o : screen.outliers) {
    const Reading& r = *readings[o.index];
    diags.Report(DiagKind::MeasureReadingOutlier, where[o.index], what, r.visit, r.repetition,
                 fmt::format("{:.4f}", values[o.index]), fmt::format("{:.4f}", std::abs(values[o.index] - o.centre_mm)),
                 r.node, fmt::format("{:.4f}", o.centre_mm), fmt::format("{:.4f}", screen.scatter_mm),
                 o.slip.kind == SlipKind::kNone ? "" : "; " + o.slip.Describe(), plan_name, r.visit);
  }
}

// Groups readings by station and node (in order of first appearance),
// each group in reading order.
std::vector<std::vector<std::size_t>> ByNode(const std::vector<Reading>& readings) {
  // One placement of the artefact, one approach: another placement or
  // approach reads another value.
  std::map<std::tuple<int, int, int>, std::size_t> group_of;
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t k = 0; k < readings.size(); ++k) {
    auto [it, fresh] =
        group_of.try_emplace({readings[k].station, readings[k].node, readings[k].direction}, groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(k);
  }
  return groups;
}

// Each node's readings (one station, one approach) screened against each
// other on `value(reading, axis)`, one screen per name in `what`; `where[k]`
// locates readings[k].
template <class Value>
void ScreenEachNode(const std::vector<Reading>& readings, const std::vector<SourceRange>& where,
                    const std::vector<std::string_view>& what, Value value, double noise_mm,
                    std::string_view plan_name, Diagnostics& diags) {
  for (const std::vector<std::size_t>& group : ByNode(readings)) {
    std::vector<const Reading*> members;
    std::vector<SourceRange> at;
    for (std::size_t k : group) {
      members.push_back(&readings[k]);
      at.push_back(where[k]);
    }
    for (std::size_t axis = 0; axis < what.size(); ++axis) {
      std::vector<double> values;
      for (const Reading* r : members) values.push_back(value(*r, static_cast<int>(axis)));
      ScreenNode(values, members, at, what[axis], noise_mm, plan_name, diags);
    }
  }
}

}  // namespace

void CheckReadings(const cell::Measure& measure, const cell::Robot& robot, const std::vector<Reading>& readings,
                   std::string_view plan_name, Diagnostics& diags) {
  const std::size_t errors_before = diags.error_count();
  auto implausible = [&](const Reading& r, std::string what) {
    diags.Report(DiagKind::MeasureReadingImplausible, r.where, std::move(what), r.visit, plan_name, r.visit);
  };
  switch (measure.device) {
    case cell::MeasureDevice::kTransducer:
      for (const Reading& r : readings) {
        for (double value : {r.a, r.b}) {
          if (measure.transducer.range_mm.Contains(value)) continue;
          diags.Report(DiagKind::MeasureReadingOutOfRange, r.where, FormatMm(value),
                       FormatMm(measure.transducer.range_mm.lo), FormatMm(measure.transducer.range_mm.hi), r.visit);
          break;
        }
      }
      break;
    case cell::MeasureDevice::kExternal:
      for (const Reading& r : readings) {
        if (r.a != 0 || r.b != 0) {
          implausible(r, fmt::format("the log of an external device holds 0,0 where this line has {:.4g},{:.4g}", r.a,
                                     r.b));
        }
      }
      return;  // the positions are the external file's: CheckExternalReadings
    case cell::MeasureDevice::kProbe: {
      // The probe move along each axis: from the node + s (radius - over)
      // to + s (radius + over); a trip is latched up to one servo period
      // of travel late.
      const Eigen::Vector2d approach = robot.final_approach_mm.value_or(Eigen::Vector2d(1, 1));
      const double radius = ProbeContactRadiusMm(measure.probe);
      const double over = measure.probe.overtravel_mm;
      const double late = measure.probe.speed_mm_s * robot.servo_period_s + 1e-6;
      for (const Reading& r : readings) {
        for (int axis = 0; axis < 2; ++axis) {
          const double s = (approach[axis] < 0 ? -1.0 : 1.0) * r.direction;
          const double along = s * ((axis == 0 ? r.a : r.b) - r.at[axis]);  // how far past the node, towards the wall
          if (along >= radius - over - 1e-6 && along <= radius + over + late) continue;
          implausible(r, fmt::format("the trip along {} ({:.6g} mm) lies {:.4g} mm from the node towards the wall, "
                                     "outside the probe move's {}..{} mm",
                                     axis == 0 ? "x" : "y", axis == 0 ? r.a : r.b, along,
                                     FormatComputedMm(radius - over), FormatComputedMm(radius + over)));
          break;
        }
      }
      break;
    }
  }
  if (diags.error_count() != errors_before) return;
  // Each node's readings against each other, on what the device read.
  std::vector<SourceRange> where;
  for (const Reading& r : readings) where.push_back(r.where);
  if (measure.device == cell::MeasureDevice::kTransducer) {
    ScreenEachNode(readings, where, {"the transducers' difference"}, [](const Reading& r, int) { return r.a - r.b; },
                   measure.noise_mm, plan_name, diags);
    return;
  }
  ScreenEachNode(readings, where,
                 {"the probe's trip along x (from the node)", "the probe's trip along y (from the node)"},
                 [](const Reading& r, int axis) { return (axis == 0 ? r.a : r.b) - r.at[axis]; }, measure.noise_mm,
                 plan_name, diags);
}

void CheckExternalReadings(const cell::Measure& measure, const cell::Robot& robot,
                           const std::vector<Reading>& readings, const std::vector<SourceRange>& where,
                           std::string_view plan_name, Diagnostics& diags) {
  const std::size_t errors_before = diags.error_count();
  const double limit = 2 * robot.uncalibrated_accuracy_mm.value_or(kPlanAssumedAccuracyMm);
  for (std::size_t k = 0; k < readings.size(); ++k) {
    const Reading& r = readings[k];
    const double off = (r.external - r.at).norm();
    if (off <= limit) continue;
    diags.Report(DiagKind::MeasureReadingImplausible, where[k],
                 fmt::format("the external system's position ({:.6g}, {:.6g}) lies {:.4g} mm from the node, more "
                             "than twice the robot's declared error ({} mm)",
                             r.external.x(), r.external.y(), off, FormatComputedMm(limit / 2)),
                 r.visit, plan_name, r.visit);
  }
  if (diags.error_count() != errors_before) return;
  ScreenEachNode(readings, where, {"the external system's x error", "the external system's y error"},
                 [](const Reading& r, int axis) { return r.external[axis] - r.at[axis]; }, measure.noise_mm, plan_name,
                 diags);
}

std::string PlanDigest(std::string_view text) {
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a
  for (char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  return fmt::format("{:016x}", hash);
}

}  // namespace smtcal::measure
