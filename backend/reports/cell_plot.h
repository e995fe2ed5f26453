// `smtcal cell plot`: the cell as a picture (docs/cell.md, "A picture of the
// cell"). One standalone SVG, robot base frame, y up, mm:
//   - the whole cell: the robot's travel, every calibrated region (its
//     bounds filled, its table's domain dashed), every fixture at its nominal
//     pose (the frame S1-S2-S3, the marker edges, the scan paths with their
//     nominal trips, the pocket boards go into), every feeder's pick points,
//     and, given a program, its placements;
//   - a close-up of each fixture with the trips numbered (T1, T2, ...) and
//     the placements named;
//   - a close-up of the feeders with every lane or pocket numbered
//     (Pallet(n, k)'s k).
// Each panel has axes in mm and a scale bar; one legend says what every mark
// is. Deterministic: the same cell and program give the same bytes.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "calibration/cell.h"

namespace smtcal {

// A motion target of a program, where it goes at the fixture's nominal pose.
struct PlottedTarget {
  std::string name;  // as written: "R1", "Pallet(1, 3)"
  double x_mm = 0, y_mm = 0;  // required position, robot base frame
  bool place = false;         // a Place (else a Pick or a move)
  int fixture = -1;           // index into cell.fixtures; -1: the robot base
};

// `title` names the cell file; `program` the program ("" without one).
std::string PlotCellSvg(const cell::Cell& cell, std::string_view title, std::string_view program,
                        const std::vector<PlottedTarget>& targets);

}  // namespace smtcal
