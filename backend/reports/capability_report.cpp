// Process figures as JSON and text (backend/reports/capability_report.h).
#include "backend/reports/capability_report.h"

#include <cmath>

#include <fmt/format.h>

#include "base/field_text.h"

namespace smtcal {

nlohmann::json RoundedJson(double value, int decimals) {
  if (!std::isfinite(value)) return nullptr;
  return RoundedToDecimals(value, decimals);
}

namespace {

// One decimal, without "-0.0".
double Tenth(double value) {
  const double rounded = std::round(value * 10) / 10;
  return rounded == 0 ? 0.0 : rounded;
}

std::string CmkText(double cmk) { return std::isfinite(cmk) ? fmt::format("{:.2f}", cmk) : std::string("∞"); }

}  // namespace

nlohmann::json CapabilityJson(const Capability& c) {
  using nlohmann::json;
  return json{{"placements", c.placements},
              {"tolerance_mm", c.tolerance_mm},
              {"mean_um", json{{"x", RoundedJson(c.mean_mm.x() * 1000, 2)}, {"y", RoundedJson(c.mean_mm.y() * 1000, 2)}}},
              {"sigma_um", json{{"x", RoundedJson(c.sigma_mm.x() * 1000, 2)}, {"y", RoundedJson(c.sigma_mm.y() * 1000, 2)}}},
              {"cmk", json{{"x", RoundedJson(c.cmk.x(), 3)},
                           {"y", RoundedJson(c.cmk.y(), 3)},
                           {"worst", RoundedJson(c.WorstCmk(), 3)}}},
              {"ppm_outside_normal", RoundedJson(c.ppm_outside, 3)},
              {"reference", json{{"tolerance_um", kReferenceToleranceMm * 1000},
                                 {"cmk_required", kReferenceCmk},
                                 {"cmk", RoundedJson(c.reference_cmk, 3)},
                                 {"met", c.MeetsReference()}}}};
}

std::string CapabilityLine(std::string_view name, const Capability& c) {
  return fmt::format(
      "{}: {} placements, mean x {:+.1f} y {:+.1f} µm, σ x {:.1f} y {:.1f} µm, Cmk {} at ±{} µm, {:.3f} ppm outside "
      "(normal); reference ±{} µm at 4σ: Cmk {}, {}",
      name, c.placements, Tenth(c.mean_mm.x() * 1000), Tenth(c.mean_mm.y() * 1000), c.sigma_mm.x() * 1000,
      c.sigma_mm.y() * 1000,
      CmkText(c.WorstCmk()), fmt::format("{}", std::round(c.tolerance_mm * 1e4) / 10), c.ppm_outside,
      kReferenceToleranceMm * 1000, CmkText(c.reference_cmk), c.MeetsReference() ? "met" : "not met");
}

}  // namespace smtcal
