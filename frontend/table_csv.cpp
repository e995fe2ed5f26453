// Reading the error tables' CSV files (the dialect is described in
// table_csv.h and docs/error-tables.md). Every mistake is a diagnostic at the
// row's line and the offending field's column; a row with a mistake is left
// out and reading goes on, so one run reports all of them.
#include "frontend/table_csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>

#include <fmt/format.h>

#include "base/check.h"
#include "base/field_text.h"
#include "calibration/tolerances.h"
#include "frontend/cad/cad_text.h"
#include "frontend/input_kind.h"

namespace smtcal {
namespace {

// ------------------------------------------------------------------ columns

// What a file holds: its columns in their usual order, the first `required`
// of them required.
struct Schema {
  std::string_view what;  // "an error table": for messages
  std::string_view row;   // what one data row holds: "node and axis"
  std::vector<std::string_view> columns;
  std::size_t required;
  bool header_optional;  // a headerless file has the required columns in order
};

const Schema kTableSchema{
    "an error table", "node and axis",
    {"axis", "x_mm", "y_mm", "error_mm", "stddev_mm", "n", "kind", "u_mm", "reversal_mm"}, 4, false};
const Schema kRawSchema{"a raw measurement file", "measurement",
                        {"axis", "x_mm", "y_mm", "set", "repetition", "error_mm", "kind", "u_mm", "approach"}, 6,
                        false};
const Schema kPointSchema{"a point list", "point", {"x_mm", "y_mm"}, 2, true};
const Schema kPlanSchema{"a measurement plan", "visit",
                         {"visit", "region", "axes", "station", "kind", "node", "x_mm", "y_mm", "set", "repetitions",
                          "approach"},
                         10, false};
const Schema kExternalSchema{
    "an external system's readings", "reading", {"node", "set", "repetition", "x_mm", "y_mm"}, 5, false};

std::string JoinColumns(const Schema& schema, std::size_t count, std::string_view separator = ", ") {
  std::string text;
  for (std::size_t i = 0; i < count; ++i) {
    if (i > 0) text += separator;
    text += schema.columns[i];
  }
  return text;
}


// A header maps each of the schema's columns to a field index (or none).
struct Header {
  std::vector<std::optional<std::size_t>> field_of;  // per schema column
  std::size_t field_count = 0;
  std::vector<std::string_view> field_names;  // per field, for "missing: ..."
};

bool LooksLikeHeader(const CsvRecord& record, const Schema& schema) {
  bool any_number = false;
  for (const CsvField& field : record.fields) {
    std::string name = AsciiLowercase(field.text);
    for (std::string_view column : schema.columns) {
      if (name == column) return true;
    }
    if (ParseNumber(field.text)) any_number = true;
  }
  return !any_number;
}

std::optional<Header> ReadHeader(const CsvRecord& record, const Schema& schema, Diagnostics& diags) {
  Header header;
  header.field_of.resize(schema.columns.size());
  header.field_count = record.fields.size();
  bool ok = true;
  std::vector<std::string> known(schema.columns.begin(), schema.columns.end());
  std::vector<std::string> suggested;  // a misspelt column is not reported missing as well
  for (std::size_t f = 0; f < record.fields.size(); ++f) {
    const CsvField& field = record.fields[f];
    std::string name = AsciiLowercase(field.text);
    auto it = std::find(schema.columns.begin(), schema.columns.end(), name);
    if (name.empty()) {
      diags.Report(DiagKind::CsvEmptyColumnName, field.range);
      ok = false;
      header.field_names.push_back("?");
      continue;
    }
    if (it == schema.columns.end()) {
      std::string closest = ClosestName(field.text, known);
      suggested.push_back(closest);
      diags.Report(DiagKind::CsvUnknownColumn, field.range, Printable(field.text),
                   closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest), schema.what,
                   JoinColumns(schema, schema.columns.size()));
      ok = false;
      header.field_names.push_back("?");
      continue;
    }
    std::size_t column = static_cast<std::size_t>(it - schema.columns.begin());
    header.field_names.push_back(schema.columns[column]);
    if (header.field_of[column]) {
      diags.Report(DiagKind::CsvDuplicateColumn, field.range, schema.columns[column]);
      ok = false;
      continue;
    }
    header.field_of[column] = f;
  }
  std::vector<std::string> missing;
  for (std::size_t c = 0; c < schema.required; ++c) {
    if (header.field_of[c]) continue;
    ok = false;
    std::string column(schema.columns[c]);
    if (std::find(suggested.begin(), suggested.end(), column) == suggested.end()) missing.push_back(column);
  }
  if (!missing.empty()) {
    std::string list;
    for (std::size_t i = 0; i < missing.size(); ++i) {
      list += fmt::format("{}'{}'", i == 0 ? "" : i + 1 == missing.size() ? " and " : ", ", missing[i]);
    }
    diags.Report(DiagKind::CsvMissingColumn, SourceRange(SourceLoc{record.end.file, record.line, 1}),
                 fmt::format("{} {}", missing.size() == 1 ? "column" : "columns", list), schema.what,
                 JoinColumns(schema, schema.required));
  }
  if (!ok) return std::nullopt;
  return header;
}

Header DefaultHeader(const Schema& schema) {
  Header header;
  for (std::size_t c = 0; c < schema.columns.size(); ++c) {
    header.field_of.push_back(c < schema.required ? std::optional<std::size_t>(c) : std::nullopt);
  }
  header.field_count = schema.required;
  header.field_names.assign(schema.columns.begin(), schema.columns.begin() + static_cast<long>(schema.required));
  return header;
}

// One data row, read through the header. Each accessor reports its own
// mistakes; `ok` turns false at the first one.
class Row {
 public:
  Row(const CsvRecord& record, const Header& header, const Schema& schema, Diagnostics& diags)
      : record_(record), header_(header), schema_(schema), diags_(diags) {}

  // Checks the field count; false (reported) when it does not match.
  bool CheckShape() {
    std::size_t have = record_.fields.size(), want = header_.field_count;
    if (have == want) return true;
    if (have < want) {
      std::string missing;
      for (std::size_t f = have; f < want; ++f) {
        missing += (missing.empty() ? "" : ", ") + std::string(header_.field_names[f]);
      }
      diags_.Report(DiagKind::CsvFieldCount, SourceRange(record_.end), Fields(have), want, "missing: " + missing);
    } else {
      diags_.Report(DiagKind::CsvFieldCount, record_.fields[want].range, Fields(have), want,
                    "the first extra field is shown");
    }
    return false;
  }

  const CsvField* Field(std::size_t column) const {
    const auto& index = header_.field_of[column];
    return index ? &record_.fields[*index] : nullptr;
  }
  SourceRange Range(std::size_t column) const {
    const CsvField* field = Field(column);
    return field != nullptr ? field->range : SourceRange(record_.end);
  }

  std::optional<TableAxis> Axis(std::size_t column) {
    const CsvField* field = Field(column);
    if (!Present(column, field)) return std::nullopt;
    std::string name = AsciiLowercase(field->text);
    if (name == "x") return TableAxis::X;
    if (name == "y") return TableAxis::Y;
    diags_.Report(DiagKind::TableBadAxis, field->range, Printable(field->text));
    ok = false;
    return std::nullopt;
  }

  // The optional `kind` column: node (also when the column or the field is
  // empty) or check.
  std::optional<ReadingKind> Kind(std::size_t column) {
    const CsvField* field = Field(column);
    if (field == nullptr || field->text.empty()) return ReadingKind::kNode;
    std::string name = AsciiLowercase(field->text);
    if (name == "node") return ReadingKind::kNode;
    if (name == "check") return ReadingKind::kCheck;
    diags_.Report(DiagKind::TableBadKind, field->range, Printable(field->text));
    ok = false;
    return std::nullopt;
  }

  // A finite length in mm, within +-kMaxLengthMm. `optional_column`: an empty
  // or absent field is nullopt.
  std::optional<double> Number(std::size_t column, bool optional_column = false) {
    const CsvField* field = Field(column);
    if (optional_column && (field == nullptr || field->text.empty())) return std::nullopt;
    if (!Present(column, field)) return std::nullopt;
    std::optional<double> value = ParseNumber(field->text);
    if (!value) {
      diags_.Report(DiagKind::CsvBadNumber, field->range, Printable(field->text), schema_.columns[column],
                    NumberHint(field->text));
      ok = false;
      return std::nullopt;
    }
    if (!std::isfinite(*value)) {
      diags_.Report(DiagKind::CsvNonFinite, field->range, Printable(field->text), schema_.columns[column]);
      ok = false;
      return std::nullopt;
    }
    if (std::abs(*value) > kMaxLengthMm) {  // every number column is a length in mm
      diags_.Report(DiagKind::CsvLengthTooLarge, field->range, Printable(field->text), schema_.columns[column],
                    kMaxLengthMm);
      ok = false;
      return std::nullopt;
    }
    return value;
  }

  // A whole number >= minimum.
  std::optional<long long> Count(std::size_t column, long long minimum, bool optional_column = false) {
    const CsvField* field = Field(column);
    if (optional_column && (field == nullptr || field->text.empty())) return std::nullopt;
    if (!Present(column, field)) return std::nullopt;
    std::string_view text = field->text;
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    long long value = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() || value < minimum) {
      diags_.Report(DiagKind::CsvBadCount, field->range, Printable(field->text), schema_.columns[column], minimum);
      ok = false;
      return std::nullopt;
    }
    return value;
  }

  // A non-empty text field.
  std::optional<std::string> Text(std::size_t column) {
    const CsvField* field = Field(column);
    if (!Present(column, field)) return std::nullopt;
    return field->text;
  }

  // One of `names` (case-insensitive); its index.
  std::optional<std::size_t> Choice(std::size_t column, const std::vector<std::string_view>& names) {
    const CsvField* field = Field(column);
    if (!Present(column, field)) return std::nullopt;
    std::string text = AsciiLowercase(field->text);
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (text == names[i]) return i;
    }
    std::string list;
    for (std::size_t i = 0; i < names.size(); ++i) {
      list += fmt::format("{}'{}'", i == 0 ? "" : i + 1 == names.size() ? " or " : ", ", names[i]);
    }
    diags_.Report(DiagKind::CsvBadChoice, field->range, Printable(field->text), schema_.columns[column], list);
    ok = false;
    return std::nullopt;
  }

  bool ok = true;

 private:
  bool Present(std::size_t column, const CsvField* field) {
    SMTCAL_CHECK(field != nullptr, "a required column without a field (the header check missed it)");
    if (!field->text.empty()) return true;
    diags_.Report(DiagKind::CsvEmptyField, field->range, schema_.columns[column]);
    ok = false;
    return false;
  }

  static std::string Fields(std::size_t count) { return fmt::format("{} field{}", count, count == 1 ? "" : "s"); }

  static std::string NumberHint(std::string_view text) {
    if (text.find(',') != std::string_view::npos) return " (write the decimal point as '.')";
    std::string lower = AsciiLowercase(text);
    for (std::string_view unit : {"mm", "um", "µm"}) {
      if (lower.size() > unit.size() && lower.ends_with(unit)) return " (write the number without its unit)";
    }
    return "";
  }

  const CsvRecord& record_;
  const Header& header_;
  const Schema& schema_;
  Diagnostics& diags_;
};

// Splits the file and reads its header. nullopt (reported) when the file has
// no usable header or no rows; otherwise the header and the data records.
struct Body {
  Header header;
  std::vector<CsvRecord> records;
};

std::optional<Body> ReadBody(std::uint32_t file, const Schema& schema, Diagnostics& diags) {
  // Another of smtcal's files (a raw measurement file for `table stats`, a
  // cell file, a program) is named with the command it belongs to.
  const InputKind wanted = &schema == &kRawSchema     ? InputKind::kRawMeasurements
                           : &schema == &kTableSchema ? InputKind::kErrorTable
                                                      : InputKind::kUnknown;
  if (ReportOtherInputKind(file, {wanted}, schema.what, diags)) return std::nullopt;
  const std::size_t errors_before = diags.error_count();
  std::vector<CsvRecord> records = SplitCsv(file, diags);
  const std::string& name = diags.sources().File(file).name;
  if (records.empty()) {
    if (diags.error_count() == errors_before) {  // else the lines were all malformed
      diags.Report(DiagKind::CsvNoRows, SourceRange(SourceLoc{file, 0, 0}), Printable(name), schema.what,
                   JoinColumns(schema, schema.required, ","), schema.row);
    }
    return std::nullopt;
  }
  Body body;
  if (LooksLikeHeader(records.front(), schema)) {
    std::optional<Header> header = ReadHeader(records.front(), schema, diags);
    if (!header) return std::nullopt;
    body.header = std::move(*header);
    records.erase(records.begin());
  } else if (schema.header_optional) {
    body.header = DefaultHeader(schema);
  } else {
    diags.Report(DiagKind::CsvMissingHeader, records.front().fields.front().range,
                 JoinColumns(schema, schema.required, ","));
    return std::nullopt;
  }
  if (records.empty()) {
    diags.Report(DiagKind::CsvNoRows, SourceRange(SourceLoc{file, 0, 0}), Printable(name), schema.what,
                   JoinColumns(schema, schema.required, ","), schema.row);
    return std::nullopt;
  }
  body.records = std::move(records);
  return body;
}

// Reads every data row of the file through `read_row`, which reports its
// row's mistakes and returns nullopt to leave the row out. Reading goes on
// after a mistake so one run reports all of them; nullopt when there was any.
template <typename T, typename ReadRow>
std::optional<std::vector<T>> ReadRows(std::uint32_t file, const Schema& schema, Diagnostics& diags,
                                       ReadRow read_row) {
  const std::size_t errors_before = diags.error_count();
  std::optional<Body> body = ReadBody(file, schema, diags);
  if (!body) return std::nullopt;
  std::vector<T> rows;
  for (const CsvRecord& record : body->records) {
    Row row(record, body->header, schema, diags);
    if (!row.CheckShape()) continue;
    if (std::optional<T> value = read_row(row, record)) rows.push_back(std::move(*value));
  }
  if (diags.error_count() != errors_before || diags.limit_reached()) return std::nullopt;
  return rows;
}

}  // namespace

std::vector<CsvRecord> SplitCsv(std::uint32_t file, Diagnostics& diags) {
  // The lines and fields are split as the CAD lists' (frontend/cad/cad_text.h),
  // with ',' between fields and every quoted field ending on its own line.
  const cad::Lines lines(diags.sources(), file);
  std::vector<CsvRecord> records;
  std::vector<cad::Field> fields;
  for (std::uint32_t number = 1; number <= lines.count(); ++number) {
    std::string_view line = lines.Text(number);
    std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string_view::npos || line[first] == '#') continue;
    std::uint32_t last = number;
    if (!cad::SplitDelimited(lines, last, ',', fields, diags, /*multiline=*/false)) continue;
    CsvRecord record;
    record.line = number;
    record.end = lines.At(number, line.size());
    record.fields.reserve(fields.size());
    for (cad::Field& field : fields) record.fields.push_back(CsvField{std::move(field.text), field.range});
    records.push_back(std::move(record));
  }
  return records;
}

std::optional<ErrorTable> ReadErrorTable(std::uint32_t file, Diagnostics& diags) {
  enum { kAxis, kX, kY, kError, kStddev, kCount, kKind, kU, kReversal };
  auto read_row = [&](Row& row, const CsvRecord&) -> std::optional<TableNode> {
    TableNode node;
    std::optional<TableAxis> axis = row.Axis(kAxis);
    std::optional<ReadingKind> kind = row.Kind(kKind);
    std::optional<double> x = row.Number(kX), y = row.Number(kY), error = row.Number(kError);
    node.stddev_mm = row.Number(kStddev, true);
    std::optional<long long> count = row.Count(kCount, 1, true);
    node.u_mm = row.Number(kU, true);
    node.reversal_mm = row.Number(kReversal, true);
    if (!row.ok) return std::nullopt;
    if (node.stddev_mm && *node.stddev_mm < 0) {
      diags.Report(DiagKind::TableNegativeStddev, row.Range(kStddev), row.Field(kStddev)->text);
      return std::nullopt;
    }
    if (node.u_mm && *node.u_mm < 0) {
      diags.Report(DiagKind::TableNegativeValue, row.Range(kU), "u_mm", Printable(row.Field(kU)->text),
                   "a standard uncertainty");
      return std::nullopt;
    }
    node.kind = *kind;
    node.axis = *axis;
    node.x_mm = *x;
    node.y_mm = *y;
    node.error_mm = *error;
    node.count = count ? static_cast<int>(std::min<long long>(*count, 1 << 30)) : 0;
    node.x_field = row.Range(kX);
    node.y_field = row.Range(kY);
    node.error_field = row.Range(kError);
    return node;
  };
  std::optional<std::vector<TableNode>> nodes = ReadRows<TableNode>(file, kTableSchema, diags, read_row);
  if (!nodes) return std::nullopt;
  return AssembleErrorTable(diags.sources().File(file).name, *nodes, SourceLoc{file, 0, 0}, diags);
}

std::optional<std::vector<RawMeasurement>> ReadRawMeasurements(std::uint32_t file, Diagnostics& diags) {
  enum { kAxis, kX, kY, kSet, kRepetition, kError, kKind, kU, kApproach };
  auto read_row = [&](Row& row, const CsvRecord&) -> std::optional<RawMeasurement> {
    std::optional<TableAxis> axis = row.Axis(kAxis);
    std::optional<ReadingKind> kind = row.Kind(kKind);
    std::optional<double> x = row.Number(kX), y = row.Number(kY);
    std::optional<long long> set = row.Count(kSet, 0), repetition = row.Count(kRepetition, 0);
    std::optional<double> error = row.Number(kError);
    std::optional<double> u = row.Number(kU, true);
    // The approach: '+' (the final approach, the default) or '-' (against it).
    std::optional<std::size_t> approach;
    if (const CsvField* field = row.Field(kApproach); field != nullptr && !field->text.empty()) {
      approach = row.Choice(kApproach, {"+", "-"});
    }
    if (!row.ok) return std::nullopt;
    if (u && *u < 0) {
      diags.Report(DiagKind::TableNegativeValue, row.Range(kU), "u_mm", Printable(row.Field(kU)->text),
                   "a standard uncertainty");
      return std::nullopt;
    }
    RawMeasurement m;
    m.u_mm = u;
    m.reverse = approach == std::size_t{1};
    m.kind = *kind;
    m.axis = *axis;
    m.x_mm = *x;
    m.y_mm = *y;
    m.set = *set;
    m.repetition = *repetition;
    m.error_mm = *error;
    m.x_field = row.Range(kX);
    m.y_field = row.Range(kY);
    m.repetition_field = row.Range(kRepetition);
    m.error_field = row.Range(kError);
    return m;
  };
  return ReadRows<RawMeasurement>(file, kRawSchema, diags, read_row);
}

std::optional<std::vector<PointRow>> ReadPoints(std::uint32_t file, Diagnostics& diags) {
  enum { kX, kY };
  auto read_row = [&](Row& row, const CsvRecord& record) -> std::optional<PointRow> {
    std::optional<double> x = row.Number(kX), y = row.Number(kY);
    if (!row.ok) return std::nullopt;
    SourceRange rx = row.Range(kX), ry = row.Range(kY);
    std::uint32_t begin = std::min(rx.begin.column, ry.begin.column);
    std::uint32_t end = std::max(rx.begin.column + rx.length, ry.begin.column + ry.length);
    return PointRow{Eigen::Vector2d(*x, *y), SourceRange(SourceLoc{file, record.line, begin}, end - begin)};
  };
  return ReadRows<PointRow>(file, kPointSchema, diags, read_row);
}

std::optional<std::vector<PlanRow>> ReadMeasurementPlan(std::uint32_t file, Diagnostics& diags) {
  enum { kVisit, kRegion, kAxes, kStation, kKind, kNode, kX, kY, kSet, kRepetitions, kApproach };
  auto read_row = [](Row& row, const CsvRecord& record) -> std::optional<PlanRow> {
    PlanRow plan;
    std::optional<long long> visit = row.Count(kVisit, 1), station = row.Count(kStation, 1),
                             node = row.Count(kNode, 1), set = row.Count(kSet, 1),
                             repetitions = row.Count(kRepetitions, 1);
    std::optional<std::string> region = row.Text(kRegion);
    std::optional<std::size_t> axes = row.Choice(kAxes, {"x", "y", "xy"});
    std::optional<std::size_t> kind = row.Choice(kKind, {"node", "check", "tie", "closure"});
    std::optional<std::size_t> approach;
    if (const CsvField* field = row.Field(kApproach); field != nullptr && !field->text.empty()) {
      approach = row.Choice(kApproach, {"+", "-"});
    }
    std::optional<double> x = row.Number(kX), y = row.Number(kY);
    if (!row.ok) return std::nullopt;
    constexpr long long kMaxCount = 1 << 30;
    auto small = [&](long long value) { return static_cast<int>(std::min(value, kMaxCount)); };
    plan.visit = small(*visit);
    plan.region = *region;
    plan.axes = static_cast<measure::MeasuredAxes>(*axes);
    plan.station = small(*station);
    plan.kind = static_cast<measure::VisitKind>(*kind);
    plan.node = small(*node);
    plan.at = Eigen::Vector2d(*x, *y);
    plan.set = small(*set);
    plan.repetitions = small(*repetitions);
    plan.direction = approach == std::size_t{1} ? -1 : 1;
    plan.line = record.line;
    plan.visit_field = row.Range(kVisit);
    plan.region_field = row.Range(kRegion);
    plan.node_field = row.Range(kNode);
    return plan;
  };
  return ReadRows<PlanRow>(file, kPlanSchema, diags, read_row);
}

std::optional<std::vector<ExternalReading>> ReadExternalReadings(std::uint32_t file, Diagnostics& diags) {
  enum { kNode, kSet, kRepetition, kX, kY };
  auto read_row = [](Row& row, const CsvRecord& record) -> std::optional<ExternalReading> {
    std::optional<long long> node = row.Count(kNode, 1), set = row.Count(kSet, 1),
                             repetition = row.Count(kRepetition, 1);
    std::optional<double> x = row.Number(kX), y = row.Number(kY);
    if (!row.ok) return std::nullopt;
    ExternalReading reading;
    reading.node = *node;
    reading.set = *set;
    reading.repetition = *repetition;
    reading.at = Eigen::Vector2d(*x, *y);
    reading.line = record.line;
    reading.range = row.Range(kNode);
    return reading;
  };
  return ReadRows<ExternalReading>(file, kExternalSchema, diags, read_row);
}

}  // namespace smtcal
