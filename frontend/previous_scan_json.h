// The previous cycle's scan for `smtcal fixture --previous`: the JSON that
// `smtcal fixture --json` writes (docs/periphery.md). Only its fixture name
// and its FIX matrix are read.
#pragma once

#include <cstdint>
#include <optional>

#include <Eigen/Geometry>

#include "base/diagnostics.h"
#include "calibration/cell.h"

namespace smtcal {

// FIX_{n-1} from the scan in `file`, which must be of `fixture` and have a
// planar pose. nullopt after reporting what is wrong with it (not JSON, with
// the line and column; a number beyond the range of a double; not a scan;
// another fixture; no pose).
std::optional<Eigen::Affine3d> ReadPreviousScan(std::uint32_t file, const cell::Fixture& fixture, Diagnostics& diags);

}  // namespace smtcal
