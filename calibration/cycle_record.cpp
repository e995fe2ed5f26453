// The record of a cycle's scan (calibration/cycle_record.h).
#include "calibration/cycle_record.h"

#include "calibration/fixture_geometry.h"

namespace smtcal {

std::optional<ScanCheck> CycleRecord::failed() const {
  if (status <= 0 || status > static_cast<int>(kScanChecks.size())) return std::nullopt;
  return static_cast<ScanCheck>(status);
}

CycleRecord RecordOfScan(int fixture, long cycle, std::optional<double> time_s, const ScanResult& scan) {
  CycleRecord record;
  record.fixture = fixture;
  record.cycle = cycle;
  record.time_s = time_s;
  if (const CheckResult* failure = scan.FirstFailure()) {
    record.status = static_cast<int>(failure->check);
    record.trip = failure->trip;
  }
  record.trips = scan.trips;
  for (const CheckResult& check : scan.checks) {
    if (check.evaluated) record.checks[static_cast<std::size_t>(check.check) - 1] = check.value;
  }
  if (scan.estimate) record.estimate = scan.estimate->s;
  return record;
}

std::string RecordName(std::string_view name) {
  if (name.empty()) return "-";
  std::string out;
  out.reserve(name.size());
  for (char c : name) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                       c == '-' || c == '.';
    out += plain ? c : '_';
  }
  return out;
}

Eigen::Affine3d FixOfEstimate(const std::array<Eigen::Vector2d, 3>& s, double l1_mm, double l2_mm) {
  Eigen::Affine3d fix = Eigen::Affine3d::Identity();
  fix.linear().topLeftCorner<2, 2>().col(0) = (s[1] - s[0]) / l1_mm;
  fix.linear().topLeftCorner<2, 2>().col(1) = (s[2] - s[0]) / l2_mm;
  fix.translation().head<2>() = s[0];
  return fix;
}

}  // namespace smtcal
