// smtcal: calibration compiler for SMT pick-and-place robot cells.
// The driver only wires subcommands together; see tools/cmd_*.cpp.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <system_error>

#include <fmt/core.h>

#include "tools/commands.h"

namespace smtcal::tools {

int PrintDiagnostics(const Diagnostics& diags, const GlobalOptions& options) {
  std::string text = options.diagnostics_format == "json" ? diags.RenderJson() : diags.RenderText();
  if (!text.empty()) {  // JSON always prints its array, even an empty one
    std::fwrite(text.data(), 1, text.size(), stderr);  // text may hold NUL bytes from the input
  }
  return diags.has_errors() ? kExitInputError : kExitOk;
}

void SayDone(const GlobalOptions& options, const std::string& output, std::string_view what) {
  if (options.quiet || output == "-") return;
  fmt::print(stderr, "smtcal: {}\n", what);
}

std::string NoErrorsText(std::string_view name, std::size_t warnings) {
  return fmt::format("{}: no errors, {}", name,
                     warnings == 0   ? std::string("no warnings")
                     : warnings == 1 ? std::string("1 warning")
                                     : fmt::format("{} warnings", warnings));
}

int ReportIoError(const Error& error) {
  fmt::print(stderr, "smtcal: error: {}\n", error.message);
  return kExitIoError;
}

namespace {

// The last word on an exception no command caught: a message and exit 3,
// never an abort. Plain stdio, because fmt::print throws when stderr fails.
int ReportEscapedException(const char* what) {
  std::fprintf(stderr, "smtcal: error: %s\n", what);
  return kExitIoError;
}

// Output to stdout is buffered: whether it all arrived is known only once it
// is flushed. A failure there is an I/O error like any other (exit 3).
int FinishStandardOutput(int exit_code) {
  errno = 0;
  // An I/O error already reported may be this one (WriteFileAtomically("-")).
  if ((std::fflush(stdout) == 0 && !std::ferror(stdout)) || exit_code == kExitIoError) return exit_code;
  std::fprintf(stderr, "smtcal: error: cannot write to standard output: %s\n",
               errno != 0 ? std::strerror(errno) : "write error");
  return kExitIoError;
}

// The command itself, with the usage errors CLI11 reports.
int Run(CLI::App& app, int argc, char** argv, const GlobalOptions& options) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsageError;
  }
  return options.exit_code;
}

}  // namespace
}  // namespace smtcal::tools

int main(int argc, char** argv) {
  using namespace smtcal::tools;
  CLI::App app{
      "smtcal - calibration compiler for SMT pick-and-place robot cells.\n"
      "Parses .place robot programs, checks them, and corrects them with the\n"
      "cell's error tables and fixture scans.\n\n"
      "Exit codes: 0 ok, 1 input errors (diagnostics were printed), 2 usage errors,\n"
      "3 I/O and resource errors (a file could not be read or written, standard\n"
      "output failed, out of memory, an input over 256 MiB, or an internal error).",
      "smtcal"};
  app.set_version_flag("--version", "smtcal " SMTCAL_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // --diagnostics may follow the subcommand
  GlobalOptions options;
  app.add_option("--diagnostics", options.diagnostics_format,
                 "How to print diagnostics: text (file:line:col, source line, caret) or json")
      ->check(CLI::IsMember({"text", "json"}))
      ->capture_default_str();
  app.add_flag("-q,--quiet", options.quiet,
               "No success line on stderr (what a command wrote or checked); diagnostics and errors are still "
               "printed");
  AddCheckCommand(app, options);
  AddFmtCommand(app, options);
  AddTableCommand(app, options);
  AddCompileCommand(app, options);
  AddFixtureCommand(app, options);
  AddImportCommand(app, options);
  AddCellCommand(app, options);
  AddDiffCommand(app, options);
  AddSimulateCommand(app, options);
  AddSetupSheetCommand(app, options);
  int exit_code = kExitOk;
  try {
    exit_code = Run(app, argc, argv, options);
  } catch (const std::bad_alloc&) {
    exit_code = ReportEscapedException("out of memory");
  } catch (const std::system_error& e) {  // a failed write through fmt or the file system library
    exit_code = ReportEscapedException(e.what());
  } catch (const std::exception& e) {
    std::string message = std::string("internal error: uncaught exception: ") + e.what();
    exit_code = ReportEscapedException(message.c_str());
  } catch (...) {
    exit_code = ReportEscapedException("internal error: uncaught exception of unknown type");
  }
  return FinishStandardOutput(exit_code);
}
