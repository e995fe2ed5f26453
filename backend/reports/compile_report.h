// Reports of a compiled program: the JSON report of `smtcal compile --report`
// and `smtcal verify --json`, and the human summary of `smtcal verify`.
// Both read the compile state (passes/correction/compile_state.h); neither changes it.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/source.h"
#include "calibration/capability.h"
#include "ir/ir.h"
#include "passes/correction/compile_state.h"

namespace smtcal {

struct ReportCounts {
  int errors = 0;
  int warnings = 0;
  bool errors_cut = false;  // the error limit was reached: not every error is listed
};

// Every motion target (name, location, required and nominal position,
// correction kind, region, residual, budget), the fixtures, the taught points
// and the cycle-time estimates. Deterministic: targets in order first reached.
nlohmann::json CompileReportJson(const ir::Program& program, const CompileState& state, const SourceManager& sources,
                                 ReportCounts counts);

// The process figures verify predicts from the budget's model, per region
// (in order of first placement) and "overall": Place targets known at
// compile time with a bounded budget.
std::vector<std::pair<std::string, Capability>> PredictedCapability(const CompileState& state);

// "file:line:col" of a location in the program.
std::string LocationText(const SourceManager& sources, SourceLoc loc);

// The summary `smtcal verify` prints: counts by correction kind, the worst
// residual and budget with their locations, each cycle's time and the scan's
// share, and the verdict.
std::string VerifySummaryText(const ir::Program& program, const CompileState& state, const SourceManager& sources,
                              ReportCounts counts);

}  // namespace smtcal
