// `smtcal cell check CELL.toml`: load a cell file (docs/cell.md) with its
// error tables, report every mistake in it, and print a short summary of what
// it describes (text, or JSON with --json). The loading and all the checks
// are in frontend/cell_toml.cpp; this file only wires the file, the options,
// the summary and the exit codes.
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <CLI/CLI.hpp>

#include "backend/reports/table_report.h"
#include "backend/reports/cell_plot.h"
#include "base/field_text.h"
#include "base/json_text.h"
#include "calibration/fixture_geometry.h"
#include "calibration/scan_plan.h"
#include "frontend/cell_toml.h"
#include "ir/symbols.h"
#include "passes/compile_pipeline.h"
#include "passes/correction/compile_state.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

using nlohmann::ordered_json;

// Numbers as the user wrote them: the shortest form that reads back.
std::string Num(double value) { return fmt::format("{}", value); }

std::string Range(const cell::Interval& interval) { return fmt::format("{}..{}", Num(interval.lo), Num(interval.hi)); }

std::string Point(const std::array<double, 4>& p) {
  return fmt::format("({}, {}, {}, {})", Num(p[0]), Num(p[1]), Num(p[2]), Num(p[3]));
}

std::string Axes(const cell::Region& region) {
  std::string axes;
  for (cell::TaskAxis axis : region.difficulty_axes) {
    axes += fmt::format("{}{}", axes.empty() ? "" : ", ", cell::TaskAxisName(axis));
  }
  return axes;
}

std::string Join(const std::vector<std::string>& items, std::string_view separator) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : std::string(separator)) + item;
  return text;
}

std::string SummaryText(const cell::Cell& cell) {
  std::string out = fmt::format("cell '{}' ({})\n", cell.name, cell.path);
  const cell::Robot& robot = cell.robot;
  out += fmt::format("robot {}: x {} mm, y {} mm, z {} mm, u {} deg; repeatability ±{} mm; safe LimZ {} mm\n",
                     robot.model.empty() ? "(no model given)" : robot.model, Range(robot.limits[0]),
                     Range(robot.limits[1]), Range(robot.limits[2]), Range(robot.limits[3]),
                     Num(robot.repeatability_mm), Num(robot.safe_limz_mm));
  out += fmt::format("  motion: xy {} mm/s, {} mm/s²; z {} mm/s, {} mm/s²; u {} deg/s, {} deg/s²; "
                     "pick {} s, place {} s\n",
                     Num(robot.xy_speed_mm_s), Num(robot.xy_accel_mm_s2), Num(robot.z_speed_mm_s),
                     Num(robot.z_accel_mm_s2), Num(robot.u_speed_deg_s), Num(robot.u_accel_deg_s2),
                     Num(robot.pick_time_s), Num(robot.place_time_s));

  out += fmt::format("regions: {}\n", cell.regions.size());
  for (const cell::Region& region : cell.regions) {
    out += fmt::format("  {}: x {}, y {} mm; table {} (domain x {}..{}, y {}..{} mm); D = ({}, {{{}}}); "
                       "tolerance ±{} mm; outside {}\n",
                       region.name, Range(region.x_mm), Range(region.y_mm), region.table_path, Num(region.domain.x0),
                       Num(region.domain.x1), Num(region.domain.y0), Num(region.domain.y1), region.difficulty_level,
                       Axes(region), Num(region.tolerance_mm), cell::OutsidePolicyName(region.outside));
    out += fmt::format("    between the nodes: {}\n", InterpolationText(region.interpolation, region.tolerance_mm));
  }

  out += fmt::format("fixtures: {}\n", cell.fixtures.size());
  for (const cell::Fixture& fixture : cell.fixtures) {
    std::string teach = fixture.teach_trips_mm.empty()
                            ? "no (taught points cannot use it)"
                            : fmt::format("yes ({} trips)", fixture.teach_trips_mm.size());
    out += fmt::format("  {}: origin ({}, {}) mm, angle {} deg; L1 {} mm, L2 {} mm; {} scan path(s), {} trips; "
                       "estimator {}; teach scan {}\n",
                       fixture.name, Num(fixture.origin_mm.x()), Num(fixture.origin_mm.y()), Num(fixture.angle_deg),
                       Num(fixture.l1_mm), Num(fixture.l2_mm), fixture.scan_paths.size(),
                       ExpectedTrips(fixture).size(), cell::EstimatorName(fixture.estimator), teach);
    const CaptureRange capture = ScanCaptureRange(fixture);
    out += fmt::format("    scan: {}; capture range {} mm and {} deg, {} x the limits ({} mm, {} deg){}\n",
                       fixture.latch_speed_mm_s > 0
                           ? fmt::format("two stages, search {} mm/s, latch {} mm/s", Num(fixture.scan_speed_mm_s),
                                         Num(fixture.latch_speed_mm_s))
                           : fmt::format("one stage at {} mm/s", Num(fixture.scan_speed_mm_s)),
                       fmt::format("{:.2f}", capture.shift_mm), fmt::format("{:.3f}", capture.rotation_deg),
                       fmt::format("{:.2f}", capture.factor), Num(fixture.max_shift_mm), Num(fixture.max_rotation_deg),
                       capture.factor >= 1 ? "" : ": smaller than the limits");
  }

  out += fmt::format("feeders: {}\n", cell.feeders.size());
  for (const cell::Feeder& feeder : cell.feeders) {
    std::string line = fmt::format("  {}: pick {}", feeder.name, Point(feeder.pick));
    if (feeder.pallet_last && feeder.pallet_back) {
      line += fmt::format("; pallet {} x {}, last {}, back {}", feeder.columns, feeder.rows,
                          Point(*feeder.pallet_last), Point(*feeder.pallet_back));
    }
    if (!feeder.packages.empty()) line += fmt::format("; package {}", Join(feeder.packages, ", "));
    if (!feeder.value.empty()) line += fmt::format("; value {}", feeder.value);
    const int points = feeder.columns * feeder.rows;
    if (feeder.kind == cell::FeederKind::kTray) {
      line += fmt::format("; a tray of {} pockets, one part each", points);
    } else if (feeder.pallet_last && points > 1) {
      line += static_cast<int>(feeder.packages.size()) == points
                  ? fmt::format("; a bank of {} tapes, lane k holds the k-th package", points)
                  : fmt::format("; a bank of {} tapes, each kind of part takes the next free lane", points);
    }
    out += line + "\n";
  }
  return out;
}

ordered_json Pair(double a, double b) { return ordered_json::array({a, b}); }
ordered_json Pair(const cell::Interval& interval) { return Pair(interval.lo, interval.hi); }

ordered_json CaptureJson(const CaptureRange& capture, const cell::Fixture& fixture) {
  return {{"factor", RoundedToDecimals(capture.factor, 4)},
          {"shift_mm", RoundedToDecimals(capture.shift_mm, 4)},
          {"rotation_deg", RoundedToDecimals(capture.rotation_deg, 5)},
          {"covers_limits", capture.factor >= 1},
          {"limited_by", capture.limited_by.empty() ? ordered_json() : ordered_json(capture.limited_by)},
          {"max_shift_mm", fixture.max_shift_mm},
          {"max_rotation_deg", fixture.max_rotation_deg}};
}

std::string SummaryJson(const cell::Cell& cell) {
  ordered_json out;
  out["name"] = cell.name;
  out["path"] = cell.path;
  const cell::Robot& robot = cell.robot;
  out["robot"] = {{"model", robot.model},
                  {"x_mm", Pair(robot.limits[0])},
                  {"y_mm", Pair(robot.limits[1])},
                  {"z_mm", Pair(robot.limits[2])},
                  {"u_deg", Pair(robot.limits[3])},
                  {"repeatability_mm", robot.repeatability_mm},
                  {"safe_limz_mm", robot.safe_limz_mm},
                  {"xy_speed_mm_s", robot.xy_speed_mm_s},
                  {"xy_accel_mm_s2", robot.xy_accel_mm_s2},
                  {"z_speed_mm_s", robot.z_speed_mm_s},
                  {"z_accel_mm_s2", robot.z_accel_mm_s2},
                  {"u_speed_deg_s", robot.u_speed_deg_s},
                  {"u_accel_deg_s2", robot.u_accel_deg_s2},
                  {"pick_time_s", robot.pick_time_s},
                  {"place_time_s", robot.place_time_s}};
  out["regions"] = ordered_json::array();
  for (const cell::Region& region : cell.regions) {
    ordered_json axes = ordered_json::array();
    for (cell::TaskAxis axis : region.difficulty_axes) axes.push_back(cell::TaskAxisName(axis));
    out["regions"].push_back(
        {{"name", region.name},
         {"x_mm", Pair(region.x_mm)},
         {"y_mm", Pair(region.y_mm)},
         {"table", region.table_path},
         {"domain", {{"x_mm", Pair(region.domain.x0, region.domain.x1)},
                     {"y_mm", Pair(region.domain.y0, region.domain.y1)}}},
         {"difficulty", {{"level", region.difficulty_level}, {"axes", axes}}},
         {"tolerance_mm", region.tolerance_mm},
         {"outside", cell::OutsidePolicyName(region.outside)},
         {"interpolation", InterpolationJson(region.interpolation, region.tolerance_mm)}});
  }
  out["fixtures"] = ordered_json::array();
  for (const cell::Fixture& fixture : cell.fixtures) {
    ordered_json paths = ordered_json::array();
    for (const cell::ScanPath& path : fixture.scan_paths) paths.push_back(path.name);
    out["fixtures"].push_back(
        {{"name", fixture.name},
         {"origin_mm", Pair(fixture.origin_mm.x(), fixture.origin_mm.y())},
         {"angle_deg", fixture.angle_deg},
         {"l1_mm", fixture.l1_mm},
         {"l2_mm", fixture.l2_mm},
         {"scan_paths", paths},
         {"trips", ExpectedTrips(fixture).size()},
         {"estimator", cell::EstimatorName(fixture.estimator)},
         {"teach_scan", !fixture.teach_trips_mm.empty()},
         {"teach_trips", fixture.teach_trips_mm.size()},
         {"scan_speed_mm_s", fixture.scan_speed_mm_s},
         {"latch_speed_mm_s", fixture.latch_speed_mm_s > 0 ? ordered_json(fixture.latch_speed_mm_s) : ordered_json()},
         {"capture", CaptureJson(ScanCaptureRange(fixture), fixture)}});
  }
  out["feeders"] = ordered_json::array();
  for (const cell::Feeder& feeder : cell.feeders) {
    ordered_json entry = {{"name", feeder.name}, {"pick", feeder.pick}};
    if (feeder.pallet_last && feeder.pallet_back) {
      entry["pallet"] = {{"last", *feeder.pallet_last},
                         {"back", *feeder.pallet_back},
                         {"columns", feeder.columns},
                         {"rows", feeder.rows}};
    }
    entry["packages"] = feeder.packages;
    entry["value"] = feeder.value;
    out["feeders"].push_back(entry);
  }
  return JsonText(out);
}

// The checks `cell check` makes of a loaded cell beyond the loader's own
// (`table_warnings`: unless the compile pipeline has made that one).
void CheckCell(const cell::Cell& cell, Diagnostics& diags, bool table_warnings) {
  cell::CheckScanCalibration(cell, diags);
  if (table_warnings) cell::ReportTableWarnings(cell, diags);
  cell::ReportGridAdvice(cell, diags);
  cell::CheckPockets(cell, diags);
}

void RunCheck(const std::string& path, bool json, GlobalOptions& options) {
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(path, sources, diags);
  if (!loaded) {
    options.exit_code = ReportIoError(loaded.error());
    return;
  }
  if (loaded.value()) CheckCell(*loaded.value(), diags, true);
  options.exit_code = PrintDiagnostics(diags, options);
  if (!loaded.value()) return;  // the errors were printed
  const cell::Cell& cell = *loaded.value();
  Status written = WriteFileAtomically("-", json ? SummaryJson(cell) : SummaryText(cell));
  if (!written) options.exit_code = ReportIoError(written.error());
}

// The program's targets for the picture, each statement's runs numbered.
std::vector<PlottedTarget> PlotTargets(const CompileState& state) {
  std::vector<PlottedTarget> targets;
  std::map<const ir::Stmt*, int> runs;
  for (const Target& target : state.targets) {
    if (target.known) ++runs[target.stmt];
  }
  std::map<const ir::Stmt*, int> seen;
  for (const Target& target : state.targets) {
    if (!target.known) continue;
    targets.push_back({target.text, target.required[0], target.required[1], target.required[3], target.is_placement(),
                       target.fixture, sema::StmtRange(*target.stmt), ++seen[target.stmt], runs[target.stmt]});
  }
  return targets;
}

// `smtcal cell plot CELL.toml -o FILE.svg [--program P.place]`: the cell as
// a picture (backend/reports/cell_plot.h); with a program, its placements
// where the correction passes put them at the fixtures' nominal poses. A
// cell with errors is drawn as far as it was read, every error and warning
// ringed where it is; the exit code is `cell check`'s (with a program,
// `verify`'s too), but the picture is written.
void RunPlot(const std::string& path, const std::string& output, const std::string& program_path,
             GlobalOptions& options) {
  if (FilesClash({{"CELL", path}, {"--program", program_path}}, {{"-o", output}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  // The cell as far as it can be drawn, with its own diagnostics.
  SourceManager cell_sources;
  Diagnostics cell_diags(cell_sources);
  cell::CellLoadOptions drawable;
  drawable.keep_drawable = true;
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(path, cell_sources, cell_diags, drawable);
  if (!loaded) {
    PrintDiagnostics(cell_diags, options);
    options.exit_code = ReportIoError(loaded.error());
    return;
  }
  if (!loaded.value()) {  // not a cell file at all: nothing to draw
    options.exit_code = PrintDiagnostics(cell_diags, options);
    if (options.exit_code == kExitOk) options.exit_code = kExitInputError;
    return;
  }
  // A clean cell and a program: the program compiled for it (the cell loaded
  // again by the pipeline), its diagnostics and the cell's in one list.
  SourceManager sources;
  Diagnostics diags(sources);
  CompiledProgram compiled;
  std::string program_note;
  const bool with_program = !program_path.empty() && !cell_diags.has_errors();
  if (!program_path.empty() && cell_diags.has_errors()) {
    program_note = fmt::format("the placements of {} are not drawn: the cell has errors",
                               std::filesystem::path(program_path).filename().string());
  }
  if (with_program) {
    Result<std::uint32_t> file = sources.Load(program_path);
    if (!file) {
      options.exit_code = ReportIoError(file.error());
      return;
    }
    Result<bool> ran = smtcal::CompileForCell(file.value(), path, false, sources, diags, compiled);
    if (!ran) {
      PrintDiagnostics(diags, options);
      options.exit_code = ReportIoError(ran.error());
      return;
    }
  }
  const cell::Cell& cell = with_program && compiled.cell ? *compiled.cell : *loaded.value();
  Diagnostics& shown = with_program ? diags : cell_diags;
  CheckCell(cell, shown, !with_program);
  std::vector<PlottedTarget> targets;
  if (with_program && compiled.program.compile != nullptr) targets = PlotTargets(*compiled.program.compile);
  const std::vector<PlotFinding> findings = LocateFindings(cell, targets, shown);
  options.exit_code = PrintDiagnostics(shown, options);
  const std::string title = std::filesystem::path(path).filename().string();
  const std::string program = program_path.empty() ? "" : std::filesystem::path(program_path).filename().string();
  Status written = WriteFileAtomically(output, PlotCellSvg(cell, title, program, targets, findings, program_note));
  if (!written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  SayDone(options, output,
          findings.empty() ? fmt::format("wrote the picture {}", output)
                           : fmt::format("wrote the picture {} ({} error{} and {} warning{} marked)", output,
                                         shown.error_count(), shown.error_count() == 1 ? "" : "s",
                                         shown.warning_count(), shown.warning_count() == 1 ? "" : "s"));
}

}  // namespace

void AddCellCommand(CLI::App& app, GlobalOptions& options) {
  static std::string path;
  static bool json = false;
  CLI::App* cell = app.add_subcommand(
      "cell", "Check and draw cell files (*.cell.toml): robot, calibrated regions, fixtures, feeders (docs/cell.md)");
  cell->require_subcommand(1);
  CLI::App* check = cell->add_subcommand(
      "check", "Load a cell file and its error tables, report every mistake (exit 1), and print a summary:\n"
               "the robot, each region (bounds, table domain, difficulty, tolerance, policy, the interpolation\n"
               "error between its table's nodes and the pitch to measure at when it is more than 10 % of the\n"
               "tolerance), each fixture\n"
               "(pose, L1/L2, scan trips, estimator, teach scan) and each feeder");
  check->add_option("CELL", path,
                    "the cell file ('-' for stdin; its table paths are then relative to the current directory)")
      ->required();
  check->add_flag("--json", json, "print the summary as JSON instead of text");
  check->callback([&options] { RunCheck(path, json, options); });

  static std::string plot_path, plot_output, plot_program;
  CLI::App* plot = cell->add_subcommand(
      "plot", "Draw the cell as an SVG picture: the robot's travel, the regions with their tables' extent,\n"
              "the fixtures with markers, scan paths and nominal trips, the feeders with their lanes and\n"
              "pockets, and with --program the program's placements and each part's orientation. Every\n"
              "error and warning of the cell (and the program) is ringed in red where it is and listed;\n"
              "a cell with errors is drawn as far as it was read, and the exit code is cell check's\n"
              "(with --program verify's too), the picture written all the same (docs/cell.md)");
  plot->add_option("CELL", plot_path, "the cell file")->required();
  plot->add_option("-o,--output", plot_output, "the SVG file to write ('-' for stdout)")->required();
  plot->add_option("--program", plot_program, "a .place program whose placements to draw on the fixtures");
  plot->callback([&options] { RunPlot(plot_path, plot_output, plot_program, options); });
}

}  // namespace smtcal::tools
