// The previous scan's JSON (frontend/previous_scan_json.h).
#include "frontend/previous_scan_json.h"

#include <cmath>

#include <fmt/format.h>

#include "base/field_text.h"
#include "base/json_text.h"

namespace smtcal {

using nlohmann::ordered_json;

std::optional<Eigen::Affine3d> ReadPreviousScan(std::uint32_t file, const cell::Fixture& fixture, Diagnostics& diags) {
  const SourceManager& sources = diags.sources();
  const SourceRange whole(SourceLoc{file, 0, 0});
  JsonParse parsed = ParseJson(sources.File(file).text);
  if (!parsed.value) {
    diags.Report(DiagKind::PreviousScanInvalid, SourceRange(sources.File(file).LocationOf(file, parsed.error_offset)),
                 fmt::format("it is not valid JSON: {}", parsed.error));
    return std::nullopt;
  }
  ordered_json& json = *parsed.value;
  if (!json.is_object() || !json.contains("fixture") || !json["fixture"].is_string() || !json.contains("fix") ||
      !json.contains("checks")) {
    diags.Report(DiagKind::PreviousScanInvalid, whole, "it has no \"fixture\", \"fix\" and \"checks\"");
    return std::nullopt;
  }
  const std::string name = json["fixture"].get<std::string>();
  if (AsciiLowercase(name) != AsciiLowercase(fixture.name)) {
    diags.Report(DiagKind::PreviousScanOtherFixture, whole, Printable(name), fixture.name);
    return std::nullopt;
  }
  if (json["fix"].is_null()) {
    const std::string fault = json.contains("fault") && json["fault"].is_string() ? json["fault"].get<std::string>()
                                                                                    : std::string("?");
    diags.Report(DiagKind::PreviousScanNoPose, whole, Printable(fault));
    return std::nullopt;
  }
  const ordered_json& matrix = json["fix"].is_object() && json["fix"].contains("matrix") ? json["fix"]["matrix"]
                                                                                         : ordered_json();
  Eigen::Matrix4d m;
  bool ok = matrix.is_array() && matrix.size() == 4;
  for (std::size_t r = 0; ok && r < 4; ++r) {
    ok = matrix[r].is_array() && matrix[r].size() == 4;
    for (std::size_t c = 0; ok && c < 4; ++c) {
      ok = matrix[r][c].is_number() && std::isfinite(matrix[r][c].get<double>());
      if (ok) m(static_cast<long>(r), static_cast<long>(c)) = matrix[r][c].get<double>();
    }
  }
  if (!ok) {
    diags.Report(DiagKind::PreviousScanInvalid, whole, "\"fix\".\"matrix\" is not a 4 x 4 matrix of numbers");
    return std::nullopt;
  }
  Eigen::Matrix4d planar = Eigen::Matrix4d::Identity();
  planar.topLeftCorner<2, 2>() = m.topLeftCorner<2, 2>();
  planar.block<2, 1>(0, 3) = m.block<2, 1>(0, 3);
  const double det = m.topLeftCorner<2, 2>().determinant();
  if (m != planar || !(std::abs(det) > 0.5)) {
    diags.Report(DiagKind::PreviousScanInvalid, whole,
                 "\"fix\".\"matrix\" is not a planar FIX (rows 3 and 4 must be 0 0 1 0 and 0 0 0 1, the x-y part "
                 "a rotation)");
    return std::nullopt;
  }
  Eigen::Affine3d fix;
  fix.matrix() = m;
  return fix;
}

}  // namespace smtcal
