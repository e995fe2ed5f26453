// KiCad's placement lists (pcbnew "Fabrication outputs > Component
// placement", kicad-cli pcb export pos):
//
// ASCII .pos, both header generations:
//   ### Module positions - created on ... ###        (KiCad 5 and older)
//   ### Footprint positions - created on ... ###     (KiCad 6 and newer)
//   ## Unit = mm, Angle = deg.                        (or "inches")
//   ## Side : All
//   # Ref     Val       Package         PosX       PosY       Rot  Side
//   C1        100n      C_0603_1608     123.4500   -67.8900   90.0000  top
//   ## End
// Columns are padded with spaces counted in bytes, so a UTF-8 value (Ω)
// shifts the alignment: the rows are split at blanks, never by position.
//
// CSV: Ref,Val,Package,PosX,PosY,Rot,Side with the strings quoted; the file
// does not state its unit (mm unless exported in inches: --units in).
#include <fmt/format.h>

#include "frontend/cad/cad_table.h"

namespace smtcal::cad {
namespace {

std::vector<ColumnAlias> KicadAliases() {
  return {
      {"ref", "Ref", Column::kDesignator, 0},  {"val", "Val", Column::kValue, 0},
      {"package", "Package", Column::kPackage, 0}, {"posx", "PosX", Column::kX, 0},
      {"posy", "PosY", Column::kY, 0},         {"rot", "Rot", Column::kRotation, 0},
      {"side", "Side", Column::kSide, 0},      {"dnp", "DNP", Column::kDnp, 0},
  };
}

std::array<bool, kColumnCount> KicadRequired() {
  std::array<bool, kColumnCount> required{};
  for (Column c : {Column::kDesignator, Column::kX, Column::kY, Column::kRotation}) {
    required[static_cast<int>(c)] = true;
  }
  return required;
}

// "## Unit = mm, Angle = deg." states the unit of PosX/PosY.
bool KicadUnitLine(const Lines& lines, std::uint32_t number, std::optional<StatedUnit>& unit, Diagnostics& diags) {
  std::string_view text = lines.Text(number);
  if (!text.starts_with("## Unit")) return true;
  auto word_after = [&](std::size_t from) -> std::pair<std::size_t, std::size_t> {
    std::size_t eq = text.find('=', from);
    if (eq == std::string_view::npos) return {text.size(), 0};
    std::size_t begin = text.find_first_not_of(" \t", eq + 1);
    if (begin == std::string_view::npos) return {text.size(), 0};
    std::size_t end = text.find_first_of(", \t", begin);
    if (end == std::string_view::npos) end = text.size();
    return {begin, end - begin};
  };
  auto [unit_at, unit_length] = word_after(7);
  std::string_view unit_word = text.substr(unit_at, unit_length);
  std::optional<LengthUnit> parsed = UnitFromName(unit_word);
  if (!parsed) {
    diags.Report(DiagKind::CadUnknownUnit, lines.Range(number, unit_at, unit_length), Printable(unit_word),
                 " in the KiCad header");
    return false;
  }
  unit = StatedUnit{*parsed, lines.Range(number, unit_at, unit_length)};
  std::size_t angle = text.find("Angle", unit_at);
  if (angle != std::string_view::npos) {
    auto [angle_at, angle_length] = word_after(angle);
    std::string_view angle_word = text.substr(angle_at, angle_length);
    if (angle_word != "deg." && angle_word != "deg") {
      diags.Report(DiagKind::CadUnknownAngleUnit, lines.Range(number, angle_at, angle_length), Printable(angle_word));
      return false;
    }
  }
  return true;
}

}  // namespace

Dialect KicadPosDialect() {
  Dialect dialect;
  dialect.format = Format::kKicadPos;
  dialect.aliases = KicadAliases();
  dialect.required = KicadRequired();
  dialect.hash_header = true;
  dialect.preamble = KicadUnitLine;
  return dialect;
}

Dialect KicadCsvDialect() {
  Dialect dialect;
  dialect.format = Format::kKicadCsv;
  dialect.aliases = KicadAliases();
  dialect.required = KicadRequired();
  return dialect;
}

}  // namespace smtcal::cad
