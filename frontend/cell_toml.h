// Loading a cell file (`*.cell.toml`, docs/cell.md) into a cell::Cell
// (calibration/cell.h).
#pragma once

#include <optional>
#include <string>

#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"
#include "calibration/cell.h"

namespace smtcal::cell {

// Loads and validates a cell file, its error tables included (paths relative
// to the cell file; read with ReadErrorTable, validated with
// ValidateErrorTable, their diagnostics located in the table files). The cell
// file failing to open is an Error; everything wrong inside it (or a table
// file that cannot be opened, located at its key) is a diagnostic, and then the
// value is nullopt. `sources` must be the SourceManager `diags` renders with.
Result<std::optional<Cell>> LoadCell(const std::string& path, SourceManager& sources, Diagnostics& diags);


}  // namespace smtcal::cell
