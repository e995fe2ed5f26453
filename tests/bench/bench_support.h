// Helpers shared by the benchmarks.
#pragma once

#include <sys/resource.h>

namespace smtcal::bench {

// Peak resident memory of the whole process so far, in MB. Run one benchmark
// at a time (--benchmark_filter) for a figure that belongs to it alone.
inline double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace smtcal::bench
