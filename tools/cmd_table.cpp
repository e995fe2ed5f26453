#include "tools/commands.h"

namespace smtcal::tools {

void AddTableCommand(CLI::App& app, GlobalOptions& options) {
  CLI::App* table = app.add_subcommand("table", "Build, check and use error tables (not yet built)");
  table->callback([&options] { options.exit_code = kExitUsageError; });
}

}  // namespace smtcal::tools
