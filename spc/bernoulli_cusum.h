// The refusals' control chart: a Bernoulli CUSUM (Reynolds and Stoumbos,
// "A CUSUM Chart for Monitoring a Proportion When Inspecting Continuously",
// J. Quality Technology 31 (1999)). Every scan is an event (refused) or
// not; the chart sums the log-likelihood ratio of a rate p1 against the
// in-control rate p0, scaled so that a scan without the event counts -1
// and a refused one +up (a whole number: the chart's states are whole, so
// its run lengths are computed exactly, by a Markov chain on them), and
// alarms when the sum reaches its limit H.
//
// Designed from the in-control rate with a floor: a clean baseline (no
// refusal in 50 scans) does not mean a rate of zero, and a chart designed
// for a rate of zero would alarm at the first refusal. The floor is the
// rate the design card accepts, 1 % of good scans refused; the chart then
// catches a rise to three times the rate.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace smtcal {

// The rate a chart is designed for at least (DESIGN: at most 1 % of good
// scans refused), the rise it is designed to catch, and its in-control
// run length (of the order of the pose charts', docs/monitor.md).
inline constexpr double kRefusalRateFloor = 0.01;
inline constexpr double kRefusalRise = 3;
inline constexpr double kRefusalInControlArl = 50'000;

struct BernoulliCusumDesign {
  double p0 = 0;  // the in-control rate
  double p1 = 0;  // the rate it is designed to catch (kRefusalRise p0, at most (1 + p0) / 2)
  int up = 1;     // what a refused scan adds (a scan without a refusal: -1)
  int limit = 1;  // H: the chart alarms when its sum reaches H
  double arl0 = 0;  // the average scans to an alarm at p0 (exact)
  double arl1 = 0;  // ... at p1 (exact)
};

// The design for an in-control rate p0 (0 < p0 < 1; the caller applies the
// floor): up = ln(p1 / p0) / -ln((1 - p1) / (1 - p0)) rounded, and the
// smallest H whose in-control run length is at least `in_control_arl`.
BernoulliCusumDesign DesignBernoulliCusum(double p0, double rise = kRefusalRise,
                                          double in_control_arl = kRefusalInControlArl);

// The average run length from a sum of 0 when each scan is refused with
// probability p, exactly (the chain's linear equations, banded).
double BernoulliCusumArl(int up, int limit, double p);

struct BernoulliCusumRun {
  std::vector<int> sum;                // after each scan
  std::optional<std::size_t> alarm;    // the first scan (index) at which the sum reached the limit
  std::size_t change_point = 0;        // the scan after the last one before the alarm at which the sum was 0
};
BernoulliCusumRun RunBernoulliCusum(const std::vector<bool>& events, const BernoulliCusumDesign& design);

}  // namespace smtcal
