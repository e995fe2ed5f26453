// Property tests of the direct and inverse calibration over random smooth
// tables and random points. Every test prints its seed on failure; set
// SMTCAL_TEST_SEED to rerun with another one (the default is fixed, so CI is
// deterministic).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numbers>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/error_table.h"
#include "calibration/error_table_check.h"
#include "calibration/inverse_calibration.h"
#include "calibration/tolerances.h"

namespace smtcal {
namespace {

std::uint64_t BaseSeed() {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : 20240521;
}

double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// Strictly increasing lines from `origin`, `count` of them, with pitches
// varying around `pitch` (non-uniform grids exercise the cell lookup).
std::vector<double> Lines(std::mt19937_64& rng, double origin, int count, double pitch, bool uniform) {
  std::vector<double> lines = {origin};
  for (int i = 1; i < count; ++i) lines.push_back(lines.back() + (uniform ? pitch : pitch * Uniform(rng, 0.4, 1.6)));
  return lines;
}

// A smooth random field: a plane plus a few waves.
struct Field {
  double c0, cx, cy;
  struct Wave {
    double amplitude, kx, ky, phase;
  };
  std::vector<Wave> waves;
  double operator()(double x, double y) const {
    double v = c0 + cx * x + cy * y;
    for (const Wave& w : waves) v += w.amplitude * std::sin(w.kx * x + w.ky * y + w.phase);
    return v;
  }
};

Field RandomField(std::mt19937_64& rng, double span) {
  Field f{Uniform(rng, -0.1, 0.1), Uniform(rng, -1, 1), Uniform(rng, -1, 1), {}};
  int waves = static_cast<int>(Uniform(rng, 0, 4));
  for (int k = 0; k < waves; ++k) {
    double wavelength = span * Uniform(rng, 0.3, 2.0);
    double angle = Uniform(rng, 0, 2 * std::numbers::pi);
    f.waves.push_back({Uniform(rng, 0.2, 1.0), 2 * std::numbers::pi / wavelength * std::cos(angle),
                       2 * std::numbers::pi / wavelength * std::sin(angle), Uniform(rng, 0, 6.3)});
  }
  return f;
}

// A random table: both axes on their own grids (offset from each other by
// a few micrometres, or by a lot), values from smooth fields scaled so the
// contraction factor is `slope`.
ErrorTable RandomTable(std::mt19937_64& rng, double slope) {
  ErrorTable table;
  table.name = "random";
  const double origin_x = Uniform(rng, -500, 500), origin_y = Uniform(rng, -500, 500);
  const double pitch = Uniform(rng, 1, 20);
  const int nx = static_cast<int>(Uniform(rng, 2, 13)), ny = static_cast<int>(Uniform(rng, 2, 13));
  const bool uniform = Uniform(rng, 0, 1) < 0.5;
  const bool small_offset = Uniform(rng, 0, 1) < 0.7;
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = table[axis];
    double ox = origin_x, oy = origin_y;
    if (axis == TableAxis::Y) {
      ox += small_offset ? Uniform(rng, -0.01, 0.01) : Uniform(rng, -0.3, 0.3) * pitch;
      oy += small_offset ? Uniform(rng, -0.01, 0.01) : Uniform(rng, -0.3, 0.3) * pitch;
    }
    t.xs = Lines(rng, ox, nx, pitch, uniform);
    t.ys = Lines(rng, oy, ny, pitch, uniform);
    Field field = RandomField(rng, pitch * std::max(nx, ny));
    for (double y : t.ys) {
      for (double x : t.xs) t.error_mm.push_back(field(x - origin_x, y - origin_y));
    }
  }
  // Scale both tables together to the wanted contraction factor.
  TableAnalysis analysis = AnalyzeTable(table);
  double scale = analysis.contraction > 0 ? slope / analysis.contraction : 0;
  for (AxisTable& t : table.axes) {
    for (double& v : t.error_mm) v *= scale;
  }
  return table;
}

bool IsValid(const ErrorTable& table) {
  SourceManager sources;
  Diagnostics diags(sources);
  return ValidateErrorTable(table, diags, TableWarnings::kSkip);
}

Eigen::Vector2d RandomInside(std::mt19937_64& rng, const Rect& r) {
  return {Uniform(rng, r.x0, r.x1), Uniform(rng, r.y0, r.y1)};
}

// Points that stress the piecewise structure: every union grid line crossing
// inside the domain, the domain's corners and edges.
std::vector<Eigen::Vector2d> SpecialPoints(const ErrorTable& table, const Rect& d) {
  std::vector<double> xs = {d.x0, d.x1, 0.5 * (d.x0 + d.x1)}, ys = {d.y0, d.y1, 0.5 * (d.y0 + d.y1)};
  for (const AxisTable& t : table.axes) {
    for (double x : t.xs) {
      if (x >= d.x0 && x <= d.x1) xs.push_back(x);
    }
    for (double y : t.ys) {
      if (y >= d.y0 && y <= d.y1) ys.push_back(y);
    }
  }
  std::vector<Eigen::Vector2d> points;
  for (double x : xs) {
    for (double y : ys) points.emplace_back(x, y);
  }
  return points;
}

constexpr int kTables = 60;
constexpr int kPointsPerTable = 300;

TEST(InverseProperty, NodesAreExact) {
  for (int k = 0; k < kTables; ++k) {
    const std::uint64_t seed = BaseSeed() + static_cast<std::uint64_t>(k);
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937_64 rng(seed);
    ErrorTable table = RandomTable(rng, Uniform(rng, 0, 0.3));
    CalibrationMap map(table);
    for (TableAxis axis : kTableAxes) {
      const AxisTable& t = table[axis];
      for (std::size_t j = 0; j < t.ny(); ++j) {
        for (std::size_t i = 0; i < t.nx(); ++i) {
          ASSERT_EQ(map.AxisDelta(axis, t.xs[i], t.ys[j]), t.At(i, j)) << "node " << i << "," << j;
          Eigen::Vector2d node(t.xs[i], t.ys[j]);
          if (map.Inside(node) && map.ClampToDomain(node) == node) {
            ASSERT_EQ(map.Delta(node)[static_cast<int>(axis)], t.At(i, j));
          }
        }
      }
    }
  }
}

TEST(InverseProperty, LinearFieldsAreReproduced) {
  for (int k = 0; k < kTables; ++k) {
    const std::uint64_t seed = BaseSeed() + 1000 + static_cast<std::uint64_t>(k);
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937_64 rng(seed);
    ErrorTable table = RandomTable(rng, 0.1);
    // Replace the values by a linear field per axis.
    std::array<std::array<double, 3>, 2> c;
    for (TableAxis axis : kTableAxes) {
      AxisTable& t = table[axis];
      auto& [c0, cx, cy] = c[static_cast<int>(axis)];
      c0 = Uniform(rng, -0.2, 0.2), cx = Uniform(rng, -0.01, 0.01), cy = Uniform(rng, -0.01, 0.01);
      t.error_mm.clear();
      for (double y : t.ys) {
        for (double x : t.xs) t.error_mm.push_back(c0 + cx * (x - t.xs[0]) + cy * (y - t.ys[0]));
      }
    }
    CalibrationMap map(table);
    for (int p = 0; p < kPointsPerTable; ++p) {
      Eigen::Vector2d n = RandomInside(rng, map.domain());
      Eigen::Vector2d delta;
      Eigen::Matrix2d jacobian;
      map.DeltaAndJacobian(n, delta, jacobian);
      for (TableAxis axis : kTableAxes) {
        int a = static_cast<int>(axis);
        const AxisTable& t = table[axis];
        auto [c0, cx, cy] = c[a];
        double expected = c0 + cx * (n.x() - t.xs[0]) + cy * (n.y() - t.ys[0]);
        ASSERT_NEAR(delta[a], expected, 1e-12) << "at " << n.transpose();
        ASSERT_NEAR(jacobian(a, 0), cx, 1e-12);
        ASSERT_NEAR(jacobian(a, 1), cy, 1e-12);
      }
    }
  }
}

// The core property: F(inverse(a)) = a within 1e-9 mm, within the bound.
void CheckInverse(const ErrorTable& table, std::mt19937_64& rng, double* worst_residual, int* most_iterations) {
  InverseSolver solver(table);
  const CalibrationMap& map = solver.map();
  const double lipschitz_inverse = 1 / (1 - solver.contraction());
  std::vector<Eigen::Vector2d> nominals = SpecialPoints(table, map.domain());
  for (int p = 0; p < kPointsPerTable; ++p) nominals.push_back(RandomInside(rng, map.domain()));
  for (const Eigen::Vector2d& n : nominals) {
    Solution forward = DirectCalibrate(map, n, OutsidePolicy::kError);
    ASSERT_EQ(forward.status, SolveStatus::kOk);
    const Eigen::Vector2d a = forward.point;
    Solution s = solver.Solve(a, OutsidePolicy::kClamp);
    ASSERT_NE(s.status, SolveStatus::kNotConverged) << "a = " << a.transpose();
    ASSERT_LE(s.iterations, solver.iteration_bound());
    ASSERT_LE(s.residual_mm, kInverseResidualTolMm) << "a = " << a.transpose();
    // The reported residual is the true one.
    ASSERT_EQ(s.residual_mm, (s.point + map.Delta(s.point) - a).norm());
    // And the solution is the nominal point (F is injective).
    ASSERT_LE((s.point - n).lpNorm<Eigen::Infinity>(), lipschitz_inverse * s.residual_mm * 1.5 + 1e-12);
    *worst_residual = std::max(*worst_residual, s.residual_mm);
    *most_iterations = std::max(*most_iterations, s.iterations);
  }
}

TEST(InverseProperty, InverseOfForwardIsIdentity) {
  double worst = 0;
  int most = 0;
  for (int k = 0; k < kTables; ++k) {
    const std::uint64_t seed = BaseSeed() + 2000 + static_cast<std::uint64_t>(k);
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937_64 rng(seed);
    ErrorTable table = RandomTable(rng, Uniform(rng, 0, 0.29));
    ASSERT_TRUE(IsValid(table));
    CheckInverse(table, rng, &worst, &most);
  }
  RecordProperty("worst_residual_mm", fmt::format("{:.3e}", worst));
  RecordProperty("most_iterations", most);
}

// Tables near the validation limits (L close to kMaxErrorSlope): the bound is
// large and Newton steps across cell boundaries get rejected more often.
TEST(InverseProperty, SteepValidTablesStayWithinTheBound) {
  double worst = 0;
  int most = 0, checked = 0;
  for (int k = 0; k < 4 * kTables && checked < kTables; ++k) {
    const std::uint64_t seed = BaseSeed() + 3000 + static_cast<std::uint64_t>(k);
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937_64 rng(seed);
    ErrorTable table = RandomTable(rng, Uniform(rng, 0.3, kMaxErrorSlope));
    if (!IsValid(table)) continue;  // folds or nearly folds: validation's job
    ++checked;
    CheckInverse(table, rng, &worst, &most);
  }
  EXPECT_GE(checked, kTables / 2) << "the generator should find enough steep valid tables";
}

TEST(InverseProperty, ClampedInverseConvergesEverywhere) {
  for (int k = 0; k < kTables; ++k) {
    const std::uint64_t seed = BaseSeed() + 4000 + static_cast<std::uint64_t>(k);
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937_64 rng(seed);
    ErrorTable table = RandomTable(rng, Uniform(rng, 0, 0.29));
    InverseSolver solver(table);
    const Rect d = solver.map().domain();
    const double wx = d.x1 - d.x0, wy = d.y1 - d.y0;
    for (int p = 0; p < kPointsPerTable; ++p) {
      Eigen::Vector2d a(Uniform(rng, d.x0 - wx, d.x1 + wx), Uniform(rng, d.y0 - wy, d.y1 + wy));
      Solution s = solver.Solve(a, OutsidePolicy::kClamp);
      ASSERT_LE(s.iterations, solver.iteration_bound());
      ASSERT_LE(s.residual_mm, kInverseResidualTolMm);
      ASSERT_EQ(s.status, solver.map().Inside(s.point) ? SolveStatus::kOk : SolveStatus::kClamped);
    }
  }
}

TEST(InverseProperty, OutsidePolicies) {
  std::mt19937_64 rng(BaseSeed() + 5000);
  SCOPED_TRACE(fmt::format("seed {}", BaseSeed() + 5000));
  ErrorTable table = RandomTable(rng, 0.05);
  InverseSolver solver(table);
  PaperSolver paper(table);
  const Rect d = solver.map().domain();
  const Eigen::Vector2d outside(d.x1 + 10 * (d.x1 - d.x0), d.y0 - 3);
  for (OutsidePolicy policy : {OutsidePolicy::kError, OutsidePolicy::kClamp, OutsidePolicy::kNone}) {
    Solution forward = DirectCalibrate(solver.map(), outside, policy);
    Solution inverse = solver.Solve(outside, policy);
    Solution by_paper = paper.Solve(outside, policy);
    for (const Solution& s : {forward, inverse, by_paper}) {
      EXPECT_TRUE(std::isfinite(s.point.x()) && std::isfinite(s.point.y()));
      switch (policy) {
        case OutsidePolicy::kError: EXPECT_EQ(s.status, SolveStatus::kOutside); break;
        case OutsidePolicy::kClamp: EXPECT_EQ(s.status, SolveStatus::kClamped); break;
        case OutsidePolicy::kNone:
          EXPECT_EQ(s.status, SolveStatus::kUncorrected);
          EXPECT_EQ(s.point, outside);
          EXPECT_EQ(s.iterations, 0);
          break;
      }
    }
  }
  // Clamped: the edge values of Delta, i.e. Delta at the corner (x1, y0).
  Solution clamped = DirectCalibrate(solver.map(), outside, OutsidePolicy::kClamp);
  Eigen::Vector2d corner(d.x1, d.y0);
  EXPECT_EQ(clamped.point, outside + solver.map().Delta(corner));
}

// The outside policy holds even when the paper's solver runs out of steps:
// a point outside is refused or left unchanged, never corrected silently.
TEST(InverseProperty, OutsidePoliciesHoldWhenThePaperSolverDoesNotConverge) {
  std::mt19937_64 rng(BaseSeed() + 5500);
  SCOPED_TRACE(fmt::format("seed {}", BaseSeed() + 5500));
  ErrorTable table = RandomTable(rng, 0.05);
  PaperSolver paper(table, 1e-300, 2);  // two steps never reach 1e-300 mm
  const Rect d = paper.map().domain();
  const Eigen::Vector2d outside(0.5 * (d.x0 + d.x1), d.y1 + 10);
  EXPECT_EQ(paper.Solve(outside, OutsidePolicy::kError).status, SolveStatus::kOutside);
  Solution none = paper.Solve(outside, OutsidePolicy::kNone);
  EXPECT_EQ(none.status, SolveStatus::kUncorrected);
  EXPECT_EQ(none.point, outside);
  EXPECT_EQ(paper.Solve(outside, OutsidePolicy::kClamp).status, SolveStatus::kNotConverged);
  const Eigen::Vector2d inside(0.5 * (d.x0 + d.x1), 0.5 * (d.y0 + d.y1));
  EXPECT_EQ(paper.Solve(inside + paper.map().Delta(inside), OutsidePolicy::kError).status,
            SolveStatus::kNotConverged);
}

TEST(InverseProperty, PaperSolverStopsWithinItsTolerance) {
  int most_steps = 0;
  for (double tolerance : {kPaperSolverTolMm, 1e-6}) {
    for (int k = 0; k < kTables / 2; ++k) {
      const std::uint64_t seed = BaseSeed() + 6000 + static_cast<std::uint64_t>(k);
      SCOPED_TRACE(fmt::format("seed {}, tolerance {}", seed, tolerance));
      std::mt19937_64 rng(seed);
      ErrorTable table = RandomTable(rng, Uniform(rng, 0, 0.2));
      PaperSolver paper(table, tolerance);
      const CalibrationMap& map = paper.map();
      for (int p = 0; p < kPointsPerTable / 3; ++p) {
        Eigen::Vector2d n = RandomInside(rng, map.domain());
        Eigen::Vector2d a = n + map.Delta(n);
        Solution s = paper.Solve(a, OutsidePolicy::kClamp);
        ASSERT_NE(s.status, SolveStatus::kNotConverged) << "a = " << a.transpose();
        ASSERT_LE(s.residual_mm, tolerance);
        ASSERT_LE(s.iterations, kPaperSolverMaxSteps);
        ASSERT_GE(s.iterations, 2);
        most_steps = std::max(most_steps, s.iterations);
      }
    }
  }
  RecordProperty("paper_most_steps", most_steps);
}

TEST(InverseProperty, ZeroAndConstantTables) {
  std::mt19937_64 rng(BaseSeed() + 7000);
  ErrorTable table = RandomTable(rng, 0.1);
  for (AxisTable& t : table.axes) std::fill(t.error_mm.begin(), t.error_mm.end(), 0.0);
  InverseSolver zero(table);
  EXPECT_EQ(zero.iteration_bound(), 0);
  Eigen::Vector2d a = RandomInside(rng, zero.map().domain());
  Solution s = zero.Solve(a, OutsidePolicy::kError);
  EXPECT_EQ(s.point, a);
  EXPECT_EQ(s.iterations, 0);
  EXPECT_EQ(s.residual_mm, 0);

  for (AxisTable& t : table.axes) std::fill(t.error_mm.begin(), t.error_mm.end(), 0.125);
  InverseSolver constant(table);
  EXPECT_EQ(constant.iteration_bound(), 1);
  s = constant.Solve(a, OutsidePolicy::kClamp);
  EXPECT_EQ(s.iterations, 1);
  EXPECT_LE(s.residual_mm, 1e-12);
}

TEST(InverseProperty, IterationBoundIsTheSmallestThatProvablySuffices) {
  const double target = kInverseResidualTolMm / 2;
  EXPECT_EQ(IterationBound(0.3, 0), 0);
  EXPECT_EQ(IterationBound(0.0, 0.1), 1);
  for (double contraction : {1e-4, 0.006, 0.05, 0.3, 0.5}) {
    for (double d : {1e-10, 1e-6, 0.153, 1.0, 30.0}) {
      int k = IterationBound(contraction, d);
      SCOPED_TRACE(fmt::format("L {}, D {}, bound {}", contraction, d, k));
      EXPECT_LE(std::sqrt(2.0) * std::pow(contraction, k) * d, target * (1 + 1e-12));
      if (k > 0) {
        EXPECT_GT(std::sqrt(2.0) * std::pow(contraction, k - 1) * d, target);
      }
    }
  }
}

}  // namespace
}  // namespace smtcal
