// smtcal simulate: being written (see the open issue); registers nothing yet.
#include "tools/commands.h"

namespace smtcal::tools {

void AddSimulateCommand(CLI::App& /*app*/, GlobalOptions& /*options*/) {}

}  // namespace smtcal::tools
