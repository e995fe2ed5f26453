// The cells the harnesses compile, scan and import with, loaded once.
#pragma once

#include "calibration/cell.h"

namespace smtcal::fuzz {

const cell::Cell& ExampleCell();  // examples/paper-cell/paper.cell.toml
const cell::Cell& ImportCell();   // tests/golden/import-data/cell.toml

}  // namespace smtcal::fuzz
