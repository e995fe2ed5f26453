// smtcal compile / smtcal verify: a .place program plus a cell file through
// the checks and the correction passes; compile also emits the corrected
// program, verify only reports.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "base/json_text.h"
#include "backend/c/c_data.h"
#include "backend/linuxcnc/linuxcnc_dry_run.h"
#include "backend/linuxcnc/linuxcnc_emit.h"
#include "backend/linuxcnc/linuxcnc_machine.h"
#include "frontend/linuxcnc_config.h"
#include "backend/place/place_printer.h"
#include "backend/reports/compile_report.h"
#include "calibration/cell.h"
#include "frontend/parse.h"
#include "ir/ir_ops.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"
#include "passes/pass_manager.h"
#include "tools/commands.h"
#include "tools/compile_or_report.h"

namespace smtcal::tools {
namespace {

struct CompileOptions {
  std::string program_path;
  std::string cell_path;
  std::string target = "place";
  std::string output;
  std::string report;
  bool json = false;
  bool verify_each = false;
  bool dry_run_probe = false;  // --target linuxcnc: also OUT/dry-run/smtcal_probe_trips.ngc
  std::string ini;             // --target linuxcnc: the machine's INI, checked; the runtime goes where it says
};


ReportCounts Counts(const Diagnostics& diags) {
  return {static_cast<int>(diags.error_count()), static_cast<int>(diags.warning_count()), diags.limit_reached()};
}

// The corrected program says at its top what it is.
void AddHeader(ir::Program& program, const cell::Cell& cell) {
  std::vector<std::string> lines = {
      fmt::format("{}{} for cell '{}' ({}). Do not edit; compile the source again.", ir::kCorrectedHeaderPrefix,
                  SMTCAL_VERSION,
                  cell.name, cell.path),
      " XY(...) in Pick/Place/Jump/Go/Move are robot commands (nominal coordinates) with the required",
      " position in the comment; points in fixture frames are corrected on the controller after each Scan.",
  };
  // The cell and table files it was compiled with: `smtcal diff` finds and checks them by these.
  for (const cell::CellFile& file : cell.files) lines.push_back(" " + cell::CellFileLine(file));
  ir::Block header;
  for (const std::string& line : lines) {
    auto stmt = std::make_unique<ir::Stmt>();
    stmt->loc = program.items.empty() ? SourceLoc{} : program.items.front()->loc;
    stmt->node = ir::Comment{line};
    header.push_back(std::move(stmt));
  }
  program.items.insert(program.items.begin(), std::make_move_iterator(header.begin()),
                       std::make_move_iterator(header.end()));
}

void RunCompile(const CompileOptions& opt, GlobalOptions& options) {
  if (FilesClash({{"PROGRAM", opt.program_path}, {"--cell", opt.cell_path}, {"--ini", opt.ini}},
                 {{"-o", opt.output, opt.target == "linuxcnc"}, {"--report", opt.report}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  CompiledProgram compiled;
  if (!CompileForCellOrReport(opt.program_path, opt.cell_path, opt.verify_each, sources, diags, compiled, options)) {
    return;
  }
  const CompileState& state = *compiled.program.compile;
  // The LinuxCNC emitter reports what it cannot lower with the passes'
  // diagnostics; it writes the main program as it goes (into the output
  // directory's temporary, or into memory for -o -).
  std::optional<LinuxCncOutput> linuxcnc;
  std::unique_ptr<LinuxCncDirectory> directory;
  TextOutput review;  // -o -, or where the text goes when the directory cannot be written
  Status opened = Ok{};
  // The machine's INI and HAL files (--ini): checked against the cell and
  // the program below; the runtime goes to the folder its SUBROUTINE_PATH names.
  std::optional<IniFile> ini;
  HalConfig hal;
  std::filesystem::path runtime_folder;
  if (opt.target == "linuxcnc" && !opt.ini.empty() && !diags.has_errors()) {
    Result<IniFile> read = ReadLinuxCncIni(opt.ini, sources, diags);
    if (!read) {
      options.exit_code = PrintDiagnostics(diags, options);
      options.exit_code = ReportIoError(read.error());
      return;
    }
    ini = std::move(read).value();
    hal = ReadLinuxCncHal(*ini, sources, diags);
    Result<std::filesystem::path> folder = LinuxCncRuntimeFolder(*ini);
    if (folder) {
      runtime_folder = folder.value();
    } else {
      diags.Report(DiagKind::LinuxCncSubroutinePath, ini->range,
                   "name the folder smtcal writes its runtime into (e.g. SUBROUTINE_PATH = smtcal-runtime)");
    }
  }
  if (opt.target == "linuxcnc" && !diags.has_errors()) {
    TextOutput* main = &review;
    if (opt.output != "-") {
      Result<std::unique_ptr<LinuxCncDirectory>> open =
          LinuxCncDirectory::Open(opt.output, LinuxCncMainName(opt.program_path), runtime_folder);
      if (open) {
        directory = std::move(open).value();
        main = &directory->main();
      } else {
        opened = open.error();  // reported after the diagnostics, as a failed write is
      }
    }
    linuxcnc = EmitLinuxCnc(compiled.program, state, opt.program_path, *main, diags);
    if (linuxcnc && opt.dry_run_probe) {
      linuxcnc->dry_run.push_back({kLinuxCncDryRunFile, EmitLinuxCncDryRunProbe(*compiled.cell)});
    }
    if (linuxcnc && ini) CheckLinuxCncMachine(*compiled.cell, linuxcnc->io, *ini, hal, sources, diags);
  }
  options.exit_code = PrintDiagnostics(diags, options);
  if (diags.has_errors()) return;  // nothing half-written
  std::string text;
  if (opt.target == "c") {
    for (const cell::Fixture& fixture : compiled.cell->fixtures) {
      if (FitsCRuntime(fixture)) continue;
      options.exit_code = ReportInputError(
          fmt::format("the scan paths of fixture '{}' make more trips than the C runtime holds ({}, "
                      "SMTCAL_MAX_TRIPS in runtime/c/smtcal_runtime.h)",
                      fixture.name, kCRuntimeMaxTrips));
      return;
    }
    text = EmitCRuntimeData(*compiled.cell, CRuntimeFixturePoints(state), ir::ProgramName(compiled.program));
  } else if (opt.target == "place") {
    AddHeader(compiled.program, *compiled.cell);
  }
  // The report and the program are written together or not at all: the
  // report waits, complete, beside its file until the program is written.
  std::optional<StagedOutput> report;
  if (!opt.report.empty()) {
    Result<StagedOutput> staged =
        StagedOutput::Stage(opt.report, JsonText(CompileReportJson(compiled.program, state, sources, Counts(diags))));
    if (!staged) {
      options.exit_code = ReportIoError(staged.error());
      return;
    }
    report.emplace(std::move(staged).value());
  }
  // Without the machine's INI: a machine for the cell beside the program.
  std::vector<LinuxCncMachineFile> machine;
  if (linuxcnc && !ini) {
    machine = EmitLinuxCncMachine(*compiled.cell, linuxcnc->io,
                                  std::filesystem::path(linuxcnc->main_name).stem().string());
  }
  Status written = opt.target == "c"       ? WriteFileAtomically(opt.output, text)
                   : opt.target == "place" ? WritePlace(opt.output, compiled.program)
                   : !opened               ? opened
                   : directory             ? directory->Commit(*linuxcnc, machine)
                                           : WriteFileAtomically("-", LinuxCncReviewText(*linuxcnc, review.text()));
  if (written && report) written = report->Commit();
  if (!written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  const std::string what = opt.target == "c"       ? "the C runtime's data"
                           : opt.target == "place" ? "the corrected program"
                           : ini                   ? fmt::format("the LinuxCNC program; its runtime in {}, checked "
                                                                 "against {}",
                                                                 runtime_folder.string(), opt.ini)
                                                   : "the LinuxCNC program, its subroutines and a machine for it";
  SayDone(options, opt.output,
          fmt::format("wrote {} ({} for cell '{}', {} targets){}", opt.output, what, compiled.cell->name,
                      state.targets.size(), opt.report.empty() ? std::string() : " and the report " + opt.report));
}

void RunVerify(const CompileOptions& opt, GlobalOptions& options) {
  if (FilesClash({{"PROGRAM", opt.program_path}, {"--cell", opt.cell_path}}, {})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  CompiledProgram compiled;
  if (!CompileForCellOrReport(opt.program_path, opt.cell_path, opt.verify_each, sources, diags, compiled, options)) {
    return;
  }
  options.exit_code = PrintDiagnostics(diags, options);
  const CompileState& state = *compiled.program.compile;
  std::string text = opt.json ? JsonText(CompileReportJson(compiled.program, state, sources, Counts(diags)))
                              : VerifySummaryText(compiled.program, state, sources, Counts(diags));
  if (Status written = WriteFileAtomically("-", text); !written) options.exit_code = ReportIoError(written.error());
}

void AddCommonOptions(CLI::App& command, CompileOptions& opt) {
  command.add_option("PROGRAM", opt.program_path, "the .place program ('-' for stdin)")->required();
  command.add_option("--cell", opt.cell_path, "the cell file (*.cell.toml, docs/cell.md)")->required();
  command.add_flag("--verify-each", opt.verify_each,
                   "verify the IR after every pass and name the pass that broke it (for debugging smtcal)");
  command.footer("Correction passes, in order (after the checks of `smtcal check`):\n" +
                 DescribePasses(CorrectionPassRegistry()));
}

}  // namespace

void AddCompileCommand(CLI::App& app, GlobalOptions& options) {
  static CompileOptions compile_options;
  CLI::App* compile = app.add_subcommand(
      "compile", "Correct a .place program for a cell: static targets inverted through the error tables, taught "
                 "points converted, a Scan injected into every Cycle; write the corrected program");
  AddCommonOptions(*compile, compile_options);
  compile->add_option("--target", compile_options.target,
                      "what to write: place (the corrected program, same language), c (the program's fixture "
                      "points and the cell's tables as C data for runtime/c) or linuxcnc (RS274NGC: -o names a "
                      "directory that gets PROGRAM.ngc and subroutines/, docs/linuxcnc.md)")
      ->check(CLI::IsMember({"place", "c", "linuxcnc"}))
      ->capture_default_str();
  compile->add_option("-o,--output", compile_options.output,
                      "the file to write, the directory for --target linuxcnc ('-' for stdout: with linuxcnc, the "
                      "main program and smtcal_data.ngc for review)")
      ->required();
  compile->add_flag("--dry-run-probe", compile_options.dry_run_probe,
                    "with --target linuxcnc: also write OUT/dry-run/smtcal_probe_trips.ngc, the nominal trips of "
                    "the nominal board instead of the marker scan, for rs274 only (put OUT/dry-run first on its "
                    "subroutine path; examples/linuxcnc/README.md)");
  compile->add_option("--ini", compile_options.ini,
                      "with --target linuxcnc: the machine's LinuxCNC INI; it and its HAL files are checked against "
                      "the cell and the program (limits, speeds, servo period, signals), and the runtime goes to the "
                      "folder its SUBROUTINE_PATH names, shared by every program for that machine (-o then gets "
                      "the main program only). Without it, -o also gets a machine for the cell (PROGRAM.ini, "
                      ".hal, .tbl, .var)");
  compile->add_option("--report", compile_options.report,
                      "also write a JSON report of every motion target (required and nominal position, correction, "
                      "region, residual, budget) and the cycle-time estimate");
  compile->callback([&options] {
    if (compile_options.dry_run_probe && compile_options.target != "linuxcnc") {
      options.exit_code = ReportUsageError("--dry-run-probe needs --target linuxcnc");
      return;
    }
    if (!compile_options.ini.empty() && compile_options.target != "linuxcnc") {
      options.exit_code = ReportUsageError("--ini needs --target linuxcnc");
      return;
    }
    RunCompile(compile_options, options);
  });

  static CompileOptions verify_options;
  CLI::App* verify = app.add_subcommand(
      "verify", "Run the checks and correction passes for a cell without writing anything; print a summary "
                "(exit 1 when anything is out of tolerance)");
  AddCommonOptions(*verify, verify_options);
  verify->add_flag("--json", verify_options.json, "print the JSON report instead of the summary");
  verify->callback([&options] { RunVerify(verify_options, options); });
}

}  // namespace smtcal::tools
