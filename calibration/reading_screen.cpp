// Screening repeated readings at one position (calibration/reading_screen.h).
#include "calibration/reading_screen.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "base/check.h"
#include "calibration/sample_statistics.h"
#include "calibration/tolerances.h"

namespace smtcal {
namespace {

struct SetOfReadings {
  long long set = 0;
  std::vector<std::size_t> members;
  double centre = 0;   // median
  double scatter = 0;  // robust sigma of its readings about the centre
};

// The robust sigma of `values` about `centre`.
double RobustScatter(const std::vector<double>& values, double centre) {
  std::vector<double> distances;
  for (double v : values) distances.push_back(std::abs(v - centre));
  return kMadToSigma * Median(distances);
}

// A whole set far from the others, undone by a factor slip.
std::optional<SetSlip> FindSetSlip(const std::vector<SetOfReadings>& sets, double floor_scatter,
                                   std::optional<double> reference) {
  if (sets.size() < 2) return std::nullopt;
  // The scale: the quietest set's own scatter (a slipped set's is scaled by
  // its slip), never under the floor.
  double scatter = sets.front().scatter;
  for (const SetOfReadings& s : sets) scatter = std::min(scatter, s.scatter);
  scatter = std::max(scatter, floor_scatter);
  auto far_apart = [&](double a, double b) {
    const double d = std::abs(a - b);
    return d > kReadingOutlierFactor * scatter && d > kOutlierFloorMm;
  };
  auto fit = [&](const SetOfReadings& a, const SetOfReadings& b) {
    const double weight = std::sqrt(1.0 / static_cast<double>(a.members.size()) +
                                    1.0 / static_cast<double>(b.members.size()));
    return kSetShiftFactor * scatter * weight + kNoisyNodeFloorMm;
  };
  if (sets.size() >= 3) {
    // The majority decides: the set farthest from the median of the centres.
    std::vector<double> centres;
    for (const SetOfReadings& s : sets) centres.push_back(s.centre);
    const double middle = Median(centres);
    const SetOfReadings* worst = &sets.front();
    for (const SetOfReadings& s : sets) {
      if (std::abs(s.centre - middle) > std::abs(worst->centre - middle)) worst = &s;
    }
    const SetOfReadings* nearest = worst == &sets.front() ? &sets[1] : &sets.front();
    for (const SetOfReadings& s : sets) {
      if (&s != worst && std::abs(s.centre - middle) < std::abs(nearest->centre - middle)) nearest = &s;
    }
    if (!far_apart(worst->centre, middle)) return std::nullopt;
    const LikelySlip slip = FindLikelySlip(worst->centre, nearest->centre, fit(*worst, *nearest), SlipsOf::kWholeSet);
    if (slip.kind == SlipKind::kNone) return std::nullopt;
    return SetSlip{worst->set, nearest->set, worst->centre, nearest->centre, slip, true};
  }
  const SetOfReadings& a = sets[0];
  const SetOfReadings& b = sets[1];
  if (!far_apart(a.centre, b.centre)) return std::nullopt;
  const LikelySlip a_slip = FindLikelySlip(a.centre, b.centre, fit(a, b), SlipsOf::kWholeSet);
  const LikelySlip b_slip = FindLikelySlip(b.centre, a.centre, fit(a, b), SlipsOf::kWholeSet);
  // Micrometres written as millimetres make a set 1000 times larger: that
  // one is the culprit. A moved decimal point could be in either.
  if (a_slip.kind == SlipKind::kMicrometres) return SetSlip{a.set, b.set, a.centre, b.centre, a_slip, true};
  if (b_slip.kind == SlipKind::kMicrometres) return SetSlip{b.set, a.set, b.centre, a.centre, b_slip, true};
  if (a_slip.kind == SlipKind::kNone && b_slip.kind == SlipKind::kNone) return std::nullopt;
  // A moved decimal point: the surroundings decide, when they clearly do.
  const double a_off = reference ? std::abs(a.centre - *reference) : 0.0;
  const double b_off = reference ? std::abs(b.centre - *reference) : 0.0;
  const bool b_is_it = reference && b_off > kSetSlipDecisiveRatio * a_off && b_slip.kind != SlipKind::kNone;
  const bool a_is_it = reference && a_off > kSetSlipDecisiveRatio * b_off && a_slip.kind != SlipKind::kNone;
  if (b_is_it) return SetSlip{b.set, a.set, b.centre, a.centre, b_slip, true};
  if (a_is_it) return SetSlip{a.set, b.set, a.centre, b.centre, a_slip, true};
  // Undecided: `set` names the one farther from the reference (the one a
  // slip fits, without a reference), for the message.
  const bool b_farther = reference && b_off > a_off;
  if ((b_farther && b_slip.kind != SlipKind::kNone) || a_slip.kind == SlipKind::kNone) {
    return SetSlip{b.set, a.set, b.centre, a.centre, b_slip, false};
  }
  return SetSlip{a.set, b.set, a.centre, b.centre, a_slip, false};
}

}  // namespace

ReadingScreen ScreenReadings(const std::vector<double>& values, const std::vector<long long>& sets,
                             double typical_scatter_mm, std::optional<double> reference_mm) {
  SMTCAL_CHECK(values.size() == sets.size(), "one set per reading");
  ReadingScreen screen;
  if (values.size() < 3) return screen;
  const double floor_scatter = std::max(typical_scatter_mm, kNoisyNodeFloorMm);

  std::map<long long, std::vector<std::size_t>> by_set;
  for (std::size_t k = 0; k < values.size(); ++k) by_set[sets[k]].push_back(k);
  std::vector<SetOfReadings> big_sets;  // sets with a centre of their own
  for (const auto& [set, members] : by_set) {
    if (members.size() < kScreenMinSetSize) continue;
    SetOfReadings s{set, members, 0, 0};
    std::vector<double> v;
    for (std::size_t k : members) v.push_back(values[k]);
    s.centre = Median(v);
    s.scatter = RobustScatter(v, s.centre);
    big_sets.push_back(s);
  }
  screen.set_slip = FindSetSlip(big_sets, floor_scatter, reference_mm);

  // Each reading's centre: its set's median, or the median of the group's
  // readings outside slipped sets when its set is small.
  auto in_slipped_set = [&](std::size_t k) {
    if (!screen.set_slip) return false;
    return sets[k] == screen.set_slip->set || (!screen.set_slip->decided && sets[k] == screen.set_slip->other);
  };
  std::vector<double> unslipped;
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!in_slipped_set(k)) unslipped.push_back(values[k]);
  }
  if (unslipped.size() < 3) return screen;  // nothing left to judge a reading by
  const double group_centre = Median(unslipped);
  std::vector<double> centre(values.size(), group_centre);
  for (const SetOfReadings& s : big_sets) {
    for (std::size_t k : s.members) centre[k] = s.centre;
  }
  std::vector<double> distances;
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!in_slipped_set(k)) distances.push_back(std::abs(values[k] - centre[k]));
  }
  screen.scatter_mm = std::max(kMadToSigma * Median(distances), floor_scatter);
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (in_slipped_set(k)) continue;
    const double d = std::abs(values[k] - centre[k]);
    if (d <= kReadingOutlierFactor * screen.scatter_mm || d <= kOutlierFloorMm) continue;
    screen.outliers.push_back(
        {k, centre[k], FindLikelySlip(values[k], centre[k], SingleValueFitMm(centre[k], screen.scatter_mm))});
  }
  return screen;
}

}  // namespace smtcal
