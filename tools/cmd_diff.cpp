// smtcal diff OLD.place NEW.place: what changes on the machine when NEW is
// deployed instead of OLD (docs/diff.md). The work is in
// backend/program_diff (the diff as a value) and backend/diff_report (text,
// JSON, SVG); this file only wires files, options and exit codes.
#include <fmt/core.h>

#include "backend/diff/diff_report.h"
#include "backend/diff/program_diff.h"
#include "calibration/limits.h"
#include "calibration/tolerances.h"
#include "frontend/cell_toml.h"
#include "frontend/parse.h"
#include "passes/pass_manager.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

struct DiffCommandOptions {
  std::string old_path, new_path;
  std::string cell_path;
  double threshold_um = kDiffDefaultThresholdUm;
  bool json = false;
  std::string svg_path;
  bool exit_zero = false;
};

// Parses a program and runs the semantic checks, like `smtcal check`.
ir::Program ParseAndCheck(std::uint32_t file, Diagnostics& diags) {
  std::size_t errors_before = diags.error_count();
  ir::Program program = ParseProgram(file, diags);
  if (diags.error_count() == errors_before) {
    std::vector<const PassInfo*> checks;
    for (const PassInfo& info : PassRegistry()) checks.push_back(&info);
    RunPasses(program, diags, checks, /*verify_each=*/false);
  }
  return program;
}

void RunDiff(const DiffCommandOptions& opt, GlobalOptions& options) {
  if (FilesClash({{"OLD", opt.old_path}, {"NEW", opt.new_path}, {"--cell", opt.cell_path}},
                 {{"--svg", opt.svg_path}, {"the diff", "-"}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Result<std::uint32_t> old_file = sources.Load(opt.old_path);
  if (!old_file) {
    options.exit_code = ReportIoError(old_file.error());
    return;
  }
  Result<std::uint32_t> new_file = sources.Load(opt.new_path);
  if (!new_file) {
    options.exit_code = ReportIoError(new_file.error());
    return;
  }
  Diagnostics diags(sources);
  ir::Program old_program = ParseAndCheck(old_file.value(), diags);
  ir::Program new_program = ParseAndCheck(new_file.value(), diags);
  std::optional<cell::Cell> cell;
  if (!opt.cell_path.empty()) {
    Result<std::optional<cell::Cell>> loaded = cell::LoadCell(opt.cell_path, sources, diags);
    if (!loaded) {
      PrintDiagnostics(diags, options);
      options.exit_code = ReportIoError(loaded.error());
      return;
    }
    cell = std::move(loaded).value();
  }
  // A program with errors is not compared: its diagnostics are the answer.
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  diff::DiffOptions diff_options;
  diff_options.threshold_um = opt.threshold_um;
  diff_options.cell = cell ? &*cell : nullptr;
  diff::ProgramDiff result = diff::DiffPrograms(old_program, new_program, diff_options, diags);
  options.exit_code = PrintDiagnostics(diags, options);
  if (options.exit_code != kExitOk) return;
  if (!opt.svg_path.empty()) {
    if (Status written = WriteFileAtomically(opt.svg_path, diff::PlotDiffSvg(result)); !written) {
      options.exit_code = ReportIoError(written.error());
      return;
    }
  }
  std::string text = opt.json ? diff::FormatDiffJson(result) : diff::FormatDiffText(result);
  if (Status written = WriteFileAtomically("-", text); !written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  if (!opt.svg_path.empty()) SayDone(options, opt.svg_path, fmt::format("wrote the picture {}", opt.svg_path));
  options.exit_code = result.summary.gate_passes() || opt.exit_zero ? kExitOk : kExitInputError;
}

}  // namespace

void AddDiffCommand(CLI::App& app, GlobalOptions& options) {
  static DiffCommandOptions opt;
  CLI::App* diff = app.add_subcommand(
      "diff",
      "Compare two .place programs (e.g. two outputs of `smtcal compile`): every target's displacement in µm, "
      "added, removed and changed statements, a summary; exit 1 when the deployment gate fails");
  diff->add_option("OLD", opt.old_path, "the program running now ('-' for stdin)")->required();
  diff->add_option("NEW", opt.new_path, "the program to deploy ('-' for stdin)")->required();
  diff->add_option("--cell", opt.cell_path,
                   "the cell file: gives the fixtures' nominal poses, so targets on a fixture are also given in the "
                   "robot base frame");
  AddNumberOption(*diff, "--threshold", opt.threshold_um, "the gate: a target that moved by more than this many µm fails it",
                  limits::kDiffThresholdUm)
      ->capture_default_str();
  diff->add_flag("--json", opt.json, "print the diff as JSON (schema in docs/diff.md) instead of text");
  diff->add_option("--svg", opt.svg_path,
                   "also draw the board to this SVG file: old positions, arrows to the new ones (enlarged), added "
                   "and removed targets");
  diff->add_flag("--exit-zero", opt.exit_zero,
                 "report only: exit 0 even when the gate fails (input and I/O errors still exit 1 and 3)");
  diff->footer(
      "The gate fails (exit 1) when a target moved by more than --threshold, or a statement or declaration was "
      "added, removed or changed other than by its coordinates (docs/diff.md). Comments and formatting never "
      "count.");
  diff->callback([&options] { RunDiff(opt, options); });
}

}  // namespace smtcal::tools
