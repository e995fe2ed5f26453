// smtcal fixture (being written).
#include "tools/commands.h"

namespace smtcal::tools {

void AddFixtureCommand(CLI::App& /*app*/, GlobalOptions& /*options*/) {}

}  // namespace smtcal::tools
