// Screening a group of repeated readings taken at one position before they
// are averaged (docs/error-tables.md, "Readings screened before they are
// averaged"). `table build` screens every node's repetitions this way; any
// other group of repeated readings at one position (a check point between
// the nodes) is screened the same way.
//
// The paper took two sets of ten readings per node and axis. A reading is
// judged against the robust centre of its own set (the median; of the whole
// group when its set has fewer than kScreenMinSetSize readings), so an
// ordinary shift between sets (the robot or the plate moved, warned by
// `table build` as a set shift) does not make readings look wrong; and the
// sets are judged against each other, so a whole set logged in the wrong
// unit is found although each of its readings agrees with its own set.
//
// The scale is the readings' robust scatter: 1.4826 x the median distance of
// a reading from its centre, but never less than the scatter typical of the
// group's kind (for a node, the median repetition scatter of its axis) nor
// kNoisyNodeFloorMm (the transducers' resolution). A reading is an outlier
// when it lies more than kReadingOutlierFactor scatters and kOutlierFloorMm
// from its centre. A set is slipped when its centre lies that far from the
// other sets' and a decimal-point or unit slip of the whole set undoes it
// within kSetShiftFactor standard errors of a set difference (plus the
// resolution): a lost sign is a slip of one reading, not of ten.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "calibration/likely_slip.h"

namespace smtcal {

struct ReadingOutlier {
  std::size_t index = 0;  // into the group
  double centre_mm = 0;   // the median it was judged against
  LikelySlip slip;        // against that centre
};

struct SetSlip {
  long long set = 0;          // the slipped set: the culprit when `decided`
  long long other = 0;        // the set it disagrees with
  double set_centre_mm = 0;   // their medians
  double other_centre_mm = 0;
  LikelySlip slip;            // `set`'s centre undone towards `other`'s
  // With three or more sets the one far from the others is the culprit;
  // with two, a unit slip (micrometres written as millimetres) has a
  // direction; otherwise the set far from the reference (what the
  // surroundings predict) is, when the other is at least
  // kSetSlipDecisiveRatio times nearer to it. Else the group cannot tell.
  bool decided = false;
};

struct ReadingScreen {
  double scatter_mm = 0;                 // the scale the readings were judged by
  std::vector<ReadingOutlier> outliers;  // single readings, in group order
  std::optional<SetSlip> set_slip;       // a whole set (its readings are not in `outliers`)
};

// `values[k]` belongs to set `sets[k]`; `typical_scatter_mm` is the scatter
// usual for such a group (0 when unknown); `reference_mm` what the
// surroundings predict at the group's position, when known (for a node, the
// mean of its neighbouring nodes' centres). Groups of fewer than 3 readings
// have no robust centre and pass unjudged.
ReadingScreen ScreenReadings(const std::vector<double>& values, const std::vector<long long>& sets,
                             double typical_scatter_mm, std::optional<double> reference_mm = std::nullopt);

}  // namespace smtcal
