// smtcal: calibration compiler for SMT pick-and-place robot cells.
// The driver only wires subcommands together; see tools/cmd_*.cpp.
#include <cstdio>
#include <iostream>

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

int ReportIoError(const Error& error) {
  fmt::print(stderr, "smtcal: error: {}\n", error.message);
  return kExitIoError;
}

}  // namespace smtcal::tools

int main(int argc, char** argv) {
  using namespace smtcal::tools;
  CLI::App app{
      "smtcal - calibration compiler for SMT pick-and-place robot cells.\n"
      "Parses .place robot programs, checks them, and corrects them with the\n"
      "cell's error tables and fixture scans.\n\n"
      "Exit codes: 0 ok, 1 input errors, 2 usage errors, 3 I/O errors.",
      "smtcal"};
  app.set_version_flag("--version", "smtcal " SMTCAL_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // --diagnostics may follow the subcommand
  GlobalOptions options;
  app.add_option("--diagnostics", options.diagnostics_format,
                 "How to print diagnostics: text (file:line:col, source line, caret) or json")
      ->check(CLI::IsMember({"text", "json"}))
      ->capture_default_str();
  AddCheckCommand(app, options);
  AddFmtCommand(app, options);
  AddTableCommand(app, options);
  AddCompileCommand(app, options);
  AddFixtureCommand(app, options);
  AddImportCommand(app, options);
  AddCellCommand(app, options);
  AddDiffCommand(app, options);
  AddSimulateCommand(app, options);
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
