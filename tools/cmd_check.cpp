#include "frontend/parse.h"
#include "tools/commands.h"

namespace smtcal::tools {

void AddCheckCommand(CLI::App& app, GlobalOptions& options) {
  CLI::App* check = app.add_subcommand("check", "Parse a .place program and run the semantic checks");
  static std::string path;
  check->add_option("FILE", path, "the .place program ('-' for stdin)")->required();
  check->callback([&options] {
    SourceManager sources;
    Result<std::uint32_t> file = sources.Load(path);
    if (!file) {
      options.exit_code = ReportIoError(file.error());
      return;
    }
    Diagnostics diags(sources);
    ir::Program program = ParseProgram(file.value(), diags);
    options.exit_code = PrintDiagnostics(diags, options);
  });
}

}  // namespace smtcal::tools
