// The table reader of the header-driven CAD list families (see cad_table.h).
//
// Layout of a list: preamble lines (the family's hook may read a unit from
// them), the header line (the first line that names a designator column and
// an x column), then data rows. Blank lines, '#' comments, rules of '=' or
// '-' and rows whose fields are all empty are skipped wherever they are.
// Units, in order of precedence: a unit written after a value ("12.5mm"),
// a unit in the column's name ("Center-X(mil)"), the unit the preamble
// states, --units, mm.
#include "frontend/cad/cad_table.h"

#include <algorithm>

#include <fmt/format.h>

#include "calibration/tolerances.h"

namespace smtcal::cad {
namespace {

std::string_view ColumnTitle(Column column) {
  switch (column) {
    case Column::kDesignator: return "designator";
    case Column::kValue: return "value";
    case Column::kPackage: return "package";
    case Column::kX: return "x";
    case Column::kY: return "y";
    case Column::kRotation: return "rotation";
    case Column::kSide: return "side";
    case Column::kDnp: return "DNP";
  }
  return "?";
}

const ColumnAlias* FindAlias(const std::vector<ColumnAlias>& aliases, std::string_view base) {
  for (const ColumnAlias& alias : aliases) {
    if (alias.base == base) return &alias;
  }
  return nullptr;
}

// "'Mid X', 'Center-X' or 'X'": the names a column goes by, for messages.
std::string AliasList(const std::vector<ColumnAlias>& aliases, Column column) {
  std::vector<std::string> names;
  for (const ColumnAlias& alias : aliases) {
    if (alias.column == column) names.push_back(fmt::format("'{}'", alias.display));
  }
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  return text;
}

// A header split at blanks may have cut two-word names ("Mid X", "Ref Y"):
// join a word with the next when the pair is a column name and the word
// alone is not.
void JoinTwoWordNames(std::vector<Field>& fields, const std::vector<ColumnAlias>& aliases) {
  std::vector<Field> joined;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (i + 1 < fields.size() && !FindAlias(aliases, NormaliseColumnName(fields[i].text).base) &&
        FindAlias(aliases, NormaliseColumnName(fields[i].text + " " + fields[i + 1].text).base)) {
      Field field = fields[i];
      field.text += " " + fields[i + 1].text;
      const SourceRange& next = fields[i + 1].range;
      field.range.length = next.begin.column + next.length - field.range.begin.column;
      joined.push_back(std::move(field));
      ++i;
      continue;
    }
    joined.push_back(fields[i]);
  }
  fields = std::move(joined);
}

class TableReader final : public ListReader {
 public:
  TableReader(const Lines& lines, Dialect dialect, const ReadOptions& options, Diagnostics& diags)
      : ListReader(dialect.format), lines_(lines), dialect_(std::move(dialect)), options_(options), diags_(diags) {
    index_.fill(-1);
  }

  bool Start() {
    if (dialect_.fixed_columns) {
      for (int c = 0; c < kColumnCount; ++c) index_[c] = (*dialect_.fixed_columns)[c];
      field_count_ = static_cast<std::size_t>(*std::max_element(index_.begin(), index_.end()) + 1);
      delimiter_ = options_.delimiter.value_or(FirstDelimiter());
      header_line_ = 0;
    } else if (!FindHeader()) {
      return false;
    }
    ReadUnits();
    tool_version_ = preamble_.version;
    decimal_comma_ = delimiter_ != ',';
    next_line_ = header_line_ + 1;
    return true;
  }

  bool Next(Row& row) override {
    while (next_line_ <= lines_.count() && !diags_.limit_reached()) {
      std::uint32_t number = next_line_;
      if (lines_.IsFiller(number)) {
        ++next_line_;
        continue;
      }
      bool split = SplitRecord(lines_, number, delimiter_, fields_, diags_);
      next_line_ = number + 1;
      if (split && std::all_of(fields_.begin(), fields_.end(), [](const Field& f) { return f.text.empty(); })) {
        continue;  // ",,,,": a spreadsheet's empty row
      }
      ++rows_read_;
      const std::size_t errors_before = diags_.error_count();
      skipped_row_ = false;
      if (split && FitFields(number) && ReadRow(number, row) && diags_.error_count() == errors_before) {
        return true;
      }
      if (skipped_row_ && diags_.error_count() == errors_before) {
        lines_without_designator_.push_back(number);
        continue;
      }
      ++rows_with_errors_;
    }
    return false;
  }

 private:
  char FirstDelimiter() const {
    for (std::uint32_t n = 1; n <= lines_.count(); ++n) {
      if (!lines_.IsFiller(n)) return GuessDelimiterOrBlank(lines_.Text(n));
    }
    return ',';
  }

  // ',' ';' or tab when the line has one outside quotes, else ' ' (blanks).
  static char GuessDelimiterOrBlank(std::string_view line) {
    char delimiter = GuessDelimiter(line);
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      if (!quoted && c == delimiter) return delimiter;
    }
    return ' ';
  }

  bool FindHeader() {
    std::vector<Field> fields;
    Diagnostics quiet(diags_.sources());  // lines before the header are not held to CSV rules
    for (std::uint32_t number = 1; number <= lines_.count(); ++number) {
      if (dialect_.preamble != nullptr && !dialect_.preamble(lines_, number, preamble_, diags_)) return false;
      if (dialect_.hash_header && SplitHashHeader(number, fields, quiet) && IsHeader(fields)) {
        return TakeHeader(number, ' ', fields);
      }
      if (lines_.IsFiller(number)) continue;
      char delimiter = options_.delimiter.value_or(GuessDelimiterOrBlank(lines_.Text(number)));
      std::uint32_t end = number;
      if (!SplitRecord(lines_, end, delimiter, fields, quiet)) continue;
      if (delimiter == ' ') JoinTwoWordNames(fields, dialect_.aliases);
      if (IsHeader(fields)) return TakeHeader(number, delimiter, fields);
    }
    std::string expected;
    for (Column column : {Column::kDesignator, Column::kX, Column::kY}) {
      expected += (expected.empty() ? "" : "; ") + AliasList(dialect_.aliases, column);
    }
    diags_.Report(DiagKind::CadNoHeader, lines_.Range(1, 0, 1), FormatTitle(format_), expected);
    return false;
  }

  // KiCad's "# Ref Val Package ..." header: the words after the '#'.
  bool SplitHashHeader(std::uint32_t number, std::vector<Field>& fields, Diagnostics& quiet) {
    std::string_view text = lines_.Text(number);
    std::size_t first = text.find_first_not_of(" \t");
    if (first == std::string_view::npos || !text.substr(first).starts_with("# ")) return false;
    if (!SplitWhitespace(lines_, number, fields, quiet) || fields.empty()) return false;
    fields.erase(fields.begin());
    JoinTwoWordNames(fields, dialect_.aliases);
    return true;
  }

  bool IsHeader(const std::vector<Field>& fields) const {
    return MentionsColumn(fields, dialect_.aliases, Column::kDesignator) &&
           MentionsColumn(fields, dialect_.aliases, Column::kX);
  }

  bool TakeHeader(std::uint32_t number, char delimiter, const std::vector<Field>& fields) {
    header_line_ = number;
    delimiter_ = delimiter;
    field_count_ = fields.size();
    std::array<int, kColumnCount> rank;
    rank.fill(1 << 20);
    bool ok = true;
    for (std::size_t f = 0; f < fields.size(); ++f) {
      ColumnName name = NormaliseColumnName(fields[f].text);
      header_names_.push_back(fields[f].text);
      starts_.push_back(fields[f].start);
      const ColumnAlias* alias = FindAlias(dialect_.aliases, name.base);
      if (alias == nullptr) continue;  // a column smtcal does not need (Description, Height, ...)
      int c = static_cast<int>(alias->column);
      if (!name.unit_text.empty()) {
        diags_.Report(DiagKind::CadUnknownUnit, fields[f].range, Printable(name.unit_text),
                      fmt::format(" in column name '{}'", Printable(fields[f].text)));
        ok = false;
      }
      if (index_[c] >= 0 && alias->rank == rank[c]) {
        diags_.Report(DiagKind::CadDuplicateColumn, fields[f].range, Printable(fields[f].text), ColumnTitle(alias->column),
                      Printable(fields[static_cast<std::size_t>(index_[c])].text));
        ok = false;
        continue;
      }
      if (alias->rank < rank[c]) {
        rank[c] = alias->rank;
        index_[c] = static_cast<int>(f);
        column_unit_[c] = name.unit;
        if (name.unit) column_unit_range_[c] = fields[f].range;
      }
    }
    for (int c = 0; c < kColumnCount; ++c) {
      if (!dialect_.required[c] || index_[c] >= 0) continue;
      diags_.Report(DiagKind::CadMissingColumn, lines_.Range(number, 0, lines_.Text(number).size()),
                    FormatTitle(format_), ColumnTitle(static_cast<Column>(c)),
                    AliasList(dialect_.aliases, static_cast<Column>(c)));
      ok = false;
    }
    return ok;
  }

  // The list's own unit (preamble or column names) against --units.
  void ReadUnits() {
    std::optional<StatedUnit> stated = preamble_.unit;
    for (int c : {static_cast<int>(Column::kX), static_cast<int>(Column::kY)}) {
      if (column_unit_[c] && !stated) stated = StatedUnit{*column_unit_[c], column_unit_range_[c]};
    }
    unit_ = stated ? stated->unit : options_.units.value_or(LengthUnit::kMm);
    if (stated && options_.units && *options_.units != stated->unit) {
      diags_.Report(DiagKind::CadUnitsIgnored, stated->range, UnitName(stated->unit), UnitName(*options_.units));
    }
  }

  // Matches the row's fields to the header's columns: extra empty fields at
  // the end are dropped; rows of fixed-width reports whose words do not
  // split cleanly are cut at the header's columns.
  bool FitFields(std::uint32_t number) {
    while (fields_.size() > field_count_ && fields_.back().text.empty()) fields_.pop_back();
    if (fields_.size() == field_count_) return true;
    if (dialect_.fixed_width && delimiter_ == ' ' && SplitFixed(lines_, number, starts_, fields_)) return true;
    std::string detail;
    if (fields_.size() < field_count_) {
      std::vector<std::string> missing(header_names_.begin() + static_cast<long>(fields_.size()), header_names_.end());
      detail = "missing: " + fmt::format("{}", fmt::join(missing, ", "));
    } else {
      detail = "the first extra field is shown";
    }
    SourceRange at = fields_.size() > field_count_ ? fields_[field_count_].range : RowRange(lines_, number);
    if (fields_.size() < field_count_) {
      at = SourceRange(lines_.At(number, lines_.Text(number).size()));
    }
    diags_.Report(DiagKind::CadFieldCount, at, fields_.size(), field_count_, Printable(detail));
    return false;
  }

  const Field* FieldOf(Column column) const {
    int index = index_[static_cast<int>(column)];
    if (index < 0 || static_cast<std::size_t>(index) >= fields_.size()) return nullptr;
    return &fields_[static_cast<std::size_t>(index)];
  }

  std::string ColumnLabel(Column column) const {
    int index = index_[static_cast<int>(column)];
    if (index >= 0 && static_cast<std::size_t>(index) < header_names_.size()) {
      return Printable(header_names_[static_cast<std::size_t>(index)]);
    }
    return fmt::format("{}", index + 1);
  }

  void Text(Column column, std::string& text, SourceRange& range, std::uint32_t number) {
    const Field* field = FieldOf(column);
    text = field != nullptr ? field->text : std::string();
    range = field != nullptr ? field->range : RowRange(lines_, number);
  }

  std::optional<double> LengthOf(Column column) {
    const Field* field = FieldOf(column);
    LengthUnit unit = column_unit_[static_cast<int>(column)].value_or(unit_);
    Length length = ParseLength(field->text, unit, decimal_comma_);
    if (length.status == Length::Status::kOk) return length.mm;
    ReportBadLength(length, *field, ColumnLabel(column), delimiter_, diags_);
    return std::nullopt;
  }

  bool ReadRow(std::uint32_t number, Row& row) {
    row.line = number;
    Text(Column::kDesignator, row.designator, row.designator_range, number);
    Text(Column::kValue, row.value, row.value_range, number);
    Text(Column::kPackage, row.package, row.package_range, number);
    bool ok = true;
    if (row.designator.empty()) {
      if (options_.skip_empty_designators) {
        diags_.Report(DiagKind::CadSkippedEmptyDesignator, RowRange(lines_, number));
        skipped_row_ = true;
      } else {
        diags_.Report(DiagKind::CadEmptyDesignator, row.designator_range);
      }
      ok = false;
    }
    std::optional<double> x = LengthOf(Column::kX), y = LengthOf(Column::kY);
    row.x_range = FieldOf(Column::kX)->range;
    row.y_range = FieldOf(Column::kY)->range;
    row.rotation_deg = 0;
    row.rotation_range = RowRange(lines_, number);
    if (const Field* rotation = FieldOf(Column::kRotation)) {
      row.rotation_range = rotation->range;
      std::optional<double> angle = ParseAngle(rotation->text, decimal_comma_);
      if (angle) {
        row.rotation_deg = *angle;
      } else {
        diags_.Report(DiagKind::CadBadNumber, rotation->range, Printable(rotation->text), ColumnLabel(Column::kRotation),
                      rotation->text.empty() ? " (the field is empty)" : "");
        ok = false;
      }
    }
    row.side = options_.side_without_column;
    row.side_given = false;
    row.side_range = RowRange(lines_, number);
    if (const Field* side = FieldOf(Column::kSide)) {
      row.side_range = side->range;
      if (std::optional<Side> parsed = ParseSide(side->text)) {
        row.side = *parsed;
        row.side_given = true;
      } else {
        diags_.Report(DiagKind::CadBadSide, side->range, Printable(side->text));
        ok = false;
      }
    }
    row.dnp = false;
    row.dnp_range = RowRange(lines_, number);
    if (const Field* dnp = FieldOf(Column::kDnp)) {
      row.dnp_range = dnp->range;
      if (std::optional<bool> parsed = ParseDnp(dnp->text)) {
        row.dnp = *parsed;
      } else {
        diags_.Report(DiagKind::CadBadDnp, dnp->range, Printable(dnp->text));
        ok = false;
      }
    }
    if (!x || !y) return false;
    row.x_mm = *x;
    row.y_mm = *y;
    return ok;
  }

  Lines lines_;
  Dialect dialect_;
  ReadOptions options_;
  Diagnostics& diags_;
  Preamble preamble_;
  bool skipped_row_ = false;  // the row just read was left out (no designator), not wrong
  std::uint32_t header_line_ = 0;
  std::uint32_t next_line_ = 1;
  char delimiter_ = ',';
  bool decimal_comma_ = false;
  std::size_t field_count_ = 0;
  std::array<int, kColumnCount> index_{};
  std::array<std::optional<LengthUnit>, kColumnCount> column_unit_{};
  std::array<SourceRange, kColumnCount> column_unit_range_{};
  std::vector<std::string> header_names_;
  std::vector<std::size_t> starts_;
  std::vector<Field> fields_;
};

}  // namespace

std::vector<ColumnAlias> MakeAliases(std::initializer_list<ColumnNames> names) {
  std::vector<ColumnAlias> aliases;
  for (const ColumnNames& column : names) {
    for (std::size_t rank = 0; rank < column.ranked.size(); ++rank) {
      std::string_view equal = column.ranked[rank];
      while (!equal.empty()) {
        std::size_t bar = std::min(equal.find('|'), equal.size());
        std::string_view display = equal.substr(0, bar);
        aliases.push_back({NormaliseColumnName(display).base, std::string(display), column.column, static_cast<int>(rank)});
        equal.remove_prefix(std::min(bar + 1, equal.size()));
      }
    }
  }
  return aliases;
}

std::array<bool, kColumnCount> RequiredColumns(std::initializer_list<Column> columns) {
  std::array<bool, kColumnCount> required{};
  for (Column c : columns) required[static_cast<int>(c)] = true;
  return required;
}

bool MentionsColumn(const std::vector<Field>& fields, const std::vector<ColumnAlias>& aliases, Column column) {
  for (const Field& field : fields) {
    const ColumnAlias* alias = FindAlias(aliases, NormaliseColumnName(field.text).base);
    if (alias != nullptr && alias->column == column) return true;
  }
  return false;
}

bool SplitRecord(const Lines& lines, std::uint32_t& number, char delimiter, std::vector<Field>& fields,
                 Diagnostics& diags) {
  if (delimiter == ' ') return SplitWhitespace(lines, number, fields, diags);
  return SplitDelimited(lines, number, delimiter, fields, diags);
}

SourceRange RowRange(const Lines& lines, std::uint32_t number) {
  std::string_view text = lines.Text(number);
  std::size_t first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) first = 0;
  return lines.Range(number, first, text.size() - first);
}

void ReportBadLength(const Length& length, const Field& field, std::string_view column, char delimiter,
                     Diagnostics& diags) {
  switch (length.status) {
    case Length::Status::kOk: return;
    case Length::Status::kNotNumber: {
      std::string hint;
      if (field.text.empty()) hint = " (the field is empty)";
      if (delimiter == ',' && field.text.find(',') != std::string::npos) {
        hint = "; this list separates its fields with ',', so a decimal comma cannot be told from a separator: write "
               "'.' or separate the fields with ';'";
      }
      diags.Report(DiagKind::CadBadNumber, field.range, Printable(field.text), column, hint);
      return;
    }
    case Length::Status::kUnknownUnit:
      diags.Report(DiagKind::CadUnknownUnit, field.range, Printable(length.suffix),
                   fmt::format(" in '{}'", Printable(field.text)));
      return;
    case Length::Status::kTooLarge:
      diags.Report(DiagKind::CadLengthTooLarge, field.range, Printable(field.text), column,
                   fmt::format("{:g}", length.mm), fmt::format("{:g}", kMaxLengthMm));
      return;
  }
}

std::unique_ptr<ListReader> OpenTable(const Lines& lines, Dialect dialect, const ReadOptions& options,
                                      Diagnostics& diags) {
  auto reader = std::make_unique<TableReader>(lines, std::move(dialect), options, diags);
  if (!reader->Start()) return nullptr;
  return reader;
}

}  // namespace smtcal::cad
