// Test helpers shared by the interpolation-error and budget property tests:
// the independent model's robot, a random smooth error field, and error
// tables measured from it with noise, with check points at the cell centres.
#pragma once

#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "calibration/error_table.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal::test {

using Field = std::function<double(double, double)>;

// The paper's measurement: 20 readings of 2.5 µm scatter per node.
inline constexpr double kReadingScatterMm = 0.0025;
inline constexpr int kReadings = 20;

// How the nodes and check points are measured: `readings` readings of
// `scatter` each, the mean and the sample stddev written (a draw of the
// readings when rng is given; otherwise the exact value, with the scatter
// and count stated).
struct Measurement {
  int readings = kReadings;
  double scatter_mm = kReadingScatterMm;
};

// A value as a table row states it: the mean of the readings and their
// sample stddev.
struct Reading {
  double mean = 0, stddev = 0;
};
inline Reading Read(double truth, const Measurement& m, std::mt19937_64* rng) {
  if (rng == nullptr) return {truth, m.scatter_mm};
  std::normal_distribution<double> normal(0, m.scatter_mm);
  double sum = 0, squares = 0;
  std::vector<double> values;
  for (int k = 0; k < m.readings; ++k) values.push_back(truth + normal(*rng));
  for (double v : values) sum += v;
  const double mean = sum / m.readings;
  for (double v : values) squares += (v - mean) * (v - mean);
  return {mean, m.readings > 1 ? std::sqrt(squares / (m.readings - 1)) : 0.0};
}

// A table of `nodes` x `nodes` at `pitch` from `origin` whose Delta-x and
// Delta-y nodes are the field measured as `m` says, with a check point at
// every cell centre measured the same way.
inline ErrorTable Measure(const Field& fx, const Field& fy, double pitch, int nodes, std::mt19937_64* rng,
                   bool checks = true, const Measurement& m = {}, Eigen::Vector2d origin = Eigen::Vector2d::Zero()) {
  ErrorTable table;
  table.name = "measured";
  for (TableAxis axis : kTableAxes) {
    const Field& f = axis == TableAxis::X ? fx : fy;
    AxisTable& t = table[axis];
    for (int i = 0; i < nodes; ++i) t.xs.push_back(origin.x() + pitch * i);
    for (int j = 0; j < nodes; ++j) t.ys.push_back(origin.y() + pitch * j);
    for (int j = 0; j < nodes; ++j) {
      for (int i = 0; i < nodes; ++i) {
        const Reading r = Read(f(t.xs[static_cast<std::size_t>(i)], t.ys[static_cast<std::size_t>(j)]), m, rng);
        t.error_mm.push_back(r.mean);
        t.stddev_mm.push_back(r.stddev);
        t.count.push_back(m.readings);
      }
    }
    if (!checks) continue;
    for (int j = 0; j + 1 < nodes; ++j) {
      for (int i = 0; i + 1 < nodes; ++i) {
        TableNode check;
        check.kind = ReadingKind::kCheck;
        check.axis = axis;
        check.x_mm = origin.x() + pitch * (i + 0.5);
        check.y_mm = origin.y() + pitch * (j + 0.5);
        const Reading r = Read(f(check.x_mm, check.y_mm), m, rng);
        check.error_mm = r.mean;
        check.stddev_mm = r.stddev;
        check.count = m.readings;
        t.checks.push_back(check);
      }
    }
  }
  return table;
}

// A smooth random field: six plane waves of wavelengths from `shortest` to
// 3 x `shortest`, random directions, phases and weights, scaled so that the
// weights sum to `amplitude`.
inline Field RandomField(std::mt19937_64& rng, double shortest, double amplitude) {
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

}  // namespace smtcal::test
