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

namespace {
constexpr std::string_view kCellFileMark = "cell file sha256 ";
constexpr std::string_view kTableFileMark = "table file sha256 ";
constexpr std::size_t kSha256HexDigits = 64;
}  // namespace

std::string CellFileLine(const CellFile& file) {
  return std::string(file.table ? kTableFileMark : kCellFileMark) + file.sha256 + " " + file.path;
}

std::optional<CellFile> ParseCellFileLine(std::string_view text) {
  CellFile file;
  if (text.starts_with(kTableFileMark)) {
    file.table = true;
    text.remove_prefix(kTableFileMark.size());
  } else if (text.starts_with(kCellFileMark)) {
    text.remove_prefix(kCellFileMark.size());
  } else {
    return std::nullopt;
  }
  if (text.size() < kSha256HexDigits + 2 || text[kSha256HexDigits] != ' ') return std::nullopt;
  for (char c : text.substr(0, kSha256HexDigits)) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return std::nullopt;
  }
  file.sha256 = std::string(text.substr(0, kSha256HexDigits));
  file.path = std::string(text.substr(kSha256HexDigits + 1));
  return file;
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

std::array<double, 4> PalletPickPoint(const std::array<double, 4>& first,
                                      const std::optional<std::array<double, 4>>& last,
                                      const std::optional<std::array<double, 4>>& back, int columns, int rows,
                                      int k) {
  if (!last) return first;
  const int i = (k - 1) % columns, j = (k - 1) / columns;  // column and row, from 0
  const double along = columns > 1 ? static_cast<double>(i) / (columns - 1) : 0.0;
  const double down = rows > 1 ? static_cast<double>(j) / (rows - 1) : 0.0;
  const std::array<double, 4>& toward = back ? *back : first;
  std::array<double, 4> point{};
  for (std::size_t a = 0; a < 4; ++a) {
    point[a] = first[a] + along * ((*last)[a] - first[a]) + down * (toward[a] - first[a]);
  }
  return point;
}

std::array<double, 4> Feeder::PickPoint(int k) const {
  return PalletPickPoint(pick, pallet_last, pallet_back, columns, rows, k);
}

}  // namespace smtcal::cell
