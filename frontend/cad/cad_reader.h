// Reading CAD placement lists (docs/import.md): the one door into the
// readers. OpenList detects the format by content (or takes the one named),
// reads the preamble and the header, and returns a reader that hands out one
// Row at a time, so a list is never held in memory twice.
//
// The families, one reader file each:
//   cad_kicad.cpp   KiCad ASCII .pos (both header generations, mm or inch) and KiCad CSV
//   cad_altium.cpp  Altium pick-and-place reports, text and CSV, both generations, and
//                   EasyEDA's (Protel's Mid/Ref/Pad layout, UTF-16 with tabs)
//   cad_csv.cpp     JLCPCB CPL / Fabrication Toolkit, DipTrace 3.x and 4.x, generic CSV
//   cad_eagle.cpp   Eagle mountsmd .mnt/.mnb (no header)
// The header-driven families share the table reader in cad_table.cpp;
// cad_detect.cpp tells the formats apart; cad_text.cpp splits and reads
// fields; cad_encoding.cpp decodes UTF-16 and Windows-1252 lists first;
// cad_bottom.cpp decides how a list writes its bottom side. Every data row
// becomes a Row or a diagnostic at its line.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "frontend/cad/cad_encoding.h"
#include "frontend/cad/cad_row.h"

namespace smtcal::cad {

// How the generic CSV's columns are found: per Column, a header name or a
// 1-based column number (all numbers: the list has no header line).
struct ColumnMapping {
  std::array<std::string, kColumnCount> columns;  // empty = not mapped
  SourceRange range;                              // where the mapping was given (unknown for the command line)
};

// Reads --columns "designator=Ref,x=X,y=Y,rotation=Rot" (keys: kColumnKeys;
// values header names or 1-based column numbers, not mixed). Returns the
// message for the user when the text is not a usable mapping.
std::optional<std::string> ParseColumnMapping(std::string_view text, ColumnMapping& mapping);

struct ReadOptions {
  std::optional<Format> format;     // nullopt: detect from the content
  std::optional<LengthUnit> units;  // lengths the list gives no unit for (default mm)
  std::optional<char> delimiter;    // nullopt: from the header line (',', ';', tab, or blanks)
  ColumnMapping mapping;            // kGenericCsv only
  Side side_without_column = Side::kTop;  // the side of rows when the list has no side column
  bool skip_empty_designators = false;    // a row without a designator: a warning and skipped, not an error
};

// What a list's preamble says about the tool that wrote it: KiCad's
// "### Printed by Pcbnew version 6.0.11" (the bottom-side convention
// depends on it, docs/import.md).
struct ToolVersion {
  std::string text;   // "6.0.11+dfsg-1" as written; empty when the list names none
  int major = 0;      // 6; 0 when unknown
  SourceRange range;  // where the list says so
};

class ListReader {
 public:
  virtual ~ListReader() = default;

  // The next data row, or false at the end of the list. A row with a
  // mistake is reported (at its line) and skipped; rows_with_errors counts it.
  virtual bool Next(Row& row) = 0;

  Format format() const { return format_; }
  LengthUnit unit() const { return unit_; }  // the list's length unit
  std::size_t rows_read() const { return rows_read_; }
  std::size_t rows_with_errors() const { return rows_with_errors_; }
  // Rows left out for having no designator (ReadOptions::skip_empty_designators).
  std::size_t rows_without_designator() const { return lines_without_designator_.size(); }
  const std::vector<std::uint32_t>& lines_without_designator() const { return lines_without_designator_; }
  const ToolVersion& tool_version() const { return tool_version_; }

 protected:
  explicit ListReader(Format format) : format_(format) {}
  Format format_;
  LengthUnit unit_ = LengthUnit::kMm;
  std::size_t rows_read_ = 0;
  std::size_t rows_with_errors_ = 0;
  std::vector<std::uint32_t> lines_without_designator_;
  ToolVersion tool_version_;
};

// Decodes the list registered as `file` to UTF-8 (cad_encoding.h): the id
// of the decoded text (`file` itself when it is UTF-8 already), or nullopt
// after reporting why it cannot be decoded. `encoding` tells which it was.
std::optional<std::uint32_t> DecodeList(std::uint32_t file, SourceManager& sources, Diagnostics& diags,
                                        TextEncoding& encoding);

// Opens the list registered as `file` in diags.sources(). Returns null after
// reporting why when the list cannot be read at all (unknown format, no
// header, missing columns, unknown units).
std::unique_ptr<ListReader> OpenList(std::uint32_t file, const ReadOptions& options, Diagnostics& diags);

}  // namespace smtcal::cad
