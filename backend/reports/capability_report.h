// Process figures (calibration/capability.h) as JSON and as a text line, for
// the reports of verify and simulate.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "calibration/capability.h"

namespace smtcal {

// {"placements", "tolerance_mm", "mean_um": {x, y}, "sigma_um": {x, y},
//  "cmk": {x, y, "worst"}, "ppm_outside_normal", "reference": {...}}; numbers
// rounded to what they mean (0.01 µm, 0.001 for Cmk and ppm).
nlohmann::json CapabilityJson(const Capability& capability);

// "layer1: 40 placements, mean x +1.2 y -0.4 µm, σ x 8.1 y 9.0 µm, Cmk 3.66 at ±100 µm,
// 0.000 ppm outside (normal); reference ±50 µm at 4σ: Cmk 1.80, met"
std::string CapabilityLine(std::string_view name, const Capability& capability);

// A finite number rounded to `decimals` decimals (RoundedToDecimals);
// infinity as null.
nlohmann::json RoundedJson(double value, int decimals);

}  // namespace smtcal
