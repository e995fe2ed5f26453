// smtcal diff OLD NEW: what changes on the machine when NEW is deployed
// instead of OLD (docs/diff.md). The work is in backend/diff (the diff as a
// value, the comparison on the machine, text, JSON, SVG), passes/
// machine_targets.h and calibration/machine_model.h; this file wires files,
// cells, options and exit codes: which cell each program is evaluated with
// (given, or the one a compiled program records), and LinuxCNC outputs read
// back through backend/linuxcnc/linuxcnc_output.h.
#include <filesystem>
#include <map>
#include <memory>

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>

#include "backend/diff/diff_cells.h"
#include "backend/diff/diff_report.h"
#include "backend/diff/program_diff.h"
#include "base/sha256.h"
#include "calibration/limits.h"
#include "calibration/tolerances.h"
#include "frontend/cell_toml.h"
#include "backend/linuxcnc/linuxcnc_output.h"
#include "frontend/parse.h"
#include "ir/ir_ops.h"
#include "passes/machine_targets.h"
#include "passes/pass_manager.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

namespace fs = std::filesystem;

struct DiffCommandOptions {
  std::string old_path, new_path;
  std::string cell_path, old_cell_path, new_cell_path;
  double threshold_um = kDiffDefaultThresholdUm;
  bool json = false;
  std::string svg_path;
  bool exit_zero = false;
  std::string machine = "new";  // whose cell describes the machine: new | old
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

// One program of the diff and the cell it is evaluated with.
struct Side {
  std::string path;
  std::string role;  // "old" or "new": the option --role-cell names
  ir::Program program;
  bool compiled = false;  // smtcal output: its numbers are commands
  const cell::Cell* cell = nullptr;
  diff::DiffSideCell described;
  MachineTargets targets;
  std::optional<LinuxCncOutputRead> linuxcnc;  // a LinuxCNC output, as read back
};

// Loads cells once per path.
class Cells {
 public:
  Cells(SourceManager& sources, Diagnostics& diags) : sources_(sources), diags_(diags) {}
  // Null when it could not be loaded (diagnostics or *io_error say why).
  const cell::Cell* Load(const std::string& path, std::optional<Error>* io_error) {
    auto found = loaded_.find(path);
    if (found != loaded_.end()) return found->second.get();
    Result<std::optional<cell::Cell>> cell = cell::LoadCell(path, sources_, diags_);
    if (!cell) {
      *io_error = cell.error();
      return nullptr;
    }
    if (!cell.value()) return loaded_.emplace(path, nullptr).first->second.get();
    return loaded_.emplace(path, std::make_unique<cell::Cell>(std::move(*cell.value()))).first->second.get();
  }
  // Keeps a cell read some other way (a LinuxCNC output's data).
  const cell::Cell* Keep(cell::Cell cell) {
    kept_.push_back(std::make_unique<cell::Cell>(std::move(cell)));
    return kept_.back().get();
  }

 private:
  SourceManager& sources_;
  Diagnostics& diags_;
  std::map<std::string, std::unique_ptr<cell::Cell>> loaded_;
  std::vector<std::unique_ptr<cell::Cell>> kept_;
};

// "paper-cell" and "paper.cell.toml" from the header "' Corrected by smtcal
// 0.1.0 for cell 'paper-cell' (paper.cell.toml). Do not edit; ...".
std::pair<std::string, std::string> CompiledCell(const ir::Program& program) {
  const ir::Stmt* header = ir::CorrectedHeader(program);
  if (header == nullptr) return {};
  const std::string& text = std::get<ir::Comment>(header->node).text;
  const std::size_t from = text.find("for cell '");
  const std::size_t to = from == std::string::npos ? from : text.find("' (", from + 10);
  const std::size_t end = to == std::string::npos ? to : text.find("). Do not edit", to);
  if (end == std::string::npos) return {};
  return {text.substr(from + 10, to - from - 10), text.substr(to + 3, end - to - 3)};
}

SourceRange HeaderRange(const ir::Program& program) {
  const ir::Stmt* header = ir::CorrectedHeader(program);
  return header != nullptr ? SourceRange(header->loc) : SourceRange(SourceLoc{program.file, 1, 1});
}

// The cell a compiled program records, found where it was given at compile
// time (as written, then beside the program) with the same bytes. Null,
// reported, when no such cell is there.
const cell::Cell* FindRecordedCell(Side& side, const std::vector<cell::CellFile>& recorded, Cells& cells,
                                   Diagnostics& diags, std::optional<Error>* io_error) {
  const cell::CellFile& cell_file = recorded.front();
  std::vector<std::string> candidates = {cell_file.path};
  const fs::path beside = fs::path(side.path).parent_path() / cell_file.path;
  if (fs::path(cell_file.path).is_relative() && !side.path.empty() && side.path != "-" &&
      beside.lexically_normal() != fs::path(cell_file.path).lexically_normal()) {
    candidates.push_back(beside.generic_string());
  }
  std::string why;
  for (const std::string& candidate : candidates) {
    std::error_code error;
    if (!fs::is_regular_file(candidate, error)) continue;
    SourceManager scratch;
    Result<std::uint32_t> bytes = scratch.Load(candidate);
    if (!bytes || Sha256Hex(scratch.File(bytes.value()).text) != cell_file.sha256) {
      why = fmt::format("the cell file at {} is not the one (its sha256 differs)", candidate);
      continue;
    }
    const cell::Cell* cell = cells.Load(candidate, io_error);
    if (cell == nullptr) return nullptr;  // reported
    std::vector<std::string> differences = diff::CellFileDifferences(recorded, *cell);
    if (differences.empty()) {
      side.described.how = fmt::format("the cell it was compiled with, {}", candidate);
      return cell;
    }
    why = fmt::format("the cell at {} has changed since: {}", candidate, fmt::join(differences, "; "));
  }
  if (why.empty()) why = fmt::format("that cell is not there (looked for {})", fmt::join(candidates, " and "));
  const auto [name, path] = CompiledCell(side.program);
  diags.Report(DiagKind::DiffCellNotFound, HeaderRange(side.program), side.path, name, path, why,
               fmt::format("--{}-cell", side.role));
  return nullptr;
}

// The cell `side` is evaluated with: the one given for it (checked against
// what a compiled program records), or the one a compiled program records.
// A source program without a cell of its own gets the other side's (later).
const cell::Cell* CellOf(Side& side, const std::string& given, const std::string& option, Cells& cells,
                         Diagnostics& diags, std::optional<Error>* io_error) {
  const std::vector<cell::CellFile> recorded = side.compiled ? diff::RecordedCellFiles(side.program)
                                                             : std::vector<cell::CellFile>();
  if (given.empty()) {
    if (!side.compiled) return nullptr;
    if (recorded.empty()) {
      const auto [name, path] = CompiledCell(side.program);
      diags.Report(DiagKind::DiffCellNotFound, HeaderRange(side.program), side.path, name, path,
                   "it does not record that cell's files (an older smtcal wrote it)",
                   fmt::format("--{}-cell", side.role));
      return nullptr;
    }
    return FindRecordedCell(side, recorded, cells, diags, io_error);
  }
  const cell::Cell* cell = cells.Load(given, io_error);
  if (cell == nullptr) return nullptr;
  side.described.how = fmt::format("given by {}", option);
  if (!side.compiled) return cell;
  if (recorded.empty()) {
    diags.Report(DiagKind::DiffCellUnrecorded, HeaderRange(side.program), side.path, given);
    return cell;
  }
  std::vector<std::string> differences = diff::CellFileDifferences(recorded, *cell);
  if (!differences.empty()) {
    diags.Report(DiagKind::DiffCellNotCompiledWith, HeaderRange(side.program), side.path, given,
                 fmt::join(differences, "; "), option == "--cell" ? fmt::format("--{}-cell", side.role) : option);
    return nullptr;
  }
  side.described.how = fmt::format("the cell it was compiled with, given by {}", option);
  return cell;
}

void Describe(Side& side) {
  side.described.program = side.path;
  side.described.compiled = side.compiled;
  if (side.cell != nullptr) {
    side.described.cell_name = side.cell->name;
    side.described.files = side.cell->files;
  }
}

bool IsLinuxCnc(const std::string& path) { return path != "-" && LooksLikeLinuxCncOutput(path); }

void RunDiff(const DiffCommandOptions& opt, GlobalOptions& options) {
  if (!opt.cell_path.empty() && (!opt.old_cell_path.empty() || !opt.new_cell_path.empty())) {
    options.exit_code = ReportUsageError("give --cell (one cell for both) or --old-cell/--new-cell, not both");
    return;
  }
  const bool linuxcnc = IsLinuxCnc(opt.old_path);
  if (linuxcnc != IsLinuxCnc(opt.new_path)) {
    options.exit_code = ReportUsageError(fmt::format(
        "{} is a LinuxCNC output and {} is not: compare two LinuxCNC outputs or two .place programs",
        linuxcnc ? opt.old_path : opt.new_path, linuxcnc ? opt.new_path : opt.old_path));
    return;
  }
  if (linuxcnc && (!opt.cell_path.empty() || !opt.old_cell_path.empty() || !opt.new_cell_path.empty())) {
    options.exit_code = ReportUsageError(
        "a LinuxCNC output carries its cell's data (subroutines/smtcal_data.ngc): leave out --cell, --old-cell and "
        "--new-cell");
    return;
  }
  if (FilesClash({{"OLD", opt.old_path},
                  {"NEW", opt.new_path},
                  {"--cell", opt.cell_path},
                  {"--old-cell", opt.old_cell_path},
                  {"--new-cell", opt.new_cell_path}},
                 {{"--svg", opt.svg_path}, {"the diff", "-"}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  Cells cells(sources, diags);
  std::optional<Error> io_error;
  Side old_side, new_side;
  old_side.path = opt.old_path;
  old_side.role = "old";
  new_side.path = opt.new_path;
  new_side.role = "new";
  for (Side* side : {&old_side, &new_side}) {
    if (linuxcnc) {
      Result<std::optional<LinuxCncOutputRead>> read = ReadLinuxCncOutput(side->path, sources, diags);
      if (!read) {
        PrintDiagnostics(diags, options);
        options.exit_code = ReportIoError(read.error());
        return;
      }
      if (!read.value()) continue;  // reported
      LinuxCncOutputRead& output = *read.value();
      // Its diagnostics would name lines of a text nobody sees: the first
      // error is reported at the .ngc line it comes from.
      Diagnostics scratch(sources);
      side->program = ParseAndCheck(output.place_file, scratch);
      for (const Diagnostic& diagnostic : scratch.all()) {
        if (diagnostic.severity != Severity::Error) continue;
        const std::uint32_t line = diagnostic.range.begin.line;
        diags.Report(DiagKind::LinuxCncOutputUnreadable,
                     SourceRange(SourceLoc{output.main_file,
                                           line >= 1 && line <= output.line_map.size() ? output.line_map[line - 1] : 1,
                                           1}),
                     "read back, it is a program smtcal does not accept: " + diagnostic.message);
        break;
      }
      side->compiled = true;
      side->cell = cells.Keep(output.cell);  // the read keeps its own: CheckLinuxCncCommands names its fixtures
      side->described.how = fmt::format("the runtime's data in {}", output.data_path);
      side->linuxcnc = std::move(output);
      continue;
    }
    Result<std::uint32_t> file = sources.Load(side->path);
    if (!file) {
      options.exit_code = ReportIoError(file.error());
      return;
    }
    side->program = ParseAndCheck(file.value(), diags);
    side->compiled = ir::CorrectedHeader(side->program) != nullptr;
  }
  // A program with errors is not compared: its diagnostics are the answer.
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  if (!linuxcnc) {
    for (Side* side : {&old_side, &new_side}) {
      const std::string& own = side == &old_side ? opt.old_cell_path : opt.new_cell_path;
      const std::string& given = own.empty() ? opt.cell_path : own;
      const std::string option = own.empty() ? "--cell" : fmt::format("--{}-cell", side->role);
      side->cell = CellOf(*side, given, option, cells, diags, &io_error);
      if (io_error) {
        PrintDiagnostics(diags, options);
        options.exit_code = ReportIoError(*io_error);
        return;
      }
    }
    // A source program is compiled for the other side's cell when it has none of its own.
    for (auto [side, other] : {std::pair{&old_side, &new_side}, std::pair{&new_side, &old_side}}) {
      if (side->cell == nullptr && !side->compiled && other->cell != nullptr) {
        side->cell = other->cell;
        side->described.how = fmt::format("{}'s cell: a source is compiled here for it", other->role == "old" ? "OLD" : "NEW");
      }
    }
  }
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  for (Side* side : {&old_side, &new_side}) Describe(*side);

  diff::DiffOptions diff_options;
  diff_options.threshold_um = opt.threshold_um;
  diff_options.cell = new_side.cell;
  diff_options.old_cell = old_side.cell;
  diff::ProgramDiff result = diff::DiffPrograms(old_side.program, new_side.program, diff_options, diags);
  if (diags.has_errors()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return;
  }
  // On the machine: what each program commands, with its own cell.
  if (old_side.cell != nullptr && new_side.cell != nullptr) {
    for (Side* side : {&old_side, &new_side}) {
      side->targets = side->compiled ? CompiledProgramTargets(side->program, *side->cell, diags)
                                     : SourceProgramTargets(side->program, *side->cell, diags);
      // Each position is commanded as the runtime is told to.
      if (side->linuxcnc) CheckLinuxCncCommands(side->program, side->targets, *side->linuxcnc, diags);
    }
    if (diags.has_errors()) {
      options.exit_code = PrintDiagnostics(diags, options);
      return;
    }
    diff::CompareOnMachine(result, {old_side.cell, &old_side.targets, old_side.described},
                           {new_side.cell, &new_side.targets, new_side.described}, opt.machine == "old");
  }
  options.exit_code = PrintDiagnostics(diags, options);
  if (options.exit_code != kExitOk) return;
  // A LinuxCNC output's lines are the .ngc file's.
  if (old_side.linuxcnc) diff::RemapLines(result, /*new_side=*/false, old_side.linuxcnc->line_map);
  if (new_side.linuxcnc) diff::RemapLines(result, /*new_side=*/true, new_side.linuxcnc->line_map);
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
      "Compare two programs as the machine runs them (two outputs of `smtcal compile`, .place or LinuxCNC): every "
      "commanded position's move in µm, each program through its own cell, at the boards' nominal and extreme "
      "poses; added, removed and changed statements; exit 1 when the deployment gate fails");
  diff->add_option("OLD", opt.old_path,
                   "the program running now: a .place program ('-' for stdin) or a LinuxCNC output (its directory "
                   "or main .ngc)")
      ->required();
  diff->add_option("NEW", opt.new_path, "the program to deploy, of the same kind")->required();
  diff->add_option("--cell", opt.cell_path,
                   "the cell both programs were compiled for (a compiled program is checked against the files it "
                   "records); without it each compiled program is evaluated with the cell it records");
  diff->add_option("--old-cell", opt.old_cell_path, "the cell OLD was compiled for (when it is not NEW's)");
  diff->add_option("--new-cell", opt.new_cell_path, "the cell NEW was compiled for (when it is not OLD's)");
  AddNumberOption(*diff, "--threshold", opt.threshold_um, "the gate: a target that moved by more than this many µm fails it",
                  limits::kDiffThresholdUm)
      ->capture_default_str();
  diff->add_option("--machine", opt.machine,
                   "whose cell describes the machine both programs run on, the robot (its tables) and the boards "
                   "(their marker edges): new (the latest description of the real cell) or old; each program brings "
                   "its own cell's tables, marker geometry, estimator, scan paths and limits")
      ->check(CLI::IsMember({"new", "old"}))
      ->capture_default_str();
  diff->add_flag("--json", opt.json, "print the diff as JSON (schema in docs/diff.md) instead of text");
  diff->add_option("--svg", opt.svg_path,
                   "also draw the board to this SVG file: old positions, arrows to the new ones (enlarged, the scale "
                   "stated), added and removed targets");
  diff->add_flag("--exit-zero", opt.exit_zero,
                 "report only: exit 0 even when the gate fails (input and I/O errors still exit 1 and 3)");
  diff->footer(
      "The gate fails (exit 1) when a target moved on the machine by more than --threshold at any of the poses "
      "evaluated, a position cannot be compared, or a statement or declaration was added, removed or changed "
      "other than by its coordinates (docs/diff.md). Comments and formatting never count.");
  diff->callback([&options] { RunDiff(opt, options); });
}

}  // namespace smtcal::tools
