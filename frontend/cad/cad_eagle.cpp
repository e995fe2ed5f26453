// Eagle's mountsmd.ulp lists: <board>.mnt (top) and <board>.mnb (bottom),
// no header, one part per line, fields separated by blanks:
//   C1 12.70 8.25 90 100n C0805
//   name x y angle value package        (mm; the part's pad centre)
// A value may be empty (five fields) or hold spaces (more than six: the
// fields between the angle and the package are the value). The list does not
// say its side; the caller passes it (ReadOptions::side_without_column).
#include <fmt/format.h>

#include "frontend/cad/cad_table.h"

namespace smtcal::cad {
namespace {

class EagleReader final : public ListReader {
 public:
  EagleReader(const Lines& lines, const ReadOptions& options, Diagnostics& diags)
      : ListReader(Format::kEagle), lines_(lines), options_(options), diags_(diags) {
    unit_ = options.units.value_or(LengthUnit::kMm);
  }

  bool Next(Row& row) override {
    while (next_line_ <= lines_.count() && !diags_.limit_reached()) {
      std::uint32_t number = next_line_++;
      if (lines_.IsFiller(number)) continue;
      ++rows_read_;
      const std::size_t errors_before = diags_.error_count();
      if (SplitWhitespace(lines_, number, fields_, diags_) && ReadRow(number, row) &&
          diags_.error_count() == errors_before) {
        return true;
      }
      ++rows_with_errors_;
    }
    return false;
  }

 private:
  bool ReadRow(std::uint32_t number, Row& row) {
    if (fields_.size() < 5) {
      diags_.Report(DiagKind::CadEagleFieldCount, RowRange(lines_, number), fields_.size());
      return false;
    }
    const Field& package = fields_.back();
    row.line = number;
    row.designator = fields_[0].text;
    row.designator_range = fields_[0].range;
    row.package = package.text;
    row.package_range = package.range;
    row.value.clear();
    row.value_range = package.range;
    if (fields_.size() > 5) {
      const Field& first = fields_[4];
      const Field& last = fields_[fields_.size() - 2];
      for (std::size_t f = 4; f + 1 < fields_.size(); ++f) row.value += (f == 4 ? "" : " ") + fields_[f].text;
      row.value_range = first.range;
      row.value_range.length = last.range.begin.column + last.range.length - first.range.begin.column;
    }
    bool ok = true;
    auto length = [&](const Field& field, std::string_view column, double& mm) {
      Length parsed = ParseLength(field.text, unit_, false);
      if (parsed.status != Length::Status::kOk) {
        ReportBadLength(parsed, field, column, ' ', diags_);
        ok = false;
      }
      mm = parsed.mm;
    };
    length(fields_[1], "x", row.x_mm);
    length(fields_[2], "y", row.y_mm);
    row.x_range = fields_[1].range;
    row.y_range = fields_[2].range;
    row.rotation_range = fields_[3].range;
    if (std::optional<double> angle = ParseAngle(fields_[3].text, false)) {
      row.rotation_deg = *angle;
    } else {
      diags_.Report(DiagKind::CadBadNumber, fields_[3].range, Printable(fields_[3].text), "angle", "");  // a blank-separated field is never empty
      ok = false;
    }
    row.side = options_.side_without_column;
    row.side_given = false;
    row.side_range = RowRange(lines_, number);
    row.dnp = false;
    row.dnp_range = row.side_range;
    return ok;
  }

  Lines lines_;
  ReadOptions options_;
  Diagnostics& diags_;
  std::uint32_t next_line_ = 1;
  std::vector<Field> fields_;
};

}  // namespace

std::unique_ptr<ListReader> OpenEagle(const Lines& lines, const ReadOptions& options, Diagnostics& diags) {
  return std::make_unique<EagleReader>(lines, options, diags);
}

}  // namespace smtcal::cad
