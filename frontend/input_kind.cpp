// Guessing a file's kind from what it says plainly (see input_kind.h).
#include "frontend/input_kind.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "base/field_text.h"

namespace smtcal {
namespace {

constexpr std::size_t kLinesLooked = 200;  // a cell file's first section may follow a long comment

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

bool EndsWith(std::string_view name, std::string_view suffix) {
  std::string lower = AsciiLowercase(name);
  return lower.size() >= suffix.size() && lower.compare(lower.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The first lines of the text, trimmed, without a UTF-8 byte order mark.
std::vector<std::string_view> FirstLines(std::string_view text) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  std::vector<std::string_view> lines;
  while (!text.empty() && lines.size() < kLinesLooked) {
    std::size_t end = text.find('\n');
    lines.push_back(Trim(text.substr(0, end)));
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return lines;
}

// "[robot]" -> "robot", "[[fixture.scan_path]]" -> "fixture.scan_path"; empty
// for anything else.
std::string TomlTableName(std::string_view line) {
  if (std::size_t hash = line.find('#'); hash != std::string_view::npos) line = Trim(line.substr(0, hash));
  bool array = line.starts_with("[[") && line.ends_with("]]");
  if (!array && !(line.starts_with("[") && line.ends_with("]"))) return "";
  line = line.substr(array ? 2 : 1, line.size() - (array ? 4 : 2));
  line = Trim(line);
  if (line.empty()) return "";
  for (char c : line) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return "";
  }
  return AsciiLowercase(line);
}

// The lowercased fields of a delimited header line (comma, semicolon or tab),
// quotes removed; empty when the line has fewer than two fields.
std::vector<std::string> HeaderFields(std::string_view line) {
  char delimiter = ',';
  for (char d : {'\t', ';', ','}) {
    if (line.find(d) != std::string_view::npos) delimiter = d;
  }
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (;;) {
    std::size_t end = line.find(delimiter, start);
    std::string field(Trim(line.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start)));
    if (field.size() >= 2 && field.front() == '"' && field.back() == '"') field = field.substr(1, field.size() - 2);
    fields.push_back(AsciiLowercase(field));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  if (fields.size() < 2) fields.clear();
  return fields;
}

bool Has(const std::vector<std::string>& fields, std::initializer_list<std::string_view> names) {
  return std::all_of(names.begin(), names.end(), [&](std::string_view name) {
    return std::find(fields.begin(), fields.end(), name) != fields.end();
  });
}

// "Fixture Board" but not the TOML key "fixture = ...".
bool StartsWithWord(std::string_view line, std::string_view word) {
  if (line.size() < word.size()) return false;
  if (AsciiLowercase(line.substr(0, word.size())) != AsciiLowercase(word)) return false;
  if (line.size() == word.size()) return false;
  if (line[word.size()] != ' ' && line[word.size()] != '\t') return false;
  std::string_view rest = Trim(line.substr(word.size()));
  // A name follows: "Point P = ...", "Function Main", "Pallet 1, ...".
  return !rest.empty() && (std::isalnum(static_cast<unsigned char>(rest.front())) || rest.front() == '_');
}

InputKind TomlKind(const std::set<std::string>& tables) {
  auto any = [&](std::initializer_list<std::string_view> names) {
    return std::any_of(names.begin(), names.end(), [&](std::string_view n) { return tables.count(std::string(n)); });
  };
  if (any({"fixture", "linuxcnc", "fixture.edges", "fixture.scan_path", "fixture.limits"})) return InputKind::kCell;
  if (any({"noise", "field", "board", "sensor"})) return InputKind::kTruth;
  if (any({"robot", "region"})) return InputKind::kCell;
  if (any({"feeder", "map"})) return InputKind::kFeeders;
  return InputKind::kToml;
}

}  // namespace

InputKind GuessInputKind(std::string_view name, std::string_view text) {
  const std::vector<std::string_view> lines = FirstLines(text);
  std::set<std::string> tables;
  for (std::string_view line : lines) {
    if (std::string table = TomlTableName(line); !table.empty()) tables.insert(table);
  }
  for (std::string_view line : lines) {
    if (line.starts_with("Altium Designer Pick and Place") || line.starts_with("### Module positions") ||
        line.starts_with("### Footprint positions")) {
      return InputKind::kCadList;
    }
  }
  for (std::string_view line : lines) {
    if (line.starts_with("smtcal-record ")) return InputKind::kRecordLog;
  }
  for (std::string_view line : lines) {
    // A program says so at the start of a line; it is never another kind.
    for (std::string_view word : {"Function", "Program", "Point", "Fixture", "Pallet", "Taught", "Vacuum"}) {
      if (StartsWithWord(line, word)) return InputKind::kProgram;
    }
    if (AsciiLowercase(line) == "fend") return InputKind::kProgram;
    for (std::string_view units : {"Units mm", "Units in", "Units inch"}) {
      if (AsciiLowercase(line) == AsciiLowercase(units)) return InputKind::kProgram;
    }
  }
  for (std::string_view line : lines) {
    if (line.empty()) continue;
    if (line.starts_with("<?xml") || line.starts_with("<svg")) return InputKind::kSvg;
    if (line.starts_with("{")) return InputKind::kJson;
    if (line.starts_with("#") || line.starts_with("'")) continue;  // comments of TOML, CSV, .place
    if (line.starts_with("%") || line.starts_with("o<") || line.starts_with("G21") || line.starts_with("(")) {
      return EndsWith(name, ".ngc") ? InputKind::kNgc : InputKind::kUnknown;
    }
    if (!TomlTableName(line).empty()) return TomlKind(tables);
    std::vector<std::string> fields = HeaderFields(line);
    if (Has(fields, {"axis", "x_mm", "y_mm", "set", "repetition", "error_mm"})) return InputKind::kRawMeasurements;
    // An error table's header holds its columns and no other (a raw file
    // with a misspelt column gets the reader's message about that column).
    const bool only_table_columns = std::all_of(fields.begin(), fields.end(), [](const std::string& f) {
      return f == "axis" || f == "x_mm" || f == "y_mm" || f == "error_mm" || f == "stddev_mm" || f == "n";
    });
    if (only_table_columns && Has(fields, {"axis", "x_mm", "y_mm", "error_mm"})) return InputKind::kErrorTable;
    if (Has(fields, {"name", "x_mm", "y_mm"}) && fields.size() <= 4) return InputKind::kTrips;
    for (std::string_view designator : {"designator", "ref", "refdes", "reference"}) {
      if (Has(fields, {designator}) && fields.size() >= 4) return InputKind::kCadList;
    }
    // A TOML key line decides only with the name's word for it.
    if (EndsWith(name, ".toml")) return TomlKind(tables);
    return InputKind::kUnknown;
  }
  return InputKind::kUnknown;
}

std::string_view InputKindName(InputKind kind) {
  switch (kind) {
    case InputKind::kUnknown: return "a file of unknown kind";
    case InputKind::kProgram: return "a .place program";
    case InputKind::kCell: return "a cell file (TOML)";
    case InputKind::kFeeders: return "a feeders file (TOML)";
    case InputKind::kTruth: return "a truth file of smtcal simulate (TOML)";
    case InputKind::kToml: return "a TOML file";
    case InputKind::kErrorTable: return "an error table (CSV)";
    case InputKind::kRawMeasurements: return "a raw measurement file (CSV)";
    case InputKind::kTrips: return "a trip file of a marker scan (CSV)";
    case InputKind::kCadList: return "a CAD placement list";
    case InputKind::kJson: return "a JSON file";
    case InputKind::kSvg: return "an SVG picture";
    case InputKind::kNgc: return "an RS274NGC program (LinuxCNC)";
    case InputKind::kRecordLog: return "a log of cycle records";
  }
  return "";
}

std::string InputKindAdvice(InputKind kind, std::string_view name) {
  std::string file(name);
  switch (kind) {
    case InputKind::kProgram: return fmt::format("check it with 'smtcal check {}'", file);
    case InputKind::kCell: return fmt::format("check it with 'smtcal cell check {}', or give it as --cell {}", file, file);
    case InputKind::kFeeders: return fmt::format("give it to 'smtcal import LIST --cell CELL.toml --feeders {}'", file);
    case InputKind::kTruth: return fmt::format("give it to 'smtcal simulate PROGRAM --cell CELL.toml --truth {}'", file);
    case InputKind::kErrorTable: return fmt::format("check it with 'smtcal table check {}'", file);
    case InputKind::kRawMeasurements:
      return fmt::format("make an error table of it with 'smtcal table build {} -o TABLE.csv'", file);
    case InputKind::kTrips: return fmt::format("give it to 'smtcal fixture --cell CELL.toml --fixture NAME --trips {}'", file);
    case InputKind::kCadList:
      return fmt::format("make a program of it with 'smtcal import {} --cell CELL.toml -o BOARD.place'", file);
    case InputKind::kNgc: return "it is smtcal's output for LinuxCNC, not one of its inputs";
    case InputKind::kRecordLog: return fmt::format("read it with 'smtcal monitor {} --cell CELL.toml'", file);
    case InputKind::kUnknown:
    case InputKind::kToml:
    case InputKind::kJson:
    case InputKind::kSvg: return "";
  }
  return "";
}

bool ReportOtherInputKind(std::uint32_t file, std::initializer_list<InputKind> accepted, std::string_view wanted,
                          Diagnostics& diags) {
  const SourceFile& source = diags.sources().File(file);
  const InputKind kind = GuessInputKind(source.name, source.text);
  if (kind == InputKind::kUnknown || std::find(accepted.begin(), accepted.end(), kind) != accepted.end()) return false;
  const std::string advice = InputKindAdvice(kind, source.name);
  diags.Report(DiagKind::InputIsOtherKind, SourceRange(SourceLoc{file, 1, 1}), Printable(source.name),
               InputKindName(kind), wanted, advice.empty() ? std::string() : "; " + advice);
  return true;
}

}  // namespace smtcal
