// The smtcal driver's subcommands. Each lives in its own tools/cmd_*.cpp and
// registers itself on the CLI11 app; the work itself is in the core library.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "base/diagnostics.h"
#include "base/result.h"

namespace smtcal::tools {

// Documented in README.md and `smtcal --help`.
enum ExitCode : int {
  kExitOk = 0,
  kExitInputError = 1,  // the input has errors (diagnostics were printed)
  kExitUsageError = 2,  // bad command line
  kExitIoError = 3,     // a file could not be read or written
};

struct GlobalOptions {
  std::string diagnostics_format = "text";  // text | json
  bool quiet = false;                       // -q: no success line
  int exit_code = kExitOk;
};

// The one line a command prints on stderr when it succeeded and wrote a file
// (or checked one): "smtcal: wrote layers.corrected.place (...)". Nothing
// with -q, or when `output` is standard output ("-": the output speaks for
// itself).
void SayDone(const GlobalOptions& options, const std::string& output, std::string_view what);
// "layers.place: no errors, 2 warnings": what a check that found no error says.
std::string NoErrorsText(std::string_view name, std::size_t warnings);

// Prints the diagnostics to stderr in the chosen format. Returns
// kExitInputError if any is an error, else kExitOk.
int PrintDiagnostics(const Diagnostics& diags, const GlobalOptions& options);
// Prints "smtcal: error: <message>" to stderr and returns kExitIoError.
int ReportIoError(const Error& error);

// True, after printing why, when the output file `output` (given with
// `option`, e.g. "-o") is one of `inputs` or a folder holding one: the
// command must then stop with kExitUsageError before reading anything.
bool OutputOverwritesInput(std::string_view option, const std::string& output,
                           const std::vector<std::string>& inputs);

void AddCheckCommand(CLI::App& app, GlobalOptions& options);
void AddFmtCommand(CLI::App& app, GlobalOptions& options);
void AddTableCommand(CLI::App& app, GlobalOptions& options);
void AddCompileCommand(CLI::App& app, GlobalOptions& options);  // compile and verify
void AddFixtureCommand(CLI::App& app, GlobalOptions& options);
void AddImportCommand(CLI::App& app, GlobalOptions& options);
void AddCellCommand(CLI::App& app, GlobalOptions& options);
void AddDiffCommand(CLI::App& app, GlobalOptions& options);
void AddSimulateCommand(CLI::App& app, GlobalOptions& options);
void AddSetupSheetCommand(CLI::App& app, GlobalOptions& options);

}  // namespace smtcal::tools
