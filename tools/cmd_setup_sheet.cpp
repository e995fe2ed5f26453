// smtcal setup-sheet: the feeder set-up sheet of a program compiled for a
// cell — which part goes in which feeder, lane or tray pocket, and how many
// each cycle takes (backend/reports/setup_sheet.h; docs/compile.md). The
// program goes through the same passes as `smtcal compile`; a program that
// does not compile for the cell has no sheet.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "backend/reports/setup_sheet.h"
#include "calibration/limits.h"
#include "frontend/feeders_toml.h"
#include "passes/correction/compile_state.h"
#include "tools/commands.h"
#include "tools/feeders_option.h"
#include "tools/compile_or_report.h"

namespace smtcal::tools {
namespace {

struct SetupSheetOptions {
  std::string program_path;
  std::string cell_path;
  std::string feeders;
  std::string output;  // the text table; "-" standard output
  std::string csv;     // the CSV
  std::string svg;     // the printable page
  std::uint64_t boards = 0;     // the lot (0: none)
  double spares_percent = 2;    // spares per slot, a share of the lot's parts
};

void RunSetupSheet(const SetupSheetOptions& opt, GlobalOptions& options) {
  // Without -o, --csv and --svg the text goes to standard output.
  const std::string output =
      opt.output.empty() && opt.csv.empty() && opt.svg.empty() ? std::string("-") : opt.output;
  if (FilesClash({{"PROGRAM", opt.program_path}, {"--cell", opt.cell_path}, {"--feeders", opt.feeders}},
                 {{"-o", output}, {"--csv", opt.csv}, {"--svg", opt.svg}})) {
    options.exit_code = kExitUsageError;
    return;
  }
  SourceManager sources;
  Diagnostics diags(sources);
  CompiledProgram compiled;
  if (!CompileForCellOrReport(opt.program_path, opt.cell_path, false, sources, diags, compiled, options)) return;
  cad::FeedersFile feeders_file;
  if (!LoadFeedersOption(opt.feeders, sources, diags, feeders_file, options)) return;
  std::optional<cad::FeederTable> feeders =
      cad::FeederTable::Build(compiled.cell->feeders, std::move(feeders_file), diags);
  std::optional<SetupSheet> sheet;
  if (feeders && !diags.has_errors()) {
    sheet = ProgramSetupSheet(compiled.program, *compiled.program.compile, *feeders, diags);
    sheet->lot_boards = opt.boards;
    sheet->spares_percent = opt.spares_percent;
  }
  options.exit_code = PrintDiagnostics(diags, options);
  if (!sheet || options.exit_code != kExitOk) {
    options.exit_code = kExitInputError;  // nothing written
    return;
  }
  std::vector<std::pair<std::string, std::string>> outputs;
  if (!output.empty()) outputs.emplace_back(output, SetupSheetText(*sheet));
  if (!opt.csv.empty()) outputs.emplace_back(opt.csv, SetupSheetCsv(*sheet));
  if (!opt.svg.empty()) outputs.emplace_back(opt.svg, SetupSheetSvg(*sheet));
  if (Status written = WriteFilesAtomically(outputs); !written) {
    options.exit_code = ReportIoError(written.error());
    return;
  }
  std::size_t picks = 0;
  for (const SetupSlot& slot : sheet->slots) picks += slot.count;
  const std::string what = fmt::format("the feeder set-up sheet of {} ({} slot{}, {} pick{} per cycle)",
                                       sheet->program, sheet->slots.size(), sheet->slots.size() == 1 ? "" : "s",
                                       picks, picks == 1 ? "" : "s");
  const std::string& file = output != "-" && !output.empty() ? output : !opt.csv.empty() ? opt.csv : opt.svg;
  SayDone(options, file, fmt::format("wrote {}", what));
}

}  // namespace

void AddSetupSheetCommand(CLI::App& app, GlobalOptions& options) {
  static SetupSheetOptions opt;
  CLI::App* cmd = app.add_subcommand(
      "setup-sheet",
      "The feeder set-up sheet of a program compiled for a cell: which part goes in which feeder, lane or\n"
      "tray pocket, and how many picks each takes per cycle (docs/compile.md)");
  cmd->add_option("PROGRAM", opt.program_path, "the .place program")->required();
  cmd->add_option("--cell", opt.cell_path, "the cell file")->required();
  cmd->add_option("--feeders", opt.feeders,
                  "a feeders file (smtcal import's) whose feeders the program also picks from");
  cmd->add_option("-o,--output", opt.output,
                  "write the sheet as a text table ('-' for standard output; the default without --csv)");
  cmd->add_option("--csv", opt.csv, "write the sheet as CSV ('-' for standard output)");
  cmd->add_option("--svg", opt.svg, "write the sheet as a printable SVG page, a tick box per slot");
  AddNumberOption(*cmd, "--boards", opt.boards,
                  "the lot's boards (a board is one run of the Cycle): each slot's parts for the lot, and its spares",
                  limits::kLotBoards);
  AddNumberOption(*cmd, "--spares", opt.spares_percent,
                  "spares per slot with --boards, percent of the lot's parts, rounded up", limits::kSparesPercent)
      ->capture_default_str();
  cmd->footer(
      "The picks are those of the first run of each Cycle as the compile traces it (loops unrolled,\n"
      "calls followed, an If on an input taken as when the input is off); a lane reached only on the\n"
      "If's other branch is listed with count 0. A slot's value and package come from the program's\n"
      "comments (\"' R1 10k 0805\": designator, value, package, as smtcal import writes them), else\n"
      "the feeders file's [[lane]], else the feeder; its part number, tape and location from the feeders\n"
      "file. Exit codes: 0 ok, 1 errors in the program, the cell or the feeders file (nothing written),\n"
      "2 a bad command line, 3 a file could not be read or written.");
  cmd->callback([&options] { RunSetupSheet(opt, options); });
}

}  // namespace smtcal::tools
