// Reports of `smtcal simulate` (docs/simulate.md): the text summary, the
// JSON report and the SVG picture of a virtual-cell run
// (simulation/virtual_cell.h). All three are deterministic: the same run gives
// the same bytes.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "calibration/cell.h"
#include "simulation/true_field.h"
#include "simulation/virtual_cell.h"

namespace smtcal {

// What the run was: for the reports' headers.
struct SimulateContext {
  std::string program;  // the program file as given
  const cell::Cell* cell = nullptr;
  const TruthSpec* truth = nullptr;
  // verify's findings the simulation measures instead of stopping for them:
  // Pick and Place targets over their budget or whose budget cannot be bounded.
  std::size_t verify_findings = 0;
};

// Per mode: placed parts, the fraction within tolerance, faults, the error
// distribution (mean, p50, p95, p99, max in µm), the scan's share; then the
// faults by check and what each mode means.
std::string SimulateReportText(const SimResult& result, const SimulateContext& context);
nlohmann::json SimulateReportJson(const SimResult& result, const SimulateContext& context);
// An error scatter per mode with the tolerance circle, and the histograms of
// the error lengths.
std::string SimulateReportSvg(const SimResult& result, const SimulateContext& context);

// One line on the true world the run assumed.
std::string DescribeTruth(const TruthSpec& truth, const cell::Cell& cell);

}  // namespace smtcal
