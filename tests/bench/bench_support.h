// Helpers shared by the benchmarks.
#pragma once

#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace smtcal::bench {

// Peak resident memory of the process (VmHWM) in MB: since the last
// ResetPeakRss(), or since the start. Falls back to getrusage's maximum when
// /proc is not there (that one cannot be reset: run one benchmark at a time).
inline double PeakRssMb() {
  if (std::FILE* status = std::fopen("/proc/self/status", "r")) {
    char line[256];
    long kib = -1;
    while (std::fgets(line, sizeof line, status) != nullptr) {
      if (std::strncmp(line, "VmHWM:", 6) == 0) kib = std::atol(line + 6);
    }
    std::fclose(status);
    if (kib >= 0) return static_cast<double>(kib) / 1024.0;
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// Starts a new peak: VmHWM drops to the current resident size (Linux >= 4.0,
// "5" to /proc/self/clear_refs), so a benchmark measures its own peak even
// after a larger one ran in the same process.
inline void ResetPeakRss() {
  if (std::FILE* refs = std::fopen("/proc/self/clear_refs", "w")) {
    std::fputs("5", refs);
    std::fclose(refs);
  }
}

}  // namespace smtcal::bench
