// Assembly and validation of error tables: the grid checks, the exact fold
// and slope analysis (checked against dense sampling), the warnings, and the
// statistics. Random tables print their seed on failure (SMTCAL_TEST_SEED
// overrides the fixed default).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/error_table.h"
#include "calibration/error_table_check.h"
#include "calibration/tolerances.h"

namespace smtcal {
namespace {

std::uint64_t BaseSeed() {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : 20240521;
}

// A table on 3 x 3 grids (10 mm pitch, the y grid offset by (0.004, -0.003))
// with Delta-x = fx(x, y), Delta-y = fy(x, y).
template <typename Fx, typename Fy>
ErrorTable SmallTable(Fx fx, Fy fy) {
  ErrorTable table;
  table.name = "small";
  for (TableAxis axis : kTableAxes) {
    AxisTable& t = table[axis];
    double ox = axis == TableAxis::Y ? 0.004 : 0, oy = axis == TableAxis::Y ? -0.003 : 0;
    t.xs = {ox, ox + 10, ox + 20};
    t.ys = {oy, oy + 10, oy + 20};
    for (double y : t.ys) {
      for (double x : t.xs) t.error_mm.push_back(axis == TableAxis::X ? fx(x, y) : fy(x, y));
    }
  }
  return table;
}

std::vector<TableNode> NodesOf(const ErrorTable& table) {
  std::vector<TableNode> nodes;
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) {
        TableNode node;
        node.axis = axis;
        node.x_mm = t.xs[i];
        node.y_mm = t.ys[j];
        node.error_mm = t.At(i, j);
        nodes.push_back(node);
      }
    }
  }
  return nodes;
}

std::vector<DiagKind> Kinds(const Diagnostics& diags) {
  std::vector<DiagKind> kinds;
  for (const Diagnostic& d : diags.all()) kinds.push_back(d.kind);
  return kinds;
}

const auto kSmoothX = [](double x, double y) { return -0.05 - 0.001 * x - 0.0004 * y; };
const auto kSmoothY = [](double x, double y) { return 0.01 + 0.0003 * x + 0.0002 * y; };

TEST(TableAssembly, BuildsTheGridFromNodesInAnyOrder) {
  ErrorTable expected = SmallTable(kSmoothX, kSmoothY);
  std::vector<TableNode> nodes = NodesOf(expected);
  std::mt19937_64 rng(7);
  std::shuffle(nodes.begin(), nodes.end(), rng);
  SourceManager sources;
  Diagnostics diags(sources);
  std::optional<ErrorTable> table = AssembleErrorTable("t", nodes, SourceLoc{}, diags);
  ASSERT_TRUE(table.has_value()) << diags.RenderText();
  for (TableAxis axis : kTableAxes) {
    EXPECT_EQ((*table)[axis].xs, expected[axis].xs);
    EXPECT_EQ((*table)[axis].ys, expected[axis].ys);
    EXPECT_EQ((*table)[axis].error_mm, expected[axis].error_mm);
  }
  EXPECT_TRUE(HasUsableShape(*table));
}

TEST(TableAssembly, ReportsStructuralMistakes) {
  ErrorTable base = SmallTable(kSmoothX, kSmoothY);
  struct Case {
    const char* what;
    std::function<void(std::vector<TableNode>&)> edit;
    DiagKind expected;
  };
  std::vector<Case> cases = {
      {"missing node", [](auto& n) { n.erase(n.begin() + 4); }, DiagKind::TableMissingNode},
      {"duplicate node", [](auto& n) { n.push_back(n[4]); }, DiagKind::TableDuplicateNode},
      {"typo in x", [](auto& n) { n[4].x_mm = 1.0; }, DiagKind::TableStrayGridLine},
      {"missing axis", [](auto& n) { n.resize(9); }, DiagKind::TableMissingAxis},
      {"one x line", [](auto& n) {
         std::erase_if(n, [](const TableNode& t) { return t.axis == TableAxis::Y && t.x_mm > 1; });
       }, DiagKind::TableGridTooSmall},
      {"no overlap", [](auto& n) {
         for (TableNode& t : n) {
           if (t.axis == TableAxis::Y) t.y_mm += 100;
         }
       }, DiagKind::TableNoOverlap},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    std::vector<TableNode> nodes = NodesOf(base);
    c.edit(nodes);
    SourceManager sources;
    Diagnostics diags(sources);
    EXPECT_FALSE(AssembleErrorTable("t", nodes, SourceLoc{}, diags).has_value());
    ASSERT_FALSE(diags.all().empty());
    EXPECT_EQ(diags.all().front().kind, c.expected) << diags.RenderText();
  }
}

TEST(TableAssembly, ATypoIsExplainedNotAlsoReportedMissing) {
  std::vector<TableNode> nodes = NodesOf(SmallTable(kSmoothX, kSmoothY));
  nodes[4].x_mm = 1.0;  // 10.0 mistyped
  SourceManager sources;
  Diagnostics diags(sources);
  EXPECT_FALSE(AssembleErrorTable("t", nodes, SourceLoc{}, diags).has_value());
  EXPECT_EQ(Kinds(diags), std::vector<DiagKind>{DiagKind::TableStrayGridLine});
  EXPECT_NE(diags.all()[0].message.find("did you mean x_mm = 10.000?"), std::string::npos)
      << diags.all()[0].message;
}

TEST(TableAssembly, LinesCloserThanTheMinimumSpacingAreOneLineWrittenTwice) {
  ErrorTable base = SmallTable(kSmoothX, kSmoothY);
  // 3 x 4 nodes; the last x line is 20.000 in two rows and 20.002 in two.
  base[TableAxis::X].ys.push_back(30);
  for (int i = 0; i < 3; ++i) base[TableAxis::X].error_mm.push_back(-0.07);
  std::vector<TableNode> nodes = NodesOf(base);
  for (TableNode& n : nodes) {
    if (n.axis == TableAxis::X && n.x_mm == 20 && n.y_mm >= 20) n.x_mm = 20.002;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  EXPECT_FALSE(AssembleErrorTable("t", nodes, SourceLoc{}, diags).has_value());
  EXPECT_EQ(Kinds(diags), std::vector<DiagKind>{DiagKind::TableGridLinesTooClose}) << diags.RenderText();
}

// Soundness and exactness of the analysis: no sampled point has a smaller
// determinant or a larger slope than the analysis says, and the analysis's
// extremes are reached (near the piece corners).
TEST(TableAnalysis, IsExactAgainstDenseSampling) {
  for (int k = 0; k < 40; ++k) {
    const std::uint64_t seed = BaseSeed() + static_cast<std::uint64_t>(k);
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    ErrorTable table;
    const int n = 2 + static_cast<int>(rng() % 5);
    for (TableAxis axis : kTableAxes) {
      AxisTable& t = table[axis];
      double ox = axis == TableAxis::Y ? 0.37 * u(rng) : 0, oy = axis == TableAxis::Y ? 0.41 * u(rng) : 0;
      for (int i = 0; i < n; ++i) t.xs.push_back(ox + i + 0.3 * u(rng) * (i > 0));
      for (int j = 0; j < n; ++j) t.ys.push_back(oy + j + 0.3 * u(rng) * (j > 0));
      for (int m = 0; m < n * n; ++m) t.error_mm.push_back(0.4 * u(rng));  // wild: slopes near 1
    }
    TableAnalysis analysis = AnalyzeTable(table);
    CalibrationMap map(table);
    const Rect d = map.domain();
    double sampled_min_det = INFINITY, sampled_max_slope = 0;
    auto sample = [&](Eigen::Vector2d p) {
      Eigen::Vector2d delta;
      Eigen::Matrix2d g;
      map.DeltaAndJacobian(p, delta, g);
      double det = (1 + g(0, 0)) * (1 + g(1, 1)) - g(0, 1) * g(1, 0);
      double slope = std::max(std::abs(g(0, 0)) + std::abs(g(0, 1)), std::abs(g(1, 0)) + std::abs(g(1, 1)));
      EXPECT_GE(det, analysis.min_jacobian_det - 1e-12) << "at " << p.transpose();
      EXPECT_LE(slope, analysis.contraction + 1e-12) << "at " << p.transpose();
      sampled_min_det = std::min(sampled_min_det, det);
      sampled_max_slope = std::max(sampled_max_slope, slope);
    };
    std::uniform_real_distribution<double> ux(d.x0, d.x1), uy(d.y0, d.y1);
    for (int s = 0; s < 3000; ++s) sample({ux(rng), uy(rng)});
    for (const PieceBound& piece : analysis.pieces) {
      const Rect& r = piece.piece;
      const double ex = 1e-9 * (r.x1 - r.x0), ey = 1e-9 * (r.y1 - r.y0);
      for (double x : {r.x0 + ex, r.x1 - ex}) {
        for (double y : {r.y0 + ey, r.y1 - ey}) sample({x, y});
      }
    }
    EXPECT_NEAR(sampled_min_det, analysis.min_jacobian_det, 1e-6);
    EXPECT_NEAR(sampled_max_slope, analysis.contraction, 1e-6);
  }
}

TEST(TableValidation, AcceptsASmoothTable) {
  SourceManager sources;
  Diagnostics diags(sources);
  TableAnalysis analysis;
  EXPECT_TRUE(ValidateErrorTable(SmallTable(kSmoothX, kSmoothY), diags, TableWarnings::kReport, &analysis));
  EXPECT_TRUE(diags.all().empty()) << diags.RenderText();
  EXPECT_NEAR(analysis.contraction, 0.0014, 1e-12);
  EXPECT_NEAR(analysis.max_abs_error_mm, 0.078, 1e-12);
}

TEST(TableValidation, RejectsAFoldNamingTheCellAndTheSlopes) {
  ErrorTable table = SmallTable(kSmoothX, kSmoothY);
  table[TableAxis::X].error_mm[4] = -64.0;  // micrometres written as millimetres
  SourceManager sources;
  Diagnostics diags(sources);
  EXPECT_FALSE(ValidateErrorTable(table, diags, TableWarnings::kSkip));
  ASSERT_EQ(diags.all().size(), 1u);
  const Diagnostic& d = diags.all()[0];
  EXPECT_EQ(d.kind, DiagKind::TableFolds);
  EXPECT_NE(d.message.find("folds in cell x "), std::string::npos) << d.message;
  EXPECT_NE(d.message.find("∂Δx/∂x = -6.3946"), std::string::npos) << d.message;
}

TEST(TableValidation, RejectsANearFold) {
  // A shear and a compression: det = (1 - 0.45) (1 + 0) - 0 = 0.55 > 0.5 is fine ...
  auto fx = [](double x, double) { return -0.45 * x; };
  SourceManager sources;
  Diagnostics ok(sources);
  EXPECT_TRUE(ValidateErrorTable(SmallTable(fx, kSmoothY), ok, TableWarnings::kSkip)) << ok.RenderText();
  // ... but compressing both axes by 0.3 leaves det = 0.49: nearly folds.
  auto fy = [](double, double y) { return -0.3 * y; };
  auto fx2 = [](double x, double) { return -0.3 * x; };
  Diagnostics near(sources);
  EXPECT_FALSE(ValidateErrorTable(SmallTable(fx2, fy), near, TableWarnings::kSkip));
  ASSERT_FALSE(near.all().empty());
  EXPECT_EQ(near.all()[0].kind, DiagKind::TableFolds);
  EXPECT_NE(near.all()[0].message.find("nearly folds"), std::string::npos) << near.all()[0].message;
}

TEST(TableValidation, RejectsATooSteepTableThatDoesNotFold) {
  // A rotation-like error: det = 1 + 0.36 but |grad Delta|_inf = 0.6.
  auto fx = [](double, double y) { return -0.6 * y; };
  auto fy = [](double x, double) { return 0.6 * x; };
  SourceManager sources;
  Diagnostics diags(sources);
  EXPECT_FALSE(ValidateErrorTable(SmallTable(fx, fy), diags, TableWarnings::kSkip));
  ASSERT_FALSE(diags.all().empty());
  EXPECT_EQ(diags.all()[0].kind, DiagKind::TableTooSteep) << diags.RenderText();
}

TEST(TableValidation, WarnsAboutSignChangesAndErrorsAboveHalfThePitch) {
  SourceManager sources;
  Diagnostics diags(sources);
  auto crossing = [](double x, double) { return -0.018 + 0.0012 * x; };  // -18, -6, +6 µm along x
  EXPECT_TRUE(ValidateErrorTable(SmallTable(crossing, kSmoothY), diags, TableWarnings::kReport));
  ASSERT_EQ(Kinds(diags), std::vector<DiagKind>{DiagKind::TableSignChange});
  EXPECT_NE(diags.all()[0].message.find("between 3 pairs"), std::string::npos) << diags.all()[0].message;

  // A crossing through nodes near zero (-2 µm to +8 µm) is noise around a
  // zero the grid resolves: no warning (kSignChangeMinMm).
  Diagnostics near_zero(sources);
  auto gentle = [](double x, double) { return -0.012 + 0.001 * x; };  // -12, -2, +8 µm along x
  EXPECT_TRUE(ValidateErrorTable(SmallTable(gentle, kSmoothY), near_zero, TableWarnings::kReport));
  EXPECT_TRUE(near_zero.all().empty()) << near_zero.RenderText();

  Diagnostics big(sources);
  auto microns = [](double x, double) { return 6.0 + 0.1 * x; };
  EXPECT_TRUE(ValidateErrorTable(SmallTable(microns, kSmoothY), big, TableWarnings::kReport));
  EXPECT_EQ(Kinds(big), std::vector<DiagKind>{DiagKind::TableErrorOverHalfPitch});

  Diagnostics quiet(sources);
  EXPECT_TRUE(ValidateErrorTable(SmallTable(microns, kSmoothY), quiet, TableWarnings::kSkip));
  EXPECT_TRUE(quiet.all().empty());
}

TEST(TableStats, ThePapersFigures) {
  ErrorTable table = SmallTable(kSmoothX, kSmoothY);
  table[TableAxis::X].stddev_mm.assign(9, 0.002);
  table[TableAxis::X].stddev_mm[3] = 0.005;
  table[TableAxis::X].count.assign(9, 20);
  TableStats stats = ComputeTableStats(table);
  const AxisStats& x = stats.axes[0];
  EXPECT_DOUBLE_EQ(x.max_mm, -0.05);
  EXPECT_DOUBLE_EQ(x.min_mm, -0.078);
  EXPECT_NEAR(x.mean_mm, -0.064, 1e-15);
  EXPECT_EQ(x.min_x, 20);
  EXPECT_EQ(x.min_y, 20);
  EXPECT_NEAR(x.abs_max_after_shift_mm, 0.014, 1e-15);
  EXPECT_EQ(x.stddev_nodes, 9u);
  EXPECT_NEAR(x.stddev_mean_mm, (8 * 0.002 + 0.005) / 9, 1e-15);
  EXPECT_DOUBLE_EQ(x.stddev_max_mm, 0.005);
  EXPECT_EQ(x.count_min, 20);
  EXPECT_EQ(stats.axes[1].stddev_nodes, 0u);
  EXPECT_EQ(stats.axes[1].count_max, 0);
  EXPECT_DOUBLE_EQ(stats.shift_x_mm, x.mean_mm);
  EXPECT_DOUBLE_EQ(stats.shift_y_mm, stats.axes[1].mean_mm);
}

}  // namespace
}  // namespace smtcal
