// `smtcal measure program PLAN.csv --cell CELL.toml -o DIR`: the plan's
// measuring programs for LinuxCNC (backend/linuxcnc/linuxcnc_measure.h,
// docs/measure.md): DIR/measure_*.ngc, one per region (and for the
// transducer per axis and mounting), and DIR/subroutines/ with the measuring
// runtime. `--start VISIT` resumes after an abort. This file wires the
// inputs, the output directory and the exit codes.
#include <filesystem>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "backend/linuxcnc/linuxcnc_emit.h"
#include "backend/linuxcnc/linuxcnc_measure.h"
#include "frontend/cell_toml.h"
#include "frontend/measurement_input.h"
#include "calibration/limits.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

struct ProgramOptions {
  std::string plan;
  std::string cell;
  std::string output;
  std::string log_dir;
  int start = 1;
};

void RunProgram(const ProgramOptions& opt, GlobalOptions& options) {
  if (FilesClash({{"PLAN", opt.plan}, {"--cell", opt.cell}}, {{"-o", opt.output, true}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  std::optional<cell::Cell> cell;
  std::optional<measure::LoadedPlan> plan;
  if (!LoadMeasurePlan(opt.plan, opt.cell, sources, diags, options, cell, plan)) return;
  options.exit_code = PrintDiagnostics(diags, options);
  if (options.exit_code != kExitOk) return;
  const int visits = static_cast<int>(plan->plan.visits.size());
  if (opt.start > visits) {
    options.exit_code = ReportUsageError(fmt::format("--start {}: the plan has {} visits", opt.start, visits));
    return;
  }
  MeasuringPrograms programs = EmitMeasuringPrograms(*plan, *cell, opt.start, opt.log_dir);
  LinuxCncOutput output;
  output.main_name = programs.programs.front().name;
  output.subroutines = programs.subroutines;
  output.more_mains.assign(programs.programs.begin() + 1, programs.programs.end());
  Result<std::unique_ptr<LinuxCncDirectory>> directory =
      LinuxCncDirectory::Open(std::filesystem::path(opt.output), output.main_name);
  if (!directory) {
    options.exit_code = ReportIoError(directory.error());
    return;
  }
  directory.value()->main().Append(programs.programs.front().text);
  Status written = directory.value()->Commit(output);
  if (!written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (!options.quiet) {
    for (std::size_t k = 0; k < programs.programs.size(); ++k) {
      fmt::print("{}/{}  logs to {}\n", opt.output, programs.programs[k].name, programs.logs[k]);
    }
  }
  SayDone(options, opt.output,
          fmt::format("wrote {} ({} measuring program{} and the measuring runtime; from visit {})", opt.output,
                      programs.programs.size(), programs.programs.size() == 1 ? "" : "s", opt.start));
}

}  // namespace

bool LoadCellForMeasure(const std::string& path, SourceManager& sources, Diagnostics& diags, GlobalOptions& options,
                        std::optional<cell::Cell>& cell) {
  Result<std::optional<cell::Cell>> loaded =
      cell::LoadCell(path, sources, diags, cell::CellLoadOptions{.tables_may_be_missing = true});
  if (!loaded) {
    options.exit_code = ReportIoError(loaded.error());
    return false;
  }
  if (loaded.value() && !loaded.value()->measure) {
    diags.Report(DiagKind::MeasureNoDevice, SourceRange(SourceLoc{loaded.value()->file, 0, 0}), loaded.value()->name);
  } else if (loaded.value() && !loaded.value()->robot.final_approach_mm) {
    diags.Report(DiagKind::MeasureNoApproach, loaded.value()->robot.range);
  }
  if (!loaded.value() || diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return false;
  }
  cell = std::move(loaded.value());
  return true;
}

bool LoadMeasurePlan(const std::string& plan_path, const std::string& cell_path, SourceManager& sources,
                     Diagnostics& diags, GlobalOptions& options, std::optional<cell::Cell>& cell,
                     std::optional<measure::LoadedPlan>& plan) {
  if (!LoadCellForMeasure(cell_path, sources, diags, options, cell)) return false;
  Result<std::uint32_t> file = sources.Load(plan_path);
  if (!file) {
    options.exit_code = ReportIoError(file.error());
    return false;
  }
  plan = measure::LoadPlan(file.value(), *cell, diags);
  if (!plan) {
    options.exit_code = PrintDiagnostics(diags, options);
    return false;
  }
  return true;
}

void AddMeasureProgramCommand(CLI::App& measure, GlobalOptions& options) {
  static ProgramOptions opt;
  CLI::App* program = measure.add_subcommand(
      "program",
      "Make the plan's measuring programs for LinuxCNC: OUTDIR/measure_<region>[_<axis>][_s<mounting>].ngc, one per\n"
      "region (the transducer: per axis and mounting of its plate), and OUTDIR/subroutines/ with the measuring\n"
      "runtime. Each visit: the final approach onto the node, a dwell, the device's readings, one log line per\n"
      "reading (LOGOPEN); a faulted device or a missing reading aborts and names the visit to resume at");
  program->add_option("PLAN", opt.plan, "the plan (smtcal measure plan)")->required();
  program->add_option("--cell", opt.cell, "the cell file the plan was made for")->required();
  program->add_option("-o,--output", opt.output, "the output directory (replaced only when smtcal wrote it)")
      ->required();
  AddNumberOption(*program, "--start", opt.start,
                  "resume at this visit: programs before it are left out, the one holding it starts there and\n"
                  "appends to its log (LOGAPPEND)",
                  limits::kMeasureStartVisit)
      ->capture_default_str();
  program->add_option("--log-dir", opt.log_dir,
                      "where the controller writes the logs (default: LinuxCNC's working directory, the folder of\n"
                      "its INI file)");
  program->callback([&options] { RunProgram(opt, options); });
}

}  // namespace smtcal::tools
