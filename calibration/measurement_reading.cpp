// From readings to errors at the nodes (calibration/measurement_reading.h).
#include "calibration/measurement_reading.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>

#include <fmt/format.h>

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
                                           const std::vector<double>& xs, const std::vector<double>& ys,
                                           const std::vector<Reading>& readings, std::vector<std::string>& notes) {
  std::vector<ReadingError> errors;
  auto add = [&](const Reading& r, TableAxis axis, double error) {
    errors.push_back({axis, r.at, r.kind, r.set, r.repetition, error, r.where});
  };
  if (measure.device == cell::MeasureDevice::kTransducer) {
    const cell::MeasureTransducer& t = measure.transducer;
    for (const Reading& r : readings) {
      add(r, r.axes == MeasuredAxes::kY ? TableAxis::Y : TableAxis::X, ((r.a - r.b) - t.zero_mm) / t.slope);
    }
    return errors;
  }
  if (measure.device == cell::MeasureDevice::kExternal) {
    for (const Reading& r : readings) {
      add(r, TableAxis::X, r.external.x() - r.at.x());
      add(r, TableAxis::Y, r.external.y() - r.at.y());
    }
    return errors;
  }
  // The probe.
  const Eigen::Vector2d approach = robot.final_approach_mm.value_or(Eigen::Vector2d(1, 1));
  const double sx = Sign(approach.x()), sy = Sign(approach.y());
  const double radius = ProbeContactRadiusMm(measure.probe);
  const double late = 0.5 * measure.probe.speed_mm_s * robot.servo_period_s;
  std::vector<double> ex(readings.size()), ey(readings.size());
  // First: each error where it was measured, taken as the node's.
  for (std::size_t k = 0; k < readings.size(); ++k) {
    const Reading& r = readings[k];
    ex[k] = r.at.x() + sx * radius - (r.a - sx * late);
    ey[k] = r.at.y() + sy * radius - (r.b - sy * late);
  }
  double largest_offset = 0, largest_move = 0;
  for (int pass = 0; pass < 4; ++pass) {
    NodeField fx(xs, ys), fy(xs, ys);
    for (std::size_t k = 0; k < readings.size(); ++k) {
      fx.Add(readings[k].at, ex[k]);
      fy.Add(readings[k].at, ey[k]);
    }
    largest_move = 0;
    for (std::size_t k = 0; k < readings.size(); ++k) {
      const Reading& r = readings[k];
      const Eigen::Vector2d qx(r.a - sx * late, r.at.y());  // where the x trip was commanded
      const Eigen::Vector2d qy(r.at.x(), r.b - sy * late);
      // The stylus sits off the hole's centre by the other axis's error: it
      // meets the wall on a chord.
      const double off_y = fy.At(qx), off_x = fx.At(qy);
      const double wall_x = r.at.x() + sx * std::sqrt(std::max(0.0, radius * radius - off_y * off_y));
      const double wall_y = r.at.y() + sy * std::sqrt(std::max(0.0, radius * radius - off_x * off_x));
      const double x = wall_x - qx.x() - (fx.At(qx) - fx.At(r.at));
      const double y = wall_y - qy.y() - (fy.At(qy) - fy.At(r.at));
      largest_move = std::max({largest_move, std::abs(x - ex[k]), std::abs(y - ey[k])});
      largest_offset = std::max({largest_offset, (qx - r.at).norm(), (qy - r.at).norm()});
      ex[k] = x;
      ey[k] = y;
    }
  }
  for (std::size_t k = 0; k < readings.size(); ++k) {
    add(readings[k], TableAxis::X, ex[k]);
    add(readings[k], TableAxis::Y, ey[k]);
  }
  notes.push_back(fmt::format(
      "probe: the trips lay up to {:.3f} mm from their nodes; each error was moved to its node through the measured "
      "field and the stylus's chord (last change {:.1e} mm), and half a servo period of travel ({:.4f} mm) taken "
      "off each trip",
      largest_offset, largest_move, late));
  return errors;
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
