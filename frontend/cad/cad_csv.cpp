// The plain CSV families:
//
// JLCPCB CPL and the KiCad Fabrication Toolkit's positions file:
//   Designator,Val,Package,Mid X,Mid Y,Rotation,Layer   (or Designator,Mid X,Mid Y,Layer,Rotation)
// often with a UTF-8 byte order mark and CRLF; values may carry "mm"; layers
// top/bottom or T/B; rotations 0..360. JLCPCB's own template names the
// columns "Comment" and "Footprint" instead of Val and Package.
//
// DipTrace 3.x: RefDes,Name,Value,X (mm),Y (mm),Rotate,Side
// DipTrace 4.x: RefDes,Name,Value,Center X (mm),Center Y (mm),Rotation,Side
// (the unit in the column names; "Pattern" is the footprint when exported,
// else DipTrace's component "Name" stands in for the package).
//
// Generic CSV: the columns are named on the command line (--columns), by
// header name or by 1-based column number (then the list has no header).
#include <algorithm>
#include <cctype>

#include "frontend/cad/cad_table.h"

namespace smtcal::cad {
namespace {

// Placement lists have a dozen columns; a larger number is a typo.
constexpr int kMaxColumnNumber = 1000;

bool IsColumnNumber(std::string_view text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
}

}  // namespace

Dialect JlcpcbDialect() {
  Dialect dialect;
  dialect.format = Format::kJlcpcb;
  dialect.aliases = MakeAliases({{Column::kDesignator, {"Designator", "Ref"}},
                                 {Column::kValue, {"Val|Value", "Comment"}},
                                 {Column::kPackage, {"Package", "Footprint"}},
                                 {Column::kX, {"Mid X", "PosX"}},
                                 {Column::kY, {"Mid Y", "PosY"}},
                                 {Column::kRotation, {"Rotation", "Rot"}},
                                 {Column::kSide, {"Layer", "Side"}},
                                 {Column::kDnp, {"DNP"}}});
  dialect.required = RequiredColumns({Column::kDesignator, Column::kX, Column::kY, Column::kRotation, Column::kSide});
  return dialect;
}

Dialect DipTraceDialect() {
  Dialect dialect;
  dialect.format = Format::kDipTrace;
  dialect.aliases = MakeAliases({{Column::kDesignator, {"RefDes"}},
                                 {Column::kValue, {"Value"}},
                                 {Column::kPackage, {"Pattern", "Name"}},
                                 {Column::kX, {"X|Center X"}},
                                 {Column::kY, {"Y|Center Y"}},
                                 {Column::kRotation, {"Rotate|Rotation"}},
                                 {Column::kSide, {"Side"}},
                                 {Column::kDnp, {"DNP"}}});
  dialect.required = RequiredColumns({Column::kDesignator, Column::kX, Column::kY, Column::kRotation});
  return dialect;
}

Dialect GenericDialect(const ColumnMapping& mapping) {
  Dialect dialect;
  dialect.format = Format::kGenericCsv;
  bool by_number = false;
  std::array<int, kColumnCount> numbers;
  numbers.fill(-1);
  for (int c = 0; c < kColumnCount; ++c) {
    const std::string& name = mapping.columns[c];
    if (name.empty()) continue;
    dialect.required[c] = true;
    if (IsColumnNumber(name)) {
      by_number = true;
      numbers[c] = std::stoi(name) - 1;
    } else {
      dialect.aliases.push_back({NormaliseColumnName(name).base, name, static_cast<Column>(c), 0});
    }
  }
  if (by_number) dialect.fixed_columns = numbers;
  return dialect;
}

std::optional<std::string> ParseColumnMapping(std::string_view text, ColumnMapping& mapping) {
  std::size_t at = 0;
  while (at <= text.size()) {
    std::size_t end = std::min(text.find(',', at), text.size());
    std::string_view item = text.substr(at, end - at);
    std::size_t eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0 || eq + 1 == item.size()) {
      return "--columns takes KEY=COLUMN pairs separated by ',' (e.g. designator=Ref,x=X,y=Y,rotation=Rot), found '" +
             std::string(item) + "'";
    }
    std::string_view key = item.substr(0, eq);
    auto known = std::find(std::begin(kColumnKeys), std::end(kColumnKeys), key);
    if (known == std::end(kColumnKeys)) {
      return "unknown --columns key '" + std::string(key) +
             "'; the keys are designator, value, package, x, y, rotation, side and dnp";
    }
    std::string column(item.substr(eq + 1));
    if (IsColumnNumber(column) && (column.size() > 4 || std::stoi(column) < 1 || std::stoi(column) > kMaxColumnNumber)) {
      return "column numbers in --columns are 1 to " + std::to_string(kMaxColumnNumber) + ", found '" + column + "'";
    }
    mapping.columns[static_cast<std::size_t>(known - std::begin(kColumnKeys))] = column;
    at = end + 1;
  }
  bool numbers = false, names = false;
  for (const std::string& column : mapping.columns) {
    if (column.empty()) continue;
    (IsColumnNumber(column) ? numbers : names) = true;
  }
  if (numbers && names) return "--columns gives either header names or column numbers, not both";
  for (Column needed : {Column::kDesignator, Column::kX, Column::kY}) {
    if (mapping.columns[static_cast<int>(needed)].empty()) {
      return "--columns must map designator, x and y (rotation, value, package, side and dnp are optional)";
    }
  }
  return std::nullopt;
}

}  // namespace smtcal::cad
