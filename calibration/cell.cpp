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

std::string_view EstimatorName(Estimator estimator) { return kEstimatorNames[static_cast<std::size_t>(estimator)]; }
std::string_view TaskAxisName(TaskAxis axis) { return kTaskAxisNames[static_cast<std::size_t>(axis)]; }
std::string_view OutsidePolicyName(OutsidePolicy policy) { return kOutsideNames[static_cast<std::size_t>(policy)]; }

}  // namespace smtcal::cell
