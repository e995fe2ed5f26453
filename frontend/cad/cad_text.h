// The lexical layer shared by the CAD list readers: lines (UTF-8 byte order
// mark and CR removed), fields (RFC 4180 delimited, whitespace-separated or
// fixed-width), numbers with unit suffixes and decimal commas, side
// spellings and column names. Numbers are read locale-independently with
// fast_float. Nothing here knows a particular EDA tool.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "base/field_text.h"
#include "base/source.h"
#include "frontend/cad/cad_row.h"

namespace smtcal::cad {

// The lines of one source file, as the readers see them: without the line
// end, and line 1 without a UTF-8 byte order mark (columns in diagnostics
// still count the file's bytes).
class Lines {
 public:
  Lines(const SourceManager& sources, std::uint32_t file);

  std::uint32_t file() const { return file_; }
  std::uint32_t count() const { return count_; }
  const std::string& name() const { return source_->name; }
  std::string_view Text(std::uint32_t number) const;
  // The location of byte `offset` of Text(number).
  SourceLoc At(std::uint32_t number, std::size_t offset) const;
  SourceRange Range(std::uint32_t number, std::size_t offset, std::size_t length) const;
  // A line that holds nothing to read: blank, a '#' comment, or a rule of
  // '=', '-' or '*' characters (report separators).
  bool IsFiller(std::uint32_t number) const;

 private:
  const SourceFile* source_;
  std::uint32_t file_;
  std::uint32_t count_;
  std::size_t bom_;  // 3 when line 1 starts with a byte order mark
};

// One field of a row: its text (unquoted; spaces and tabs around it
// removed) and where it is.
struct Field {
  std::string text;
  SourceRange range;      // the field as written, quotes included
  std::size_t start = 0;  // blank-separated fields: the first character's column in code points (fixed width)
  bool quoted = false;
};

// Splits a delimited record starting on line `number` (RFC 4180: a field in
// double quotes may hold the delimiter and "" for a quote). With
// `multiline`, a quoted field may hold line ends too: the record then runs
// on to later lines and `number` is advanced to its last line (CAD lists);
// without it a quoted field ends on its own line (the error tables' CSV,
// frontend/table_csv.h, which splits its lines here too). Returns false
// after reporting a quoting error.
bool SplitDelimited(const Lines& lines, std::uint32_t& number, char delimiter, std::vector<Field>& fields,
                    Diagnostics& diags, bool multiline = true);
// Splits a line at runs of spaces and tabs; a field that starts with '"'
// runs to the closing quote and may hold spaces (Altium's descriptions).
bool SplitWhitespace(const Lines& lines, std::uint32_t number, std::vector<Field>& fields, Diagnostics& diags);
// Cuts a line at the given code point columns (fixed-width reports): field i
// runs from starts[i] to starts[i + 1]. Returns false when a cut falls
// inside a word (the row does not follow the header's layout).
bool SplitFixed(const Lines& lines, std::uint32_t number, const std::vector<std::size_t>& starts,
                std::vector<Field>& fields);

// The delimiter of a delimited header line: the most frequent of ',', ';'
// and tab outside quotes (',' when there is none).
char GuessDelimiter(std::string_view line);

// ------------------------------------------------------------------ numbers

struct Length {
  enum class Status { kOk, kNotNumber, kUnknownUnit, kTooLarge };
  Status status = Status::kNotNumber;
  double mm = 0;            // rounded to kCadResolutionMm (kTooLarge: as read)
  std::string_view suffix;  // the unit as written after the number ("" when none)
};
// A length: a decimal number, optionally followed by a unit (mm, mil, mils,
// in, inch, inches, ", any case, spaces allowed before it); without one it is
// in `unit`. `decimal_comma`: "12,5" is 12.5 (lists whose fields are
// separated by ';', tabs or spaces).
Length ParseLength(std::string_view text, LengthUnit unit, bool decimal_comma);
// An angle in degrees, optionally followed by "deg" or "°".
std::optional<double> ParseAngle(std::string_view text, bool decimal_comma);
// A unit name: mm, mil, mils, in, inch, inches (any case).
std::optional<LengthUnit> UnitFromName(std::string_view name);

// top/t/front/f.cu/toplayer/top layer and bottom/b/bot/back/b.cu/
// bottomlayer/bottom layer, any case.
std::optional<Side> ParseSide(std::string_view text);
// A DNP column's "do not place" marks: yes, y, true, 1, x, dnp, dnf, dni,
// excluded (any case); no/n/false/0/empty mean place it.
std::optional<bool> ParseDnp(std::string_view text);

// ------------------------------------------------------------------ column names

// A column name split into its base (lowercase, without spaces, '-', '_',
// '.') and a unit written after it: "Center-X(mil)" -> centerx, mil;
// "X (mm)" -> x, mm. `unit_text` holds an unknown unit as written.
struct ColumnName {
  std::string base;
  std::optional<LengthUnit> unit;
  std::string unit_text;  // non-empty when the parenthesised unit is not one smtcal knows
};
ColumnName NormaliseColumnName(std::string_view name);


// Case-insensitive glob match: '*' any run, '?' one code point; the rest
// compared ASCII-case-insensitively.
bool GlobMatch(std::string_view pattern, std::string_view text);

// A feeder's package pattern against a package as CAD tools write it
// (docs/import.md, "Feeders"):
//   - a chip size code ("0805", "0402", "01005", or metric "2012Metric")
//     matches every package of that size, however the tool spells it:
//     KiCad's C_0805_2012Metric, EasyEDA's C0805, Altium's 0805 and IPC-7351
//     names such as CAPC2012X135N or RESC2012X65N (metric sizes after an
//     IPC family, or before "Metric"); "0603" is the imperial 0603 and never
//     the metric one (C_0201_0603Metric is an 0201);
//   - anything else is a glob (GlobMatch) in which '-', '_' and spaces do
//     not count, so "SOT-23" matches SOT23 and SOT_23, "C_0805*" C0805.
bool PackageMatch(std::string_view pattern, std::string_view package);

// The imperial chip size a package name holds ("0805" for
// C_0805_2012Metric and CAPC2012X135N), or "" when it names none.
std::string_view ChipSize(std::string_view package);

}  // namespace smtcal::cad
