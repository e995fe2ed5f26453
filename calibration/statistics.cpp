// The robust statistics the measurement's screens share (calibration/statistics.h).
#include "calibration/statistics.h"

#include <algorithm>

#include "base/check.h"

namespace smtcal {

double Median(std::vector<double> values) {
  SMTCAL_CHECK(!values.empty(), "median of nothing");
  std::sort(values.begin(), values.end());
  const std::size_t mid = values.size() / 2;
  return values.size() % 2 == 1 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
}

}  // namespace smtcal
