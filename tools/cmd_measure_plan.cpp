// `smtcal measure plan --cell CELL.toml -o PLAN.csv`: the measurement plan
// (calibration/measurement_plan.h, docs/measure.md): per region the grid,
// its pitch and why, check points, sets and repetitions, the visits in their
// order, and the time at the cell's speeds. This file wires the cell, the
// options, the summary and the exit codes.
#include <filesystem>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "backend/reports/measurement_csv.h"
#include "calibration/measurement_plan.h"
#include "frontend/cell_toml.h"
#include "calibration/limits.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

struct PlanOptionsCli {
  std::string cell;
  std::string output;
  std::vector<std::string> regions;
  double pitch_mm = 0;
  int sets = 2;
  int repetitions = 10;
  bool no_check_points = false;
  bool bidirectional = false;
};

void RunPlan(const PlanOptionsCli& opt, GlobalOptions& options) {
  if (FilesClash({{"--cell", opt.cell}}, {{"-o", opt.output}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> loaded =
      cell::LoadCell(opt.cell, sources, diags, cell::CellLoadOptions{.tables_may_be_missing = true});
  if (!loaded) {
    options.exit_code = ReportIoError(loaded.error());
    return;
  }
  std::optional<measure::Plan> plan;
  if (loaded.value()) {
    measure::PlanOptions plan_options;
    plan_options.regions = opt.regions;
    if (opt.pitch_mm > 0) plan_options.pitch_mm = opt.pitch_mm;
    plan_options.sets = opt.sets;
    plan_options.repetitions = opt.repetitions;
    plan_options.check_points = !opt.no_check_points;
    plan_options.bidirectional = opt.bidirectional;
    plan = measure::MakePlan(*loaded.value(), plan_options, diags);
  }
  options.exit_code = PrintDiagnostics(diags, options);
  if (!plan || options.exit_code != kExitOk) return;
  const std::string cell_name = std::filesystem::path(opt.cell).filename().string();
  Status written = WriteFileAtomically(opt.output, FormatPlanCsv(*plan, cell_name));
  if (!written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (!options.quiet && opt.output != "-") {
    for (const std::string& line : PlanSummary(*plan, cell_name)) fmt::print("{}\n", line);
  }
  SayDone(options, opt.output, fmt::format("wrote {} ({} visits)", opt.output, plan->visits.size()));
}

}  // namespace

void AddMeasurePlanCommand(CLI::App& measure, GlobalOptions& options) {
  static PlanOptionsCli opt;
  CLI::App* plan = measure.add_subcommand(
      "plan",
      "Plan the measurement of the cell's regions (and of the markers' when the cell lacks them): per region the\n"
      "grid over its bounds and a margin for the robot's error, the pitch (default: where verify's estimate of\n"
      "the interpolation error is 10 % of the tolerance: from the robot's declared roughness, or from the grid\n"
      "advice of the region's previous table when it exists), check points between nodes, sets x repetitions (the paper's\n"
      "2 x 10), every node reached by the robot's final approach, in serpentine order; the stations (placements of\n"
      "the artefact: several regions on one, neighbours tied by measuring a line of each other's nodes), each set\n"
      "closed by its first point again; prints the summary and the time at the cell's speeds. A region whose table\n"
      "file does not exist yet needs its bounds x_mm, y_mm");
  plan->add_option("--cell", opt.cell, "the cell file ([measure] describes the device)")->required();
  plan->add_option("-o,--output", opt.output, "the plan to write (CSV; '-' for stdout)")->required();
  plan->add_option("--region", opt.regions, "measure only this region (repeatable; default: every region)");
  AddNumberOption(*plan, "--pitch", opt.pitch_mm,
                  "the grid pitch in mm (default: the interpolation estimate's, from the declared roughness or the previous table)", limits::kMeasurePitchMm);
  AddNumberOption(*plan, "--sets", opt.sets, "sets of repetitions per node (the paper: 2)", limits::kMeasureSets)
      ->capture_default_str();
  AddNumberOption(*plan, "--repetitions", opt.repetitions, "repetitions per node and set (the paper: 10)",
                  limits::kMeasureRepetitions)
      ->capture_default_str();
  plan->add_flag("--no-check-points", opt.no_check_points,
                 "no check points between nodes (the interpolation error is then estimated from the table alone)");
  plan->add_flag("--bidirectional", opt.bidirectional,
                 "the bidirectional measurement of ISO 230-2: every point also approached (and probed) against the final\n"
                 "approach; table build gives each node its reversal value (reversal_mm: the backlash)");
  plan->callback([&options] { RunPlan(opt, options); });
}

}  // namespace smtcal::tools
