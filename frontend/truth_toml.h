// Reading the truth file of `smtcal simulate --truth` (docs/simulate.md):
// the true error field, the board's pose distribution, the sensor's and the
// robot's true accuracy. toml++ parses; every key is checked here and each
// mistake is reported at its own line and column; reading goes on so one run
// shows all of them.
#pragma once

#include <optional>
#include <string>

#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"
#include "calibration/cell.h"
#include "calibration/truth_spec.h"

namespace smtcal {

// The file failing to open is an Error; everything wrong inside it (a true
// table file included, located in that file or at its key) is a diagnostic,
// and then the value is nullopt. Region names refer to `cell`'s regions.
Result<std::optional<TruthSpec>> LoadTruth(const std::string& path, const cell::Cell& cell, SourceManager& sources,
                                           Diagnostics& diags);

}  // namespace smtcal
