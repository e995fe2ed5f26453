// The robust statistics the measurement's screens share (calibration/
// error_table_build.cpp, reading_screen.cpp, table_outliers.cpp): one
// median, one MAD-to-sigma factor, so the screens agree on what a centre
// and a scatter are.
#pragma once

#include <vector>

namespace smtcal {

// The median absolute deviation of a normal distribution times this is its
// standard deviation.
inline constexpr double kMadToSigma = 1.4826;

// The median of `values`: the middle value, the mean of the two middle
// ones for an even count. `values` must not be empty (checked).
double Median(std::vector<double> values);

}  // namespace smtcal
