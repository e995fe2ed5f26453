// The cell's lookups and names (calibration/cell.h).
#include "calibration/cell.h"

#include "base/field_text.h"

namespace smtcal::cell {
namespace {

bool SameName(std::string_view a, std::string_view b) { return AsciiLowercase(a) == AsciiLowercase(b); }

}  // namespace

const Fixture* Cell::FindFixture(std::string_view name) const {
  for (const Fixture& fixture : fixtures) {
    if (SameName(fixture.name, name)) return &fixture;
  }
  return nullptr;
}

const Region* Cell::FindRegion(std::string_view name) const {
  for (const Region& region : regions) {
    if (SameName(region.name, name)) return &region;
  }
  return nullptr;
}

const Feeder* Cell::FindFeeder(std::string_view name) const {
  for (const Feeder& feeder : feeders) {
    if (SameName(feeder.name, name)) return &feeder;
  }
  return nullptr;
}

const Region* Cell::RegionAt(const Point2& p) const {
  for (const Region& region : regions) {
    if (region.Contains(p)) return &region;
  }
  return nullptr;
}

std::optional<DeclaredRoughness> DeclaredRoughnessOf(const Robot& robot) {
  if (!robot.uncalibrated_accuracy_mm) return std::nullopt;
  return DeclaredRoughness{*robot.uncalibrated_accuracy_mm, robot.uncalibrated_correlation_mm};
}

InterpolationEstimate RegionInterpolation(const Robot& robot, const ErrorTable& table) {
  return EstimateInterpolationError(table, DeclaredRoughnessOf(robot), robot.repeatability_mm);
}

std::string_view EstimatorName(Estimator estimator) { return kEstimatorNames[static_cast<std::size_t>(estimator)]; }
std::string_view TaskAxisName(TaskAxis axis) { return kTaskAxisNames[static_cast<std::size_t>(axis)]; }
std::string_view OutsidePolicyName(OutsidePolicy policy) { return kOutsideNames[static_cast<std::size_t>(policy)]; }

}  // namespace smtcal::cell
