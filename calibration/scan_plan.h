// The marker scan as the controller drives it (docs/periphery.md, "The
// scan's time and capture range"): which board poses its paths can measure,
// and how long it takes.
//
// Capture range. A scan measures a board when every expected trip still
// happens where the runtime looks for it: each leg crosses its edge inside
// the edge's visible segment (not within the sensor's accuracy of an end,
// where it would see the marker's other side), within the leg and within
// the trip window, the trips of a leg in their order, and no leg crosses an
// edge segment it does not cross at the nominal pose (an extra change of the
// sensor). The board may be anywhere the fixture's checks accept: shifted
// (its origin S1) by up to max_shift_mm in any direction and turned about
// S1 by up to max_rotation_deg. The capture range is the largest factor k
// such that every pose within k x those limits is measured; k >= 1 means the
// paths take every board the checks accept. For a fixed turn the crossings
// are linear in the shift, so the worst shift is exact; the turn is sampled.
//
// Time. The runtime's moves (runtime/linuxcnc/smtcal_probe_trips.ngc): per
// path a jump to its start at the safe z and down to the scan z, then along
// each leg a probe move per trip (two stages: the search at scan_speed_mm_s,
// which stops past the edge, a probe move back over it and one forward at
// latch_speed_mm_s that latches it) and the rest of the leg (at the scan
// feed with one stage, a traverse with two), then up to the safe z. Moves are trapezoidal with the robot's x-y
// acceleration; a probe move stops past its trip by its stopping distance;
// every probe move also costs the controller's probe_turnaround_s (the
// interpreter waits for its result before it plans the next move). The
// board is taken at its nominal pose.
//
// Predicted search (predicted_window_mm > 0): every scan after a fixture's
// first knows where the last one found the board (its FIX); the runtime
// latches each trip where that pose puts it, from predicted_window_mm before
// the predicted crossing to as far past it, along the leg: per path a jump
// to above the first trip's window and a descent to the scan z, then per
// trip the latch at latch_speed_mm_s and a move straight to the next trip's
// window start at the traverse speed, then up. Every move at the scan z is
// a probe move (descent and moves between trips stop on an unexpected
// change of the sensor). A trip not in its window, or a change where none
// was expected, makes the runtime search that path in full (the fallback).
//
// The floor: what no scan of these paths can go below with this motion
// model: the jumps (up, across to the next path's first trip, down) and per
// trip one latch from rest that crosses the edge at the latch feed, with its
// turnaround. It leaves out the moves between a path's trips.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calibration/cell.h"

namespace smtcal {

// The largest capture factor searched for: paths that take boards four
// times as far off as the limits are plenty.
inline constexpr double kMaxCaptureFactor = 4;

struct CaptureRange {
  double factor = 0;        // k: every pose within k x the fixture's limits is measured (<= kMaxCaptureFactor)
  double shift_mm = 0;      // k x max_shift_mm
  double rotation_deg = 0;  // k x max_rotation_deg
  // What fails first just beyond k (empty when k reached kMaxCaptureFactor),
  // and the trip it concerns (0-based) or -1.
  std::string limited_by;
  int trip = -1;
  // When a leg crosses an edge besides its trips: the leg (0-based) of
  // scan_paths[leg_path] and the edge (index into edges); else -1.
  int leg_path = -1, leg = -1, edge = -1;
};

// The capture range of the fixture's scan paths as drawn. The fixture must
// be one the cell loader accepted.
CaptureRange ScanCaptureRange(const cell::Fixture& fixture);

// Whether the paths measure a board at this pose (shift of S1 in the base
// frame, turn about S1): the conditions above for one pose. `why` gets the
// first failure.
bool ScanMeasuresPose(const cell::Fixture& fixture, const Eigen::Vector2d& shift_mm, double turn_deg,
                      std::string* why = nullptr);

// A point of the robot in the base frame (x, y, z mm).
using ScanPoint = Eigen::Vector3d;

struct ScanTiming {
  double seconds = 0;        // from the first move to the end of the last rise
  double travel_s = 0;       // the jumps: to each path's start, down, and up at its end
  double search_s = 0;       // probe moves along the legs at the scan feed, and the rest of each leg
  double latch_s = 0;        // two stages: the moves back over each edge and the latching moves
  double turnaround_s = 0;   // probe_turnaround_s for every probe move
  int probe_moves = 0;
  ScanPoint end = ScanPoint::Zero();  // where the scan leaves the robot (the last path's end, at the safe z)
};

// How the runtime searches the trips of a scan.
enum class ScanSearch {
  kFull,       // along every leg from its start: a fixture's first scan, a fallback, no predicted_window_mm
  kPredicted,  // every trip in its predicted window (the steady state); kFull without predicted_window_mm
};

// The scan's moves and their time, from `from` (unknown: the first path's
// start is where the scan begins).
ScanTiming ScanTime(const cell::Robot& robot, const cell::Fixture& fixture, const std::optional<ScanPoint>& from,
                    ScanSearch search = ScanSearch::kFull);

// The scan's floor (above): travel_s the jumps, latch_s one latch per trip,
// turnaround_s one turnaround per trip, search_s 0.
ScanTiming ScanFloor(const cell::Robot& robot, const cell::Fixture& fixture, const std::optional<ScanPoint>& from);

}  // namespace smtcal
