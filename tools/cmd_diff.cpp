// smtcal diff: being written (see the open issue); registers nothing yet.
#include "tools/commands.h"

namespace smtcal::tools {

void AddDiffCommand(CLI::App& /*app*/, GlobalOptions& /*options*/) {}

}  // namespace smtcal::tools
