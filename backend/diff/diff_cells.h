// Which cell a compiled program was compiled with (docs/diff.md, "Which
// cells"): `smtcal compile` records the cell file and every table file with
// their SHA-256 in the output's header (calibration/cell.h, CellFileLine),
// and `smtcal diff` evaluates each program only with a cell whose files are
// those — a table re-measured in place must never stand in for the one a
// program was compiled with.
#pragma once

#include <string>
#include <vector>

#include "calibration/cell.h"
#include "ir/ir.h"

namespace smtcal::diff {

// The files recorded in a compiled program's leading comments, cell file
// first; empty when it records none (not compiled, or by an older smtcal).
std::vector<cell::CellFile> RecordedCellFiles(const ir::Program& program);

// How `cell`'s files differ from `recorded`, one phrase each ("its table
// placing-table.csv has sha256 2c4f9a01b3d7..., the program was compiled
// with 8e01c4d2a9b0..."); empty when they are the same files.
std::vector<std::string> CellFileDifferences(const std::vector<cell::CellFile>& recorded, const cell::Cell& cell);

// The first 12 hex digits of a SHA-256, for reports ("2c4f9a01b3d7").
std::string ShortHash(const std::string& sha256);

}  // namespace smtcal::diff
