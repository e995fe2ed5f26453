// `smtcal table build|check|stats|forward|inverse|plot|diff`: the error
// tables of a calibrated region (docs/error-tables.md). The work is in
// frontend/table_csv, passes/error_table*, passes/inverse_calibration and
// backend/table_*; this file only wires files, options and exit codes.
#include <filesystem>
#include <optional>
#include <CLI/CLI.hpp>

#include "backend/reports/table_diff_report.h"
#include "backend/reports/table_plot.h"
#include "backend/reports/table_report.h"
#include "calibration/error_table_build.h"
#include "calibration/error_table_check.h"
#include "calibration/interpolation_error.h"
#include "calibration/inverse_calibration.h"
#include "calibration/table_diff.h"
#include "calibration/tolerances.h"
#include "frontend/cell_toml.h"
#include "calibration/limits.h"
#include "frontend/measurement_input.h"
#include "frontend/table_csv.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

struct TableOptions {
  std::string input;   // the table (or raw file for build)
  std::string points = "-";
  bool points_given = false;
  std::string output = "-";
  bool json = false;
  std::string outside = "error";
  std::string solver = "default";
  double paper_tolerance_mm = kPaperSolverTolMm;
  double tolerance_mm = kDefaultTableToleranceMm;  // check, stats: what the interpolation error is a share of
  bool drop_outlier_readings = false;
  // table diff
  std::string new_input;
  std::string cell;
  std::string svg;
  double threshold_um = kDiffDefaultThresholdUm;
  bool exit_zero = false;
};

std::string BaseName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

// The interpolation estimate of a table on its own: no cell, so no declared
// roughness; a node or check point that states no noise counts as one
// reading of the table's pooled reading scatter (the other axis's when its
// own states none; 0 when the table states none, where a cell counts its
// robot's repeatability instead: docs/error-tables.md).
InterpolationEstimate TableInterpolation(const ErrorTable& table) {
  double scatter = 0;
  for (const AxisTable& t : table.axes) scatter = std::max(scatter, PooledReadingScatterMm(t).value_or(0.0));
  return EstimateInterpolationError(table, std::nullopt, scatter);
}

// Loads and validates a table. Returns nullopt after setting the exit code
// (I/O error, or input errors printed); diagnostics are printed by the caller
// on success (warnings).
std::optional<ErrorTable> LoadTable(const std::string& path, SourceManager& sources, Diagnostics& diags,
                                    TableWarnings warnings, GlobalOptions& options,
                                    TableAnalysis* analysis = nullptr) {
  Result<std::uint32_t> file = sources.Load(path);
  if (!file) {
    options.exit_code = ReportIoError(file.error());
    return std::nullopt;
  }
  std::optional<ErrorTable> table = ReadErrorTable(file.value(), diags);
  if (table && !ValidateErrorTable(*table, diags, warnings, analysis)) table.reset();
  if (!table) {
    options.exit_code = PrintDiagnostics(diags, options);
    return std::nullopt;
  }
  return table;
}

void Finish(const Diagnostics& diags, GlobalOptions& options, const std::string& output, const std::string& text) {
  options.exit_code = PrintDiagnostics(diags, options);
  if (options.exit_code != kExitOk) return;
  Status written = WriteFileAtomically(output, text);
  if (!written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  SayDone(options, output, fmt::format("wrote {}", output));
}

OutsidePolicy ParsePolicy(const std::string& name) {
  if (name == "clamp") return OutsidePolicy::kClamp;
  if (name == "none") return OutsidePolicy::kNone;
  return OutsidePolicy::kError;
}

// The files of a `table` command against each other (tools/commands.h):
// POINTS is standard input unless given, so `table inverse -` clashes too.
bool FilesClashIn(const TableOptions& opt, bool with_points, GlobalOptions& options) {
  std::vector<NamedFile> inputs = {{"TABLE", opt.input}};
  if (with_points) inputs.push_back({opt.points_given ? "POINTS" : "POINTS (standard input unless given)", opt.points});
  if (!FilesClash(inputs, {{"-o", opt.output}})) return false;
  options.exit_code = kExitUsageError;
  return true;
}

void RunBuild(const TableOptions& opt, GlobalOptions& options) {
  if (FilesClashIn(opt, false, options)) return;
  SourceManager sources;
  Diagnostics diags(sources);
  // With --cell: the settings the raw file was measured with (its
  // "measured with:" comment) against the cell's.
  std::optional<cell::Cell> cell;
  if (!opt.cell.empty() && !LoadCellForMeasure(opt.cell, sources, diags, options, cell)) return;
  Result<std::uint32_t> file = sources.Load(opt.input);
  if (!file) {
    options.exit_code = ReportIoError(file.error());
    return;
  }
  if (cell) measure::CheckRawSettings(file.value(), *cell, diags);
  std::optional<std::vector<RawMeasurement>> raw = ReadRawMeasurements(file.value(), diags);
  std::optional<ErrorTable> table;
  BuildOptions build;
  build.drop_outlier_readings = opt.drop_outlier_readings;
  if (raw) table = BuildErrorTable(BaseName(opt.input), *raw, SourceLoc{file.value(), 0, 0}, diags, build);
  if (table) ValidateErrorTable(*table, diags, TableWarnings::kReport);
  std::string text;
  if (table && !diags.has_errors()) {
    std::vector<std::string> comment = BuiltTableComment(BaseName(opt.input));
    bool u = false, reversal = false;
    for (const AxisTable& t : table->axes) {
      for (const auto& v : t.u_mm) u = u || v.has_value();
      for (const auto& v : t.reversal_mm) reversal = reversal || v.has_value();
    }
    if (u) {
      comment.push_back("u_mm: the largest standard uncertainty of the node's readings from everything but their "
                        "scatter (measure read's budget: the artefact, the device's geometry, the registration)");
    }
    if (reversal) {
      comment.push_back("reversal_mm: the mean of the readings approached against the final approach less error_mm "
                        "(ISO 230-2's reversal value: the backlash)");
    }
    text = FormatTableCsv(*table, comment);
  }
  Finish(diags, options, opt.output, text);
}

void RunCheck(const TableOptions& opt, GlobalOptions& options) {
  SourceManager sources;
  Diagnostics diags(sources);
  std::optional<ErrorTable> table = LoadTable(opt.input, sources, diags, TableWarnings::kReport, options);
  if (!table) return;
  const InterpolationEstimate interpolation = TableInterpolation(*table);
  ReportCoarseGrid(interpolation, opt.tolerance_mm, "the table", interpolation.Origin(), diags);
  options.exit_code = PrintDiagnostics(diags, options);
  const std::string text = fmt::format("between the nodes: {}\n", InterpolationText(interpolation, opt.tolerance_mm));
  if (Status written = WriteFileAtomically("-", text); !written) options.exit_code = ReportIoError(written.error());
  if (options.exit_code == kExitOk) SayDone(options, "", NoErrorsText(table->name, diags.warning_count()));
}

void RunStats(const TableOptions& opt, GlobalOptions& options) {
  SourceManager sources;
  Diagnostics diags(sources);
  TableAnalysis analysis;
  std::optional<ErrorTable> table = LoadTable(opt.input, sources, diags, TableWarnings::kSkip, options, &analysis);
  if (!table) return;
  table->name = BaseName(table->name);
  TableStats stats = ComputeTableStats(*table);
  int bound = IterationBound(analysis.contraction, analysis.max_abs_error_mm);
  const InterpolationEstimate interpolation = TableInterpolation(*table);
  Finish(diags, options, "-",
         opt.json ? FormatStatsJson(*table, stats, analysis, bound, interpolation, opt.tolerance_mm)
                  : FormatStatsText(*table, stats, analysis, bound, interpolation, opt.tolerance_mm));
}

void RunSolve(const TableOptions& opt, GlobalOptions& options, bool inverse) {
  if (FilesClashIn(opt, true, options)) return;
  SourceManager sources;
  Diagnostics diags(sources);
  TableAnalysis analysis;
  std::optional<ErrorTable> table = LoadTable(opt.input, sources, diags, TableWarnings::kSkip, options, &analysis);
  if (!table) return;
  Result<std::uint32_t> file = sources.Load(opt.points);
  if (!file) {
    options.exit_code = ReportIoError(file.error());
    return;
  }
  std::optional<std::vector<PointRow>> points = ReadPoints(file.value(), diags);
  if (!points) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  const OutsidePolicy policy = ParsePolicy(opt.outside);
  std::optional<InverseSolver> solver;
  std::optional<PaperSolver> paper;
  if (inverse && opt.solver == "paper") {
    paper.emplace(*table, opt.paper_tolerance_mm);
  } else if (inverse) {
    solver.emplace(*table, analysis);
  }
  CalibrationMap map(*table);
  const Rect& domain = map.domain();
  std::vector<Solution> solutions;
  for (const PointRow& row : *points) {
    Solution s = paper    ? paper->Solve(row.point, policy)
                 : solver ? solver->Solve(row.point, policy)
                          : DirectCalibrate(map, row.point, policy);
    SMTCAL_CHECK(paper || s.status != SolveStatus::kNotConverged,
                 "the default inverse solver exceeded the iteration bound proven for this table");
    if (s.status == SolveStatus::kOutside) {
      std::string detail = inverse ? fmt::format("; the nominal position that reaches it would be ({:.6f}, {:.6f})",
                                                 s.point.x(), s.point.y())
                                   : "";
      diags.Report(DiagKind::PointOutsideTable, row.range, FormatMm(row.point.x()), FormatMm(row.point.y()),
                   FormatMm(domain.x0), FormatMm(domain.x1), FormatMm(domain.y0), FormatMm(domain.y1), detail);
    } else if (s.status == SolveStatus::kNotConverged) {
      diags.Report(DiagKind::PaperSolverNotConverged, row.range, s.iterations, fmt::format("{:.3e}", s.residual_mm),
                   FormatMm(row.point.x()), FormatMm(row.point.y()), FormatMm(paper->tolerance_mm()));
    }
    solutions.push_back(s);
  }
  Finish(diags, options, opt.output, FormatSolutionsCsv(solutions));
}

void RunPlot(const TableOptions& opt, GlobalOptions& options) {
  if (FilesClashIn(opt, false, options)) return;
  SourceManager sources;
  Diagnostics diags(sources);
  std::optional<ErrorTable> table = LoadTable(opt.input, sources, diags, TableWarnings::kSkip, options);
  if (!table) return;
  Finish(diags, options, opt.output, PlotTableSvg(*table, BaseName(table->name)));
}

void RunDiff(const TableOptions& opt, GlobalOptions& options) {
  if (FilesClash({{"A", opt.input}, {"B", opt.new_input}, {"--cell", opt.cell}},
                 {{"--svg", opt.svg}, {"the diff", "-"}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  std::optional<ErrorTable> old_table = LoadTable(opt.input, sources, diags, TableWarnings::kSkip, options);
  if (!old_table) return;
  std::optional<ErrorTable> new_table = LoadTable(opt.new_input, sources, diags, TableWarnings::kSkip, options);
  if (!new_table) return;
  std::optional<cell::Cell> cell;
  if (!opt.cell.empty()) {
    cell = LoadCellOrReport(opt.cell, sources, diags, options);
    if (!cell) return;
  }
  const TableChanges changes =
      CompareTables(*old_table, *new_table, opt.threshold_um, cell ? &cell->regions : nullptr);
  const TableDiffNames names{opt.input, opt.new_input, opt.cell};
  options.exit_code = PrintDiagnostics(diags, options);
  if (options.exit_code != kExitOk) return;
  if (!opt.svg.empty()) {
    const std::string svg = PlotTableDiffSvg(*old_table, *new_table, names);
    if (svg.empty()) {
      options.exit_code = ReportInputError("the tables share no area of 2 x 2 nodes to draw; no --svg written");
      return;
    }
    if (Status written = WriteFileAtomically(opt.svg, svg); !written) {
      options.exit_code = ReportIoError(written.error());
      return;
    }
  }
  const std::string text = opt.json ? FormatTableDiffJson(changes, names) : FormatTableDiffText(changes, names);
  if (Status written = WriteFileAtomically("-", text); !written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (!opt.svg.empty()) SayDone(options, opt.svg, fmt::format("wrote the picture {}", opt.svg));
  options.exit_code = TableDiffPasses(changes) || opt.exit_zero ? kExitOk : kExitInputError;
}

void AddToleranceOption(CLI::App& command, TableOptions& opt) {
  AddNumberOption(command, "--tolerance", opt.tolerance_mm,
                  "the placing tolerance (mm) the interpolation error between the nodes is a share of; above "
                  "10 % the pitch to measure at next is advised",
                  limits::kAccuracyMm)
      ->capture_default_str();
}

}  // namespace

void AddTableCommand(CLI::App& app, GlobalOptions& options) {
  static TableOptions opt;
  CLI::App* table = app.add_subcommand(
      "table", "Build, check and use error tables: the robot's measured position errors (docs/error-tables.md)");
  table->require_subcommand(1);

  CLI::App* build = table->add_subcommand(
      "build", "Average raw measurements (axis,x_mm,y_mm,set,repetition,error_mm[,kind]) into an error table\n"
               "(kind check: check points off the nodes, averaged per position and kept in the table);\n"
               "a reading or a whole set far from the other readings at its position is an error naming\n"
               "its line and the likely slip; warns about nodes whose scatter or set-to-set difference is far above the rest");
  build->add_option("RAW", opt.input, "the raw measurement CSV ('-' for stdin)")->required();
  build->add_option("-o,--output", opt.output, "the error table to write ('-' for stdout)")->required();
  build->add_flag("--drop-outlier-readings", opt.drop_outlier_readings,
                  "leave readings (and sets) far from their node's others out of the means,\n"
                  "each reported as a warning, instead of stopping at them");
  build->add_option("--cell", opt.cell,
                    "the cell the table is for: the final approach and the device's settings the raw file says it\n"
                    "was measured with (smtcal measure read writes them) must be the cell's");
  build->callback([&options] { RunBuild(opt, options); });

  CLI::App* check = table->add_subcommand(
      "check", "Validate an error table: grid, values, no fold (det(I + grad Delta) >= 0.5), slopes,\n"
               "and warn where the error changes sign between nodes or exceeds half the pitch; print the\n"
               "interpolation error between the nodes as a share of --tolerance (and the pitch to measure at\n"
               "when it is more than 10 %)");
  check->add_option("TABLE", opt.input, "the error table CSV ('-' for stdin)")->required();
  AddToleranceOption(*check, opt);
  check->callback([&options] { RunCheck(opt, options); });

  CLI::App* stats = table->add_subcommand(
      "stats", "The paper's statistics per axis (max, min, mean, origin shift by the means, max |Delta - mean|,\n"
               "stddev summary), the inverse calibration's contraction factor and iteration bound, and the\n"
               "interpolation error between the nodes as a share of --tolerance");
  stats->add_option("TABLE", opt.input, "the error table CSV ('-' for stdin)")->required();
  stats->add_flag("--json", opt.json, "print JSON instead of text");
  AddToleranceOption(*stats, opt);
  stats->callback([&options] { RunStats(opt, options); });

  for (bool inverse : {false, true}) {
    CLI::App* solve = table->add_subcommand(
        inverse ? "inverse" : "forward",
        inverse ? "Inverse calibration: the nominal positions n that reach the required actual positions a\n"
                  "(F(n) = a); prints x_mm,y_mm,residual_mm,iterations"
                : "Direct calibration: the actual positions F(n) = n + Delta(n) the robot reaches when\n"
                  "commanded to n; prints x_mm,y_mm,residual_mm,iterations (residual and iterations 0)");
    solve->add_option("TABLE", opt.input, "the error table CSV")->required();
    CLI::Option* points =
        solve->add_option("POINTS", opt.points, "CSV of points x_mm,y_mm (header optional; default '-', stdin)")
            ->capture_default_str();
    solve->add_option("-o,--output", opt.output, "where to write the results ('-' for stdout)")
        ->capture_default_str();
    solve->add_option("--outside", opt.outside,
                      "points outside the table: error (refuse), clamp (use the edge values),\n"
                      "none (leave uncorrected)")
        ->check(CLI::IsMember({"error", "clamp", "none"}))
        ->capture_default_str();
    if (inverse) {
      solve->add_option("--solver", opt.solver,
                        "default (Newton guarded by the contracting fixed-point step, residual <= 1e-9 mm)\n"
                        "or paper (the paper's iterative interval search)")
          ->check(CLI::IsMember({"default", "paper"}))
          ->capture_default_str();
      AddNumberOption(*solve, "--paper-tolerance", opt.paper_tolerance_mm, "the paper solver's stopping tolerance",
                      limits::kPaperToleranceMm)
          ->capture_default_str();
    }
    solve->callback([&options, inverse, points] {
      opt.points_given = points->count() > 0;
      RunSolve(opt, options, inverse);
    });
  }

  CLI::App* plot = table->add_subcommand(
      "plot", "Draw the error field as SVG: colour maps of Delta-x and Delta-y (µm), grid nodes,\n"
              "and the error vectors as enlarged arrows with a scale bar");
  plot->add_option("TABLE", opt.input, "the error table CSV ('-' for stdin)")->required();
  plot->add_option("-o,--output", opt.output, "the SVG file to write ('-' for stdout)")->required();
  plot->callback([&options] { RunPlot(opt, options); });

  CLI::App* diff = table->add_subcommand(
      "diff", "Compare two error tables of a region (before and after re-measuring): every node's change per axis\n"
              "(grids may differ: each node against the other table's interpolation on the common area), the\n"
              "largest, mean and rms change, the nodes that changed most, per region with --cell; exit 1 when a\n"
              "node changed by more than --threshold");
  diff->add_option("A", opt.input, "the table in use now (CSV; '-' for stdin)")->required();
  diff->add_option("B", opt.new_input, "the re-measured table (CSV; '-' for stdin)")->required();
  diff->add_option("--cell", opt.cell, "a cell file: the changes within each of its regions' bounds too");
  AddNumberOption(*diff, "--threshold", opt.threshold_um,
                  "the gate: a node whose error changed by more than this many µm fails it", limits::kDiffThresholdUm)
      ->capture_default_str();
  diff->add_flag("--json", opt.json, "print JSON (schema smtcal-table-diff/1) instead of text");
  diff->add_option("--svg", opt.svg, "also draw the change as an SVG file: colour maps of both axes in µm and arrows");
  diff->add_flag("--exit-zero", opt.exit_zero, "report only: exit 0 even when the gate fails");
  diff->callback([&options] { RunDiff(opt, options); });
}

}  // namespace smtcal::tools
