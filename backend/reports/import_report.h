// The import report that `smtcal import --report FILE.json` writes beside
// the program: every row of the list and what became of it
// (docs/import.md). The set-up sheet it also writes is setup_sheet.h's.
#pragma once

#include <string>
#include <vector>

#include "frontend/cad/cad_to_program.h"

namespace smtcal {

// The import report as JSON: the summary's counts, every skip group with
// its designators, and one entry per row in list order.
std::string ImportReportJson(const ImportSummary& summary, const std::vector<RowFate>& fates,
                             const std::string& list_name);

}  // namespace smtcal
