// How a placement list writes its bottom side, decided once per import
// (docs/import.md, "Sides, mirroring and rotations"): the x of bottom-side
// parts as seen from the top, or negated as seen from the bottom.
//
// KiCad is the one tool whose lists differ by version: its .pos up to
// KiCad 6 and its CSV of KiCad 6 negate bottom x, KiCad 5's CSV does not,
// KiCad 7 and later do only when "negative X" was asked for, and only the
// .pos names the version. So for KiCad:
//   - a .pos naming KiCad 6 or older: negated (those versions had no choice);
//   - otherwise the list's own numbers decide when they can: every bottom
//     part at x < 0 while every top part (if any) is at x > 0 is a list
//     written with x negated (a board drawn in KiCad's page, or with its
//     origin at a corner, has all x of one sign seen from the top);
//   - else seen from the top, KiCad 7's default.
// Every other tool writes bottom x as seen from the top. The reason is kept
// so the summary can say what was applied and why; --bottom-positions
// overrides it.
#pragma once

#include <string>
#include <vector>

#include "frontend/cad/cad_reader.h"
#include "frontend/cad/cad_row.h"

namespace smtcal::cad {

struct BottomDecision {
  BottomPositions positions = BottomPositions::kTopView;
  std::string why;  // "KiCad 6.0.11 writes bottom x negated (line 2)", for the summary
};

// One part's x and side, as the list writes them.
struct SidedX {
  double x_mm = 0;
  Side side = Side::kTop;
};

BottomDecision DecideBottomPositions(const ListReader& reader, const std::vector<SidedX>& parts);

}  // namespace smtcal::cad
