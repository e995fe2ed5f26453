// smtcal fmt: print a .place program in canonical form (docs/language.md,
// "Canonical form"). Only parses; the semantic checks are `smtcal check`.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "backend/place/place_printer.h"
#include "frontend/parse.h"
#include "ir/ir_dump.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

struct FmtOptions {
  std::string path;
  std::string output;  // empty: stdout
  bool in_place = false;
  bool check = false;
};

int RunFmt(const FmtOptions& fmt_options, const GlobalOptions& options) {
  if (fmt_options.in_place && fmt_options.path == "-") {
    throw CLI::ValidationError("--in-place", "standard input cannot be rewritten in place; use -o OUT");
  }
  if (FilesClash({{"FILE", fmt_options.path}}, {{"-o", fmt_options.output}})) return kExitUsageError;
  SourceManager sources;
  Result<std::uint32_t> file = sources.Load(fmt_options.path);
  if (!file) return ReportIoError(file.error());
  Diagnostics diags(sources);
  ir::Program program = ParseProgram(file.value(), diags);
  // A file with syntax errors is never formatted: the IR holds only what
  // parsed, and printing it would silently drop the rest.
  int exit_code = PrintDiagnostics(diags, options);
  if (exit_code != kExitOk) return exit_code;

  std::string canonical = PrintPlace(program);
  // fmt may rewrite a file in place, so it proves on every run that the
  // canonical text means what the input meant before anything is written.
  Diagnostics reparse_diags(sources);
  ir::Program reparsed = ParseProgram(sources.Add("<fmt output>", canonical), reparse_diags);
  ApplyCanonicalChanges(program);
  SMTCAL_CHECK(!reparse_diags.has_errors() && DumpIr(reparsed) == DumpIr(program),
               "fmt's output does not parse back to the input's program; nothing was written");

  const SourceFile& source = sources.File(file.value());
  bool already_canonical = canonical == source.text;
  if (fmt_options.check) {
    if (already_canonical) return kExitOk;
    fmt::print("{}\n", source.name);
    return kExitInputError;
  }
  if (fmt_options.in_place) {
    // An unchanged file is left alone (its modification time too).
    if (already_canonical) {
      SayDone(options, fmt_options.path, fmt::format("{} is already in canonical form; left as it was", fmt_options.path));
      return kExitOk;
    }
    Status written = WriteFileAtomically(fmt_options.path, canonical);
    if (!written) return ReportIoError(written.error());
    SayDone(options, fmt_options.path, fmt::format("rewrote {} in canonical form", fmt_options.path));
    return kExitOk;
  }
  const std::string output = fmt_options.output.empty() ? "-" : fmt_options.output;
  Status written = WriteFileAtomically(output, canonical);
  if (!written) return ReportIoError(written.error());
  SayDone(options, output, fmt::format("wrote {}", output));
  return kExitOk;
}

}  // namespace

void AddFmtCommand(CLI::App& app, GlobalOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "fmt",
      "Print a .place program in canonical form (docs/language.md, \"Canonical form\").\n"
      "Comments and blank lines are kept; the program means exactly what it meant before.\n"
      "A file with syntax errors is not formatted.");
  static FmtOptions fmt_options;
  cmd->add_option("FILE", fmt_options.path, "the .place program ('-' for stdin)")->required();
  CLI::Option* output =
      cmd->add_option("-o,--output", fmt_options.output, "write the canonical form to OUT instead of stdout")
          ->type_name("OUT");
  CLI::Option* in_place =
      cmd->add_flag("--in-place", fmt_options.in_place, "rewrite FILE (only if it changes)");
  CLI::Option* check = cmd->add_flag(
      "--check", fmt_options.check,
      "write nothing; if FILE is not in canonical form print its name and exit with 1");
  output->excludes(in_place);
  check->excludes(output)->excludes(in_place);
  cmd->callback([&options] { options.exit_code = RunFmt(fmt_options, options); });
}

}  // namespace smtcal::tools
