// The smtcal driver's subcommands. Each lives in its own tools/cmd_*.cpp and
// registers itself on the CLI11 app; the work itself is in the core library.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "base/number_range.h"
#include "base/result.h"
#include "calibration/cell.h"
#include "frontend/measurement_input.h"

// CLI11 is included only where options are defined (tools/cmd_*.cpp): its
// header costs every file that includes it about 5 s of the build.
namespace CLI {
class App;
class Option;
}  // namespace CLI

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

// What smtcal says on standard error goes through these (tools/main.cpp), so
// it is always valid UTF-8 (base/field_text.h, Printable) and, with
// --diagnostics=json, one JSON document: the diagnostics and every other
// message collected into the array main prints when the command ends
// (docs/files-and-exit-codes.md, "Diagnostics").

// The one line a command prints on stderr when it succeeded and wrote a file
// (or checked one): "smtcal: wrote layers.corrected.place (...)". Nothing
// with -q or --diagnostics=json, or when `output` is standard output ("-":
// the output speaks for itself).
void SayDone(const GlobalOptions& options, const std::string& output, std::string_view what);
// A command's summary of what it did (import's), several lines.
void SaySummary(const std::string& text);
// "layers.place: no errors, 2 warnings": what a check that found no error says.
std::string NoErrorsText(std::string_view name, std::size_t warnings);

// Prints the diagnostics to stderr in the chosen format. Returns
// kExitInputError if any is an error, else kExitOk.
int PrintDiagnostics(const Diagnostics& diags, const GlobalOptions& options);
// "smtcal: error: <message>"; each returns its exit code.
int ReportIoError(const Error& error);               // kExitIoError
int ReportUsageError(const std::string& message);    // kExitUsageError
int ReportInputError(const std::string& message);    // kExitInputError: a mistake no diagnostic locates

// The cell file at `path`, every table with it; or nullopt after printing
// the diagnostics and, when the file could not be read, the I/O error
// (options.exit_code set: kExitIoError, else kExitInputError).
std::optional<cell::Cell> LoadCellOrReport(const std::string& path, SourceManager& sources, Diagnostics& diags,
                                           GlobalOptions& options);

// The files a command reads and writes, by the option that names them, for
// CheckFiles: "-" is standard input (an input) or standard output (an
// output); an output's `folder` says it is a folder (--target linuxcnc).
struct NamedFile {
  std::string option;  // "-o", "--trips", "PROGRAM", "the report" (a command's standard output)
  std::string path;    // empty: not given
  bool folder = false;
};
// True, after printing why (a usage error), when the command must not run:
// standard input named for two inputs, standard output for two outputs, two
// outputs naming the same file (however spelled: ./x, a/../x, a symbolic
// link; or one inside the other's folder), or an output that is one of the
// inputs or a folder holding one. Called before anything is read.
bool FilesClash(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs);

// Numeric options (tools/number_options.cpp): the text must be one number in
// `range` (base/number_range.h), which --help states; nan, inf, -0, hex and
// an empty value are usage errors naming the option.
inline constexpr const char* kNumberOptionType = "NUMBER";
inline constexpr const char* kWholeOptionType = "INTEGER";
CLI::Option* AddNumberOption(CLI::App& command, const std::string& name, double& value, const std::string& help,
                             const NumberRange& range);
CLI::Option* AddNumberOption(CLI::App& command, const std::string& name, std::optional<double>& value,
                             const std::string& help, const NumberRange& range);
CLI::Option* AddNumberOption(CLI::App& command, const std::string& name, int& value, const std::string& help,
                             const NumberRange& range);
CLI::Option* AddNumberOption(CLI::App& command, const std::string& name, std::uint64_t& value,
                             const std::string& help, const NumberRange& range);

void AddCheckCommand(CLI::App& app, GlobalOptions& options);
void AddFmtCommand(CLI::App& app, GlobalOptions& options);
void AddTableCommand(CLI::App& app, GlobalOptions& options);
void AddCompileCommand(CLI::App& app, GlobalOptions& options);  // compile and verify
void AddFixtureCommand(CLI::App& app, GlobalOptions& options);
void AddImportCommand(CLI::App& app, GlobalOptions& options);
void AddCellCommand(CLI::App& app, GlobalOptions& options);
void AddDiffCommand(CLI::App& app, GlobalOptions& options);
void AddSimulateCommand(CLI::App& app, GlobalOptions& options);
// `smtcal measure plan|program|read` (cmd_measure*.cpp): the family, and each command.
void AddMeasureCommand(CLI::App& app, GlobalOptions& options);
void AddMeasurePlanCommand(CLI::App& measure, GlobalOptions& options);
void AddMeasureProgramCommand(CLI::App& measure, GlobalOptions& options);
void AddMeasureReadCommand(CLI::App& measure, GlobalOptions& options);
// The cell of a measurement: tables may be missing; it needs [measure] and
// robot.final_approach_mm. False (diagnostics printed, exit code set) when
// it cannot be used.
bool LoadCellForMeasure(const std::string& path, SourceManager& sources, Diagnostics& diags, GlobalOptions& options,
                        std::optional<cell::Cell>& cell);
// ... and the plan made for it (frontend/measurement_input.h); false, with
// the diagnostics printed and the exit code set, when either cannot be used.
bool LoadMeasurePlan(const std::string& plan_path, const std::string& cell_path, SourceManager& sources,
                     Diagnostics& diags, GlobalOptions& options, std::optional<cell::Cell>& cell,
                     std::optional<measure::LoadedPlan>& plan);
void AddSetupSheetCommand(CLI::App& app, GlobalOptions& options);
void AddScanCommand(CLI::App& app, GlobalOptions& options);
void AddMonitorCommand(CLI::App& app, GlobalOptions& options);

}  // namespace smtcal::tools
