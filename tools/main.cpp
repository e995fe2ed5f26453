// smtcal: calibration compiler for SMT pick-and-place robot cells.
// The driver only wires subcommands together; see tools/cmd_*.cpp. It also
// owns standard error: every message goes through the functions below
// (tools/commands.h), so stderr is valid UTF-8 and, with --diagnostics=json,
// exactly one JSON document.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <system_error>

#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <CLI/CLI.hpp>

#include "base/check.h"
#include "base/field_text.h"
#include "frontend/cell_toml.h"
#include "tools/commands.h"

namespace smtcal::tools {
namespace {

using nlohmann::ordered_json;

// What goes to standard error. In text each message is printed at once; in
// JSON (--diagnostics=json) the diagnostics and the other messages are kept
// in one array, printed once when the command ends (or when an internal
// error ends it).
struct Stderr {
  bool json = false;
  ordered_json entries = ordered_json::array();
};
Stderr g_stderr;

// Plain stdio, which never throws (fmt::print throws when stderr fails).
void Write(const std::string& text) { std::fwrite(text.data(), 1, text.size(), stderr); }

// A message that is no diagnostic, as a JSON entry shaped like one (kind,
// severity, an empty location, message, notes).
void AddEntry(std::string_view kind, std::string_view severity, const std::string& message) {
  ordered_json entry;
  entry["kind"] = kind;
  entry["severity"] = severity;
  entry["file"] = "";
  entry["line"] = 0;
  entry["column"] = 0;
  entry["length"] = 0;
  entry["message"] = Printable(message, TextQuoting::kMessage);
  entry["notes"] = ordered_json::array();
  g_stderr.entries.push_back(std::move(entry));
}

// "smtcal: error: ..." in text; an entry of `kind` in JSON.
void Say(std::string_view kind, std::string_view severity, const std::string& message) {
  if (g_stderr.json) {
    AddEntry(kind, severity, message);
    return;
  }
  Write(Printable(severity == "error" ? "smtcal: error: " + message : message, TextQuoting::kMessage) + "\n");
}

// The one JSON document of --diagnostics=json.
void PrintJsonDocument() {
  if (!g_stderr.json) return;
  Write(g_stderr.entries.dump(2, ' ', false, ordered_json::error_handler_t::replace) + "\n");
  g_stderr.entries = ordered_json::array();
}

void ReportInternalError(const std::string& message) {
  if (g_stderr.json) {
    AddEntry("InternalError", "error", message);
    PrintJsonDocument();
  } else {
    Write(Printable("smtcal: error: " + message, TextQuoting::kMessage) + "\n");
  }
}

}  // namespace

int PrintDiagnostics(const Diagnostics& diags, const GlobalOptions& options) {
  (void)options;  // the format is g_stderr's, from the command line
  if (g_stderr.json) {
    for (ordered_json& entry : ordered_json::parse(diags.RenderJson())) g_stderr.entries.push_back(std::move(entry));
  } else {
    Write(diags.RenderText());  // valid UTF-8 already (base/diagnostics.h)
  }
  return diags.has_errors() ? kExitInputError : kExitOk;
}

void SayDone(const GlobalOptions& options, const std::string& output, std::string_view what) {
  if (options.quiet || g_stderr.json || output == "-") return;
  Say("Done", "note", fmt::format("smtcal: {}", what));
}

void SaySummary(const std::string& text) {
  std::string trimmed = text;
  while (!trimmed.empty() && trimmed.back() == '\n') trimmed.pop_back();
  Say("Summary", "note", trimmed);
}

std::string NoErrorsText(std::string_view name, std::size_t warnings) {
  return fmt::format("{}: no errors, {}", name,
                     warnings == 0   ? std::string("no warnings")
                     : warnings == 1 ? std::string("1 warning")
                                     : fmt::format("{} warnings", warnings));
}

int ReportIoError(const Error& error) {
  Say("IoError", "error", error.message);
  return kExitIoError;
}

std::optional<cell::Cell> LoadCellOrReport(const std::string& path, SourceManager& sources, Diagnostics& diags,
                                           GlobalOptions& options) {
  Result<std::optional<cell::Cell>> loaded = cell::LoadCell(path, sources, diags);
  if (!loaded) {
    PrintDiagnostics(diags, options);
    options.exit_code = ReportIoError(loaded.error());
    return std::nullopt;
  }
  if (!loaded.value()) {
    options.exit_code = PrintDiagnostics(diags, options);
    return std::nullopt;
  }
  return std::move(loaded).value();
}

int ReportUsageError(const std::string& message) {
  Say("UsageError", "error", message);
  return kExitUsageError;
}

int ReportInputError(const std::string& message) {
  Say("InputError", "error", message);
  return kExitInputError;
}

namespace {

// The last word on an exception no command caught: a message and exit 3,
// never an abort.
int ReportEscapedException(const char* what) {
  try {
    return ReportIoError(Error{what});
  } catch (...) {  // out of memory again: plain stdio
    std::fprintf(stderr, "smtcal: error: %s\n", what);
    return kExitIoError;
  }
}

// Output to stdout is buffered: whether it all arrived is known only once it
// is flushed. A failure there is an I/O error like any other (exit 3).
int FinishStandardOutput(int exit_code) {
  errno = 0;
  // An I/O error already reported may be this one (WriteFileAtomically("-")).
  if ((std::fflush(stdout) == 0 && !std::ferror(stdout)) || exit_code == kExitIoError) return exit_code;
  return ReportIoError(Error{fmt::format("cannot write to standard output: {}",
                                         errno != 0 ? std::strerror(errno) : "write error")});
}

// What the command line says before CLI11 reads it: the diagnostics format
// (so a usage error is JSON too), and an option given as "--name=" with
// nothing after it, which CLI11 would read as no value at all and fill
// with the next argument.
int Prescan(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--") break;
    if (arg == "--diagnostics=json" || (arg == "--diagnostics" && i + 1 < argc && std::string_view(argv[i + 1]) == "json")) {
      g_stderr.json = true;
    }
  }
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--") break;
    if (arg.starts_with("--") && arg.size() > 3 && arg.ends_with("=") && arg.find('=') == arg.size() - 1) {
      return ReportUsageError(fmt::format("{} gives no value; write {}VALUE or {} VALUE", arg, arg,
                                          arg.substr(0, arg.size() - 1)));
    }
  }
  return kExitOk;
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
    std::string message = CLI::FailureMessage::simple(&app, e);
    while (!message.empty() && message.back() == '\n') message.pop_back();
    return ReportUsageError(message);
  }
  return options.exit_code;
}

}  // namespace
}  // namespace smtcal::tools

int main(int argc, char** argv) {
  using namespace smtcal::tools;
  smtcal::SetInternalErrorReporter(ReportInternalError);
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
                 "How to print diagnostics: text (file:line:col, source line, caret) or json (one JSON array on "
                 "stderr holding every diagnostic and message; no success line)")
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
  AddScanCommand(app, options);
  AddMeasureCommand(app, options);
  AddSetupSheetCommand(app, options);
  AddMonitorCommand(app, options);
  int exit_code = Prescan(argc, argv);
  try {
    if (exit_code == kExitOk) exit_code = Run(app, argc, argv, options);
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
  exit_code = FinishStandardOutput(exit_code);
  PrintJsonDocument();
  return exit_code;
}
