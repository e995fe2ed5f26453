// The baseline file of `smtcal monitor` (docs/monitor.md, "Phase I and
// Phase II"): what `--baseline-out` writes and `--baseline-in` reads — per
// fixture the charts' references (centre, sigma, moving range, how many
// scans), the refusal counts of its window, the scans and records it came
// from, and the SHA-256 of the cell file and its tables it was taken with.
// JSON, every number with the digits that read back as the same double, so
// judging against a stored baseline gives what judging against the window
// it came from gives.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "base/diagnostics.h"
#include "calibration/cell.h"
#include "spc/cycle_monitor.h"

namespace smtcal {

inline constexpr int kBaselineFormat = 1;

std::string BaselineJsonText(const MonitorBaseline& baseline);

// The baseline in `file`, taken with `cell` (its cell file and tables the
// same bytes): nullopt after reporting what is wrong with it (not JSON,
// another format, a missing or impossible field, another cell).
std::optional<MonitorBaseline> ReadBaseline(std::uint32_t file, const cell::Cell& cell, Diagnostics& diags);

}  // namespace smtcal
