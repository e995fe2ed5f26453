#include "tools/commands.h"

namespace smtcal::tools {

void AddFmtCommand(CLI::App& app, GlobalOptions& options) {
  CLI::App* fmt = app.add_subcommand("fmt", "Print a .place program in canonical form (not yet built)");
  fmt->callback([&options] { options.exit_code = kExitUsageError; });
}

}  // namespace smtcal::tools
