// KiCad's placement lists (pcbnew "Fabrication outputs > Component
// placement", kicad-cli pcb export pos):
//
// ASCII .pos, both header generations:
//   ### Module positions - created on ... ###        (KiCad 6 and older)
//   ### Printed by Pcbnew version 6.0.11+dfsg-1
//   ### Footprint positions - created on ... ###     (KiCad 7 and newer)
//   ### Printed by KiCad version 8.0.3
//   ## Unit = mm, Angle = deg.                        (or "inches")
//   ## Side : All
//   # Ref     Val       Package         PosX       PosY       Rot  Side
//   C1        100n      C_0603_1608     123.4500   -67.8900   90.0000  top
//   ## End
// Columns are padded with spaces counted in bytes, so a UTF-8 value (Ω)
// shifts the alignment: the rows are split at blanks, never by position.
//
// CSV: Ref,Val,Package,PosX,PosY,Rot,Side with the strings quoted; the file
// does not state its unit (mm unless exported in inches: --units in) nor
// KiCad's version.
//
// Bottom sides (KiCad's place_file_exporter.cpp of each version; checked on
// lists KiCad 6.0.11 wrote, tests/golden/import-data/generate_kicad_lists.py):
// the .pos of KiCad 6 and older and the CSV of KiCad 6 write bottom-side x
// negated; KiCad 5's CSV does not; KiCad 7 and later negate only when asked
// ("Use negative X coordinates for footprints on bottom layer", off by
// default). Every version writes the rotation as seen from the top. The
// version line is read here; cad_bottom.cpp decides.
#include <fmt/format.h>

#include "frontend/cad/cad_table.h"

namespace smtcal::cad {
namespace {

std::vector<ColumnAlias> KicadAliases() {
  return MakeAliases({{Column::kDesignator, {"Ref"}},
                      {Column::kValue, {"Val"}},
                      {Column::kPackage, {"Package"}},
                      {Column::kX, {"PosX"}},
                      {Column::kY, {"PosY"}},
                      {Column::kRotation, {"Rot"}},
                      {Column::kSide, {"Side"}},
                      {Column::kDnp, {"DNP"}}});
}

std::array<bool, kColumnCount> KicadRequired() {
  return RequiredColumns({Column::kDesignator, Column::kX, Column::kY, Column::kRotation});
}

// "### Printed by Pcbnew version 6.0.11+dfsg-1", "### Printed by KiCad
// version 8.0.3", "### Printed by Pcbnew version kicad (5.1.9)-1": the
// version is the first number with a '.' after the word "version".
void KicadVersionLine(const Lines& lines, std::uint32_t number, ToolVersion& version) {
  std::string_view text = lines.Text(number);
  if (!text.starts_with("### Printed by")) return;
  std::size_t word = text.find("version");
  if (word == std::string_view::npos) return;
  std::size_t begin = text.find_first_not_of(" \t", word + 7);
  if (begin == std::string_view::npos) return;
  std::string_view rest = text.substr(begin);
  while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\t')) rest.remove_suffix(1);
  for (std::size_t i = 0; i < rest.size(); ++i) {
    if (rest[i] < '0' || rest[i] > '9') continue;
    std::size_t end = i;
    while (end < rest.size() && rest[end] >= '0' && rest[end] <= '9') ++end;
    if (end >= rest.size() || rest[end] != '.' || end - i > 4) {
      i = end;
      continue;
    }
    version.text = std::string(rest);
    version.major = std::stoi(std::string(rest.substr(i, end - i)));
    version.range = lines.Range(number, begin, rest.size());
    return;
  }
}

// "## Unit = mm, Angle = deg." states the unit of PosX/PosY.
bool KicadPreamble(const Lines& lines, std::uint32_t number, Preamble& preamble, Diagnostics& diags) {
  KicadVersionLine(lines, number, preamble.version);
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
  preamble.unit = StatedUnit{*parsed, lines.Range(number, unit_at, unit_length)};
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
  dialect.preamble = KicadPreamble;
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
