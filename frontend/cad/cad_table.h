// The table reader shared by the header-driven CAD list families (KiCad,
// Altium, JLCPCB, DipTrace, generic CSV): a preamble, a header line naming
// the columns, then one row per part. A family describes its lists with a
// Dialect (the names its columns go by, how its preamble states the unit);
// this reader finds the header, maps the columns and reads the rows.
// Internal to frontend/cad_*.cpp; everyone else uses cad_reader.h.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "frontend/cad/cad_reader.h"
#include "frontend/cad/cad_text.h"

namespace smtcal::cad {

// One name a column goes by in a family's header.
struct ColumnAlias {
  std::string base;     // as NormaliseColumnName gives it: "midx", "centerx"
  std::string display;  // for messages: "Mid X"
  Column column;
  int rank = 0;  // when a header has two names for one column, the lower rank wins
};

// The names a column goes by in one family, best first: each entry is one
// name or several of equal rank separated by '|' ("Center-X|Mid X"); a
// later entry is used only when the header has none of the earlier ones.
struct ColumnNames {
  Column column;
  std::vector<std::string_view> ranked;
};
std::vector<ColumnAlias> MakeAliases(std::initializer_list<ColumnNames> names);
// The columns a header must have.
std::array<bool, kColumnCount> RequiredColumns(std::initializer_list<Column> columns);

// What a preamble line said about the list's unit.
struct StatedUnit {
  LengthUnit unit = LengthUnit::kMm;
  SourceRange range;  // where the list says so
};

// What the preamble lines said: the unit, the tool's version.
struct Preamble {
  std::optional<StatedUnit> unit;
  ToolVersion version;
};

struct Dialect {
  Format format = Format::kGenericCsv;
  std::vector<ColumnAlias> aliases;
  std::array<bool, kColumnCount> required{};  // columns a header must have
  bool hash_header = false;  // the header line starts with '#' (KiCad .pos)
  bool fixed_width = false;  // rows whose blank-separated fields do not fit are cut at the header's columns (Altium text)
  // Reads a line before the header; may state the unit or the tool's
  // version. Returns false after reporting a mistake.
  bool (*preamble)(const Lines& lines, std::uint32_t number, Preamble& preamble, Diagnostics& diags) = nullptr;
  // Generic CSV given by column numbers: no header, 0-based field index per
  // column (-1 = not mapped).
  std::optional<std::array<int, kColumnCount>> fixed_columns;
};

// Reads a header-driven list. Returns null after reporting why it cannot
// (no header line, a required column missing, an unknown unit).
std::unique_ptr<ListReader> OpenTable(const Lines& lines, Dialect dialect, const ReadOptions& options,
                                      Diagnostics& diags);

// The family dialects (cad_kicad.cpp, cad_altium.cpp, cad_csv.cpp). The
// generic mapping has been checked by ParseColumnMapping.
Dialect KicadPosDialect();
Dialect KicadCsvDialect();
Dialect AltiumDialect();
Dialect JlcpcbDialect();
Dialect EasyEdaDialect();
Dialect DipTraceDialect();
Dialect GenericDialect(const ColumnMapping& mapping);

// The Eagle reader (cad_eagle.cpp).
std::unique_ptr<ListReader> OpenEagle(const Lines& lines, const ReadOptions& options, Diagnostics& diags);

// Content detection (cad_detect.cpp): the format of a list, or nullopt.
std::optional<Format> DetectFormat(const Lines& lines, const SourceManager& sources);

// Helpers the family files share.
// Whether a header's fields name `column` by one of the aliases.
bool MentionsColumn(const std::vector<Field>& fields, const std::vector<ColumnAlias>& aliases, Column column);
// Splits a header or data line the way the list separates fields: at
// `delimiter`, or at blanks when it is ' '.
bool SplitRecord(const Lines& lines, std::uint32_t& number, char delimiter, std::vector<Field>& fields,
                 Diagnostics& diags);
// A row's location for diagnostics about the whole row.
SourceRange RowRange(const Lines& lines, std::uint32_t number);
// Reports a length field that did not parse; `column` names it in the message.
void ReportBadLength(const Length& length, const Field& field, std::string_view column, char delimiter,
                     Diagnostics& diags);

}  // namespace smtcal::cad
