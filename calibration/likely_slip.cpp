// The simple slips of a measured value (calibration/likely_slip.h).
#include "calibration/likely_slip.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "calibration/tolerances.h"

namespace smtcal {

std::string LikelySlip::Describe() const {
  switch (kind) {
    case SlipKind::kNone: return "";
    case SlipKind::kDecimalPoint: return fmt::format("a decimal point moved ({:.6g} would fit)", fixed);
    case SlipKind::kMicrometres: return fmt::format("micrometres written as millimetres ({:.6g} would fit)", fixed);
    case SlipKind::kSign: return fmt::format("a lost or added minus sign ({:.6g} would fit)", fixed);
  }
  return "";
}

double SingleValueFitMm(double expected, double scatter_mm) {
  return std::max(kOutlierScatterFactor * scatter_mm, 0.25 * std::abs(expected));
}

LikelySlip FindLikelySlip(double value, double expected, double fit_mm, SlipsOf which) {
  std::vector<LikelySlip> candidates;
  for (int shift : {-3, -2, -1, 1, 2, 3}) {
    candidates.push_back({shift == -3 ? SlipKind::kMicrometres : SlipKind::kDecimalPoint,
                          value * std::pow(10.0, shift)});
  }
  if (which == SlipsOf::kOneValue) candidates.push_back({SlipKind::kSign, -value});
  LikelySlip best;
  for (const LikelySlip& c : candidates) {
    const double miss = std::abs(c.fixed - expected);
    if (miss > fit_mm) continue;
    if (best.kind == SlipKind::kNone || miss < std::abs(best.fixed - expected)) best = c;
  }
  return best;
}

}  // namespace smtcal
