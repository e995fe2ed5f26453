// smtcal check FILE: parse a .place program and run the semantic checks.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "frontend/parse.h"
#include "passes/pass_manager.h"
#include "tools/commands.h"

namespace smtcal::tools {

void AddCheckCommand(CLI::App& app, GlobalOptions& options) {
  CLI::App* check = app.add_subcommand("check", "Parse a .place program and run the semantic checks");
  static std::string path;
  static std::vector<std::string> passes;
  static bool verify_each = false;
  check->add_option("FILE", path, "the .place program ('-' for stdin)")->required();
  check->add_option("--passes", passes, "run only these passes, in this order (comma-separated)")
      ->delimiter(',')
      ->check(CLI::Validator(
          [](const std::string& name) -> std::string {
            Result<std::vector<const PassInfo*>> found = FindPasses({name});
            return found ? std::string() : found.error().message;
          },
          "PASS"));
  check->add_flag("--verify-each", verify_each,
                  "verify the IR after every pass and name the pass that broke it (for debugging smtcal)");
  check->footer("Passes, in pipeline order:\n" + DescribePasses());
  check->callback([&options] {
    SourceManager sources;
    Result<std::uint32_t> file = sources.Load(path);
    if (!file) {
      options.exit_code = ReportIoError(file.error());
      return;
    }
    Diagnostics diags(sources);
    ir::Program program = ParseProgram(file.value(), diags);
    // Semantic checks on a program that did not parse would report the
    // parser's gaps, not the user's mistakes.
    if (!diags.has_errors()) {
      Status ran = RunPasses(program, diags, passes, verify_each);
      if (!ran) {  // not expected: --passes was validated while parsing the command line
        options.exit_code = ReportUsageError(ran.error().message);
        return;
      }
    }
    options.exit_code = PrintDiagnostics(diags, options);
    if (options.exit_code == kExitOk) {
      SayDone(options, "", NoErrorsText(sources.File(file.value()).name, diags.warning_count()));
    }
  });
}

}  // namespace smtcal::tools
