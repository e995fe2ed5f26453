// The simple slips a measured value suffers on its way into a file: a decimal
// point moved (x10^+-1, +-2, +-3; x10^-3 is micrometres written as
// millimetres), a lost or added minus sign. Shared by the table's node
// outlier search (calibration/table_outliers.h) and the screening of raw
// readings (calibration/reading_screen.h), so both name a slip the same way.
#pragma once

#include <string>

namespace smtcal {

enum class SlipKind { kNone, kDecimalPoint, kMicrometres, kSign };

struct LikelySlip {
  SlipKind kind = SlipKind::kNone;
  double fixed = 0;  // the value with the slip undone
  // "a decimal point moved (-0.07711 would fit)"; empty for kNone.
  std::string Describe() const;
};

// Which slips to consider: a lost sign hits one value; a whole set of
// readings slips only by a factor (a logger writing the wrong unit).
enum class SlipsOf { kOneValue, kWholeSet };

// The slip that best turns `value` back into `expected`, when the undone
// value lands within `fit_mm` of it; kNone when no simple slip does.
LikelySlip FindLikelySlip(double value, double expected, double fit_mm, SlipsOf which = SlipsOf::kOneValue);
// The fit a single value is held to: the larger of kOutlierScatterFactor x
// the scatter it is judged by and a quarter of |expected|.
double SingleValueFitMm(double expected, double scatter_mm);

}  // namespace smtcal
