// Reading trip files (see trips_csv.h). The CSV is split by SplitCsv; each
// mistake is reported at its row and field with the generic Csv* kinds or the
// trip kinds, and reading goes on so one run reports all of them.
#include "frontend/trips_csv.h"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "base/field_text.h"
#include "calibration/tolerances.h"
#include "frontend/input_kind.h"
#include "frontend/table_csv.h"

namespace smtcal {
namespace {

enum Column { kName, kX, kY, kZ, kColumnCount };
constexpr std::array<std::string_view, kColumnCount> kColumns = {"name", "x_mm", "y_mm", "z_mm"};
constexpr std::size_t kRequired = 3;  // name, x_mm, y_mm
constexpr std::string_view kWhat = "a trip file";
constexpr std::string_view kAllColumns = "name, x_mm, y_mm, z_mm";
constexpr std::string_view kHeaderExample = "name,x_mm,y_mm,z_mm";



std::string NumberHint(std::string_view text) {
  if (text.find(',') != std::string_view::npos) return " (write the decimal point as '.')";
  const std::string lower = AsciiLowercase(text);
  if (lower.size() > 2 && (lower.ends_with("mm") || lower.ends_with("um"))) {
    return " (write the number without its unit)";
  }
  return "";
}

// The trip index of a name "T<k>" with 1 <= k <= count, else nullopt.
std::optional<std::size_t> TripIndex(std::string_view name, std::size_t count) {
  if (name.size() < 2 || (name[0] != 'T' && name[0] != 't')) return std::nullopt;
  std::size_t k = 0;
  auto [end, ec] = std::from_chars(name.data() + 1, name.data() + name.size(), k);
  if (ec != std::errc() || end != name.data() + name.size() || name[1] == '0' || k < 1 || k > count) {
    return std::nullopt;
  }
  return k - 1;
}

using Header = std::array<std::optional<std::size_t>, kColumnCount>;  // field index per column

std::optional<Header> ReadHeader(const CsvRecord& record, Diagnostics& diags) {
  Header header;
  bool ok = true;
  const std::vector<std::string> known(kColumns.begin(), kColumns.end());
  for (std::size_t f = 0; f < record.fields.size(); ++f) {
    const CsvField& field = record.fields[f];
    const std::string name = AsciiLowercase(field.text);
    if (name.empty()) {
      diags.Report(DiagKind::CsvEmptyColumnName, field.range);
      ok = false;
      continue;
    }
    std::size_t column = 0;
    while (column < kColumnCount && kColumns[column] != name) ++column;
    if (column == kColumnCount) {
      const std::string closest = ClosestName(field.text, known);
      diags.Report(DiagKind::CsvUnknownColumn, field.range, Printable(field.text),
                   closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest), kWhat, kAllColumns);
      ok = false;
    } else if (header[column]) {
      diags.Report(DiagKind::CsvDuplicateColumn, field.range, kColumns[column]);
      ok = false;
    } else {
      header[column] = f;
    }
  }
  if (!ok) return std::nullopt;
  std::vector<std::string_view> missing;
  for (std::size_t c = 0; c < kRequired; ++c) {
    if (!header[c]) missing.push_back(kColumns[c]);
  }
  if (!missing.empty()) {
    std::string list;
    for (std::size_t i = 0; i < missing.size(); ++i) {
      list += fmt::format("{}'{}'", i == 0 ? "" : i + 1 == missing.size() ? " and " : ", ", missing[i]);
    }
    diags.Report(DiagKind::CsvMissingColumn, SourceRange(SourceLoc{record.end.file, record.line, 1}),
                 fmt::format("{} {}", missing.size() == 1 ? "column" : "columns", list), kWhat, "name, x_mm, y_mm");
    return std::nullopt;
  }
  return header;
}

// A first row naming a known column, or holding no number, is the header
// (misspelt column names are then reported with a suggestion); a row of data
// there means the header is missing.
bool LooksLikeHeader(const CsvRecord& record) {
  bool any_number = false;
  for (const CsvField& field : record.fields) {
    for (std::string_view column : kColumns) {
      if (AsciiLowercase(field.text) == column) return true;
    }
    if (ParseNumber(field.text)) any_number = true;
  }
  return !any_number;
}

// One number field: finite and within +-kMaxLengthMm.
std::optional<double> Number(const CsvField& field, std::string_view column, Diagnostics& diags) {
  if (field.text.empty()) {
    diags.Report(DiagKind::CsvEmptyField, field.range, column);
    return std::nullopt;
  }
  const std::optional<double> value = ParseNumber(field.text);
  if (!value) {
    diags.Report(DiagKind::CsvBadNumber, field.range, Printable(field.text), column, NumberHint(field.text));
    return std::nullopt;
  }
  if (!std::isfinite(*value)) {
    diags.Report(DiagKind::CsvNonFinite, field.range, Printable(field.text), column);
    return std::nullopt;
  }
  if (std::abs(*value) > kMaxLengthMm) {
    diags.Report(DiagKind::CsvLengthTooLarge, field.range, Printable(field.text), column, kMaxLengthMm);
    return std::nullopt;
  }
  return value;
}

}  // namespace

std::optional<std::vector<TripRow>> ReadTrips(std::uint32_t file, std::size_t expected_trips,
                                              std::string_view fixture, Diagnostics& diags) {
  if (ReportOtherInputKind(file, {InputKind::kTrips}, "a trip file", diags)) return std::nullopt;
  const std::size_t errors_before = diags.error_count();
  std::vector<CsvRecord> records = SplitCsv(file, diags);
  const std::string& name = diags.sources().File(file).name;
  if (records.empty()) {
    if (diags.error_count() == errors_before) {
      diags.Report(DiagKind::CsvNoRows, SourceRange(SourceLoc{file, 0, 0}), Printable(name), kWhat, kHeaderExample,
                   "trip");
    }
    return std::nullopt;
  }
  if (!LooksLikeHeader(records.front())) {
    diags.Report(DiagKind::CsvMissingHeader, records.front().fields.front().range, kHeaderExample);
    return std::nullopt;
  }
  std::optional<Header> header = ReadHeader(records.front(), diags);
  if (!header) return std::nullopt;
  const std::size_t field_count = records.front().fields.size();
  // A header and no rows: a scan in which the sensor never tripped (the
  // runtime's missing_trip), not a broken file.

  std::vector<TripRow> trips;
  std::vector<std::uint32_t> line_of(expected_trips, 0);  // where each trip was given
  for (std::size_t r = 1; r < records.size(); ++r) {
    const CsvRecord& record = records[r];
    const std::size_t have = record.fields.size();
    if (have != field_count) {
      const SourceRange where = have < field_count ? SourceRange(record.end) : record.fields[field_count].range;
      diags.Report(DiagKind::CsvFieldCount, where, fmt::format("{} field{}", have, have == 1 ? "" : "s"), field_count,
                   have < field_count ? "a field is missing" : "the first extra field is shown");
      continue;
    }
    auto field = [&](Column column) -> const CsvField& { return record.fields[*(*header)[column]]; };
    const CsvField& name_field = field(kName);
    // The trip's index, or kNoTrip when the name is wrong (reported).
    constexpr std::size_t kNoTrip = static_cast<std::size_t>(-1);
    const std::size_t index = TripIndex(name_field.text, expected_trips).value_or(kNoTrip);
    bool named = false;
    if (name_field.text.empty()) {
      diags.Report(DiagKind::CsvEmptyField, name_field.range, "name");
    } else if (index == kNoTrip) {
      diags.Report(DiagKind::TripUnknownName, name_field.range, Printable(name_field.text), fixture, expected_trips,
                   expected_trips);
    } else if (line_of[index] != 0) {
      diags.Report(DiagKind::TripDuplicate, name_field.range, fmt::format("T{}", index + 1), line_of[index]);
    } else {
      named = true;
    }
    std::optional<double> x = Number(field(kX), "x_mm", diags), y = Number(field(kY), "y_mm", diags);
    std::optional<double> z;
    bool z_ok = true;
    if ((*header)[kZ]) {
      z = Number(field(kZ), "z_mm", diags);
      z_ok = z.has_value();
    }
    if (!named || !x || !y || !z_ok) continue;
    line_of[index] = record.line;
    const std::uint32_t begin = record.fields.front().range.begin.column;
    const SourceRange& last = record.fields.back().range;
    TripRow row;
    row.index = index;
    row.point = Eigen::Vector2d(*x, *y);
    row.z_mm = z;
    row.name_range = name_field.range;
    row.range = SourceRange(SourceLoc{file, record.line, begin}, last.begin.column + last.length - begin);
    trips.push_back(row);
  }
  if (diags.error_count() != errors_before || diags.limit_reached()) return std::nullopt;
  return trips;
}

}  // namespace smtcal
