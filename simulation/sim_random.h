// The virtual cell's random numbers (simulation/virtual_cell.h): one
// std::mt19937_64 per run and our own transforms, because the standard
// library's distributions differ between implementations and the simulator
// promises the same report for the same seed on every platform.
//
// Uniform: the top 53 bits of one draw as a double in [0, 1). Normal:
// Box-Muller from two uniforms, one variate per call (no cached second one,
// so the stream position depends only on the number of calls).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace smtcal {

class SimRandom {
 public:
  explicit SimRandom(std::uint64_t seed) : engine_(seed) {}

  // [0, 1)
  double Uniform01() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  // [lo, hi)
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform01(); }
  // Standard normal.
  double Normal() {
    const double u1 = 1.0 - Uniform01();  // (0, 1]: log is finite
    const double u2 = Uniform01();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
  // True with probability p.
  bool Chance(double p) { return Uniform01() < p; }
  // 0 .. count - 1 (count > 0).
  std::size_t Index(std::size_t count) {
    const auto index = static_cast<std::size_t>(Uniform01() * static_cast<double>(count));
    return index < count ? index : count - 1;
  }
  // A new engine for a separate stream (the true field's perturbation), so
  // that changing one part of a run does not shift the draws of another.
  std::uint64_t Split() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace smtcal
