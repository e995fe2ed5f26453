// Altium Designer pick-and-place reports, text (.txt) and CSV:
//
//   Altium Designer Pick and Place Locations
//   <project path>
//   ====...
//   File Design Information:
//   Date: ...   Units used: mil
//   Designator Comment Layer    Footprint Center-X(mil) Center-Y(mil) Rotation Description
//   J1         53261   TopLayer MOLEX-... 175.000       470.000       270      "Male Header, ..."
//
// The CSV report has the same lines with every field quoted. The text
// report pads its columns with spaces; rows are split at blanks (quoted
// descriptions kept whole), and a row whose words do not match the header
// (a Comment with a space in it) is cut at the header's column positions.
// Older reports (Protel, DXP) have "Mid X  Mid Y  Ref X  Ref Y  Pad X  Pad Y
// TB" columns with the unit written after every value ("1190mil"): the
// part's centre is Mid X/Y (Center-X/Y in newer reports), Ref is the
// footprint origin and Pad pin 1, read only when the centre is missing.
#include <fmt/format.h>

#include "frontend/cad/cad_table.h"

namespace smtcal::cad {
namespace {

// "Units used: mil" (possibly quoted, in the CSV report).
bool AltiumUnitLine(const Lines& lines, std::uint32_t number, Preamble& preamble, Diagnostics& diags) {
  std::string_view text = lines.Text(number);
  constexpr std::string_view kKey = "Units used:";
  std::size_t key = text.find(kKey);
  if (key == std::string_view::npos) return true;
  std::size_t begin = text.find_first_not_of(" \t", key + kKey.size());
  if (begin == std::string_view::npos) return true;
  std::size_t end = text.find_first_of(" \t\",", begin);
  if (end == std::string_view::npos) end = text.size();
  std::string_view word = text.substr(begin, end - begin);
  std::optional<LengthUnit> parsed = UnitFromName(word);
  if (!parsed) {
    diags.Report(DiagKind::CadUnknownUnit, lines.Range(number, begin, word.size()), Printable(word),
                 " in the report's 'Units used'");
    return false;
  }
  preamble.unit = StatedUnit{*parsed, lines.Range(number, begin, word.size())};
  return true;
}

}  // namespace

Dialect AltiumDialect() {
  Dialect dialect;
  dialect.format = Format::kAltium;
  dialect.aliases = MakeAliases({{Column::kDesignator, {"Designator"}},
                                 {Column::kValue, {"Comment"}},
                                 {Column::kPackage, {"Footprint"}},
                                 {Column::kX, {"Center-X|Mid X", "Ref X", "Pad X"}},
                                 {Column::kY, {"Center-Y|Mid Y", "Ref Y", "Pad Y"}},
                                 {Column::kRotation, {"Rotation"}},
                                 {Column::kSide, {"Layer|TB"}},
                                 {Column::kDnp, {"DNP"}}});
  dialect.required = RequiredColumns({Column::kDesignator, Column::kX, Column::kY, Column::kRotation});
  dialect.fixed_width = true;
  dialect.preamble = AltiumUnitLine;
  return dialect;
}

// EasyEDA (std and Pro, the editor behind JLCPCB) writes Protel's layout
// too, as UTF-16 LE text with a byte order mark and tabs between fields
// (cad_encoding.h decodes it), values with their unit ("62.6mm"):
//   Designator<TAB>Footprint<TAB>Mid X<TAB>Mid Y<TAB>Ref X<TAB>Ref Y<TAB>Pad X<TAB>Pad Y<TAB>Layer<TAB>Rotation<TAB>Comment
//   C1<TAB>C0805<TAB>62.6mm<TAB>71.25mm<TAB>...<TAB>T<TAB>0<TAB>10uF
// Mid X/Y is the part's centre; layers T/B.
Dialect EasyEdaDialect() {
  Dialect dialect = AltiumDialect();
  dialect.format = Format::kEasyEda;
  dialect.fixed_width = false;
  dialect.preamble = nullptr;
  return dialect;
}

}  // namespace smtcal::cad
