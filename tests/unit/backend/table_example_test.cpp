// The shipped example (examples/paper-cell/): the table is exactly what
// `smtcal table build` makes of the raw measurements, the plot is current, and
// the statistics are the paper's.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "backend/reports/table_plot.h"
#include "backend/reports/table_report.h"
#include "calibration/error_table_build.h"
#include "calibration/error_table_check.h"
#include "calibration/inverse_calibration.h"
#include "frontend/table_csv.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

const std::filesystem::path kDir = std::filesystem::path(SMTCAL_SOURCE_DIR) / "examples" / "paper-cell";

using test::ReadFileText;

struct Example {
  SourceManager sources;
  Diagnostics diags{sources};
  std::optional<ErrorTable> table;
  Example() {
    std::uint32_t file = sources.Add("placing-table.csv", ReadFileText(kDir / "placing-table.csv"));
    table = ReadErrorTable(file, diags);
  }
};

long Um(double mm) { return std::lround(mm * 1000); }

TEST(PaperCellExample, TheTableIsTheBuildOfTheRawMeasurements) {
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("placing-raw.csv", ReadFileText(kDir / "placing-raw.csv"));
  std::optional<std::vector<RawMeasurement>> raw = ReadRawMeasurements(file, diags);
  ASSERT_TRUE(raw.has_value()) << diags.RenderText();
  EXPECT_EQ(raw->size(), 2u * 121 * 2 * 10);
  std::optional<ErrorTable> table = BuildErrorTable("placing-table.csv", *raw, SourceLoc{file, 0, 0}, diags);
  ASSERT_TRUE(table.has_value()) << diags.RenderText();
  EXPECT_TRUE(diags.all().empty()) << "the shipped data are clean:\n" << diags.RenderText();
  EXPECT_EQ(FormatTableCsv(*table, BuiltTableComment("placing-raw.csv")), ReadFileText(kDir / "placing-table.csv"))
      << "regenerate: build/smtcal_gen_paper_tables examples/paper-cell";
}

TEST(PaperCellExample, GridsAsThePaperMeasuredThem) {
  Example e;
  ASSERT_TRUE(e.table.has_value()) << e.diags.RenderText();
  const AxisTable& x = (*e.table)[TableAxis::X];
  const AxisTable& y = (*e.table)[TableAxis::Y];
  ASSERT_EQ(x.nx(), 11u);
  ASSERT_EQ(x.ny(), 11u);
  ASSERT_EQ(y.nx(), 11u);
  ASSERT_EQ(y.ny(), 11u);
  EXPECT_DOUBLE_EQ(x.xs.back() - x.xs.front(), 50);
  EXPECT_DOUBLE_EQ(x.ys.back() - x.ys.front(), 50);
  for (std::size_t i = 0; i < 11; ++i) {
    EXPECT_NEAR(y.xs[i] - x.xs[i], 0.004, 1e-9);
    EXPECT_NEAR(y.ys[i] - x.ys[i], -0.003, 1e-9);
  }
  EXPECT_EQ(x.count, std::vector<int>(121, 20));
}

TEST(PaperCellExample, StatisticsAreThePapers) {
  Example e;
  ASSERT_TRUE(e.table.has_value()) << e.diags.RenderText();
  TableStats stats = ComputeTableStats(*e.table);
  const AxisStats& x = stats.axes[0];
  const AxisStats& y = stats.axes[1];
  EXPECT_EQ(Um(x.max_mm), 27);
  EXPECT_EQ(Um(x.min_mm), -153);
  EXPECT_EQ(Um(x.mean_mm), -79);
  EXPECT_EQ(Um(y.max_mm), 62);
  EXPECT_EQ(Um(y.min_mm), -71);
  EXPECT_EQ(Um(y.mean_mm), 7);
  // After shifting the origin by the means: max |Delta - mean|.
  EXPECT_EQ(Um(x.abs_max_after_shift_mm), 106);
  EXPECT_EQ(Um(y.abs_max_after_shift_mm), 78);
  // Repetition scatter of about 2.5 µm, as generated.
  EXPECT_NEAR(x.stddev_mean_mm, 0.0025, 0.0003);
  EXPECT_NEAR(y.stddev_mean_mm, 0.0025, 0.0003);
}

TEST(PaperCellExample, IsValidAndInvertsWithinItsBound) {
  Example e;
  ASSERT_TRUE(e.table.has_value()) << e.diags.RenderText();
  TableAnalysis analysis;
  ASSERT_TRUE(ValidateErrorTable(*e.table, e.diags, TableWarnings::kReport, &analysis)) << e.diags.RenderText();
  for (const Diagnostic& d : e.diags.all()) EXPECT_EQ(d.kind, DiagKind::TableSignChange) << d.message;
  EXPECT_LT(analysis.contraction, 0.01);  // micrometres per millimetre: a real robot
  EXPECT_GT(analysis.min_jacobian_det, 0.98);
  InverseSolver solver(*e.table, analysis);
  EXPECT_EQ(solver.iteration_bound(), 4);
  const Rect& d = solver.map().domain();
  for (int i = 0; i <= 50; ++i) {
    for (int j = 0; j <= 50; ++j) {
      Eigen::Vector2d n(d.x0 + (d.x1 - d.x0) * i / 50, d.y0 + (d.y1 - d.y0) * j / 50);
      Solution s = solver.Solve(n + solver.map().Delta(n), OutsidePolicy::kError);
      ASSERT_EQ(s.status, SolveStatus::kOk);
      ASSERT_LE(s.residual_mm, kInverseResidualTolMm);
      ASSERT_LE(s.iterations, solver.iteration_bound());
    }
  }
}

TEST(PaperCellExample, ThePlotIsCurrent) {
  Example e;
  ASSERT_TRUE(e.table.has_value()) << e.diags.RenderText();
  // (Not EXPECT_EQ: a 400 kB diff helps nobody.)
  EXPECT_TRUE(PlotTableSvg(*e.table, "placing-table.csv") == ReadFileText(kDir / "placing-table.svg"))
      << "placing-table.svg is stale; regenerate: build/smtcal_gen_paper_tables examples/paper-cell";
}

}  // namespace
}  // namespace smtcal
