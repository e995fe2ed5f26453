// The record of one cycle's marker scan, as the runtimes keep it (the
// LinuxCNC runtime writes it to a log, the C runtime hands it to its caller,
// `smtcal simulate --record` writes it for a virtual cell): the trips the
// sensor made, the pose the estimator found, every check's value and the
// verdict. The text format is docs/monitor.md; frontend/cycle_record.h reads
// it back, runtime/c/smtcal_record.h writes it.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "calibration/fixture_estimation.h"

namespace smtcal {

// The format version a begin line states (runtime/c's SMTCAL_RECORD_FORMAT).
// 2: the LinuxCNC runtime writes lengths and angles in millionths followed by
// e-6, since LinuxCNC prints a number below 1e-4 as 0; the logs of format 1
// hold such values as 0 and are refused (docs/monitor.md).
inline constexpr int kRecordFormat = 2;

struct CycleRecord {
  int fixture = 0;   // index into the begin line's fixtures
  long cycle = 0;    // 1, 2, ... scans of this fixture since the begin line
  std::optional<double> time_s;  // the controller's clock; none without one
  int status = 0;    // 0 accepted, else the code of the first failed check (ScanCheck)
  int trip = -1;     // the trip that failure concerns (0-based), or -1
  std::vector<std::optional<Eigen::Vector2d>> trips;  // as commanded when the sensor tripped; nullopt: not made
  std::array<std::optional<double>, kScanChecks.size()> checks{};  // per check (code - 1): its value when it ran
  std::optional<std::array<Eigen::Vector2d, 3>> estimate;  // S1, S2, S3 of the estimator's pose, base frame

  bool accepted() const { return status == 0; }
  // The check that refused the scan, or nullopt.
  std::optional<ScanCheck> failed() const;
};

// The record of a scan (ScanFixture) of fixture number `fixture` in its
// cycle `cycle`.
CycleRecord RecordOfScan(int fixture, long cycle, std::optional<double> time_s, const ScanResult& scan);

// The line that opens a log, or a part of one.
struct RecordFixture {
  std::string name;
  std::size_t trips = 0;
};
struct RecordBegin {
  int version = kRecordFormat;
  std::string cell;
  std::vector<RecordFixture> fixtures;
  std::string clock;  // "none" without a clock
  long segment = 0;   // the writer's count of log files
};

// A name as records write it: letters, digits, '_', '-' and '.' kept,
// anything else '_' (the LinuxCNC runtime can print no other); "-" for "".
std::string RecordName(std::string_view name);

// The board's pose a record's estimate gives: FIX from S1..S3 (p = S1,
// n = (S2 - S1) / L1, o = (S3 - S1) / L2), as the runtime's FIX.
Eigen::Affine3d FixOfEstimate(const std::array<Eigen::Vector2d, 3>& s, double l1_mm, double l2_mm);

}  // namespace smtcal
