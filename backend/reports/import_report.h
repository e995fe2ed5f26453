// What `smtcal import` writes besides the program: the import report
// (--report FILE.json: every row of the list and what became of it) and the
// feeder set-up sheet (--setup-sheet FILE: which part goes in which feeder,
// lane or pocket), as text or CSV. docs/import.md describes both.
#pragma once

#include <string>
#include <vector>

#include "frontend/cad/cad_to_program.h"

namespace smtcal {

// The import report as JSON: the summary's counts, every skip group with
// its designators, and one entry per row in list order.
std::string ImportReportJson(const ImportSummary& summary, const std::vector<RowFate>& fates,
                             const std::string& list_name);

// The set-up sheet as a text table for the operator, and as CSV (one row per
// feeder slot: feeder, kind, slot, count, value, package, designators, pick
// point).
std::string SetupSheetText(const SetupSheet& sheet);
std::string SetupSheetCsv(const SetupSheet& sheet);

}  // namespace smtcal
