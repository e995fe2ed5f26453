// How long a move takes at the cell's speeds: the motion model of the cycle
// time (verify) and of the measurement plan's time (measure plan).
#pragma once

#include <cmath>

namespace smtcal {

// Time to move `distance` along one axis with a trapezoidal profile
// (accelerate, cruise, decelerate; triangular when the move is too short to
// reach `speed`). 0 for no move or a motion model that is not set.
inline double MoveTime(double distance, double speed, double accel) {
  distance = std::abs(distance);
  if (distance == 0 || speed <= 0 || accel <= 0) return 0;
  if (distance < speed * speed / accel) return 2 * std::sqrt(distance / accel);
  return distance / speed + speed / accel;
}

}  // namespace smtcal
