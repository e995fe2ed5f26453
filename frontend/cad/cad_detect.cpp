// Telling CAD list formats apart by their content, never by the file name
// (a ".csv" may hold a KiCad ASCII .pos). The signs, in order:
//   "### Module positions", "### Footprint positions", "## Unit =",
//   "# Ref "                                                        -> KiCad .pos
//   "Altium Designer Pick and Place", "Units used:"                 -> Altium
// and otherwise the first line with content, as a header:
//   Ref .. PosX (separated by blanks: .pos without its '#', else CSV) -> KiCad
//   RefDes .. X / Center X                                          -> DipTrace
//   Designator .. Mid X, Ref X, Pad X and Layer (not TB), delimited -> EasyEDA
//   Designator .. with Center-X, Ref X, Pad X or TB, or separated
//     by blanks                                                     -> Altium
//   Designator .. Mid X / PosX                                      -> JLCPCB CPL
// or, as a data row: name x y angle [value] package                 -> Eagle
#include <algorithm>

#include "base/field_text.h"
#include "frontend/cad/cad_table.h"

namespace smtcal::cad {
namespace {

// How many lines the signs are looked for in: every format's preamble is a
// dozen lines at most.
constexpr std::uint32_t kDetectLines = 40;

std::string_view Unquote(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  if (text.size() >= 2 && text.front() == '"' && text.back() == '"') text = text.substr(1, text.size() - 2);
  return text;
}

bool Names(const std::vector<Field>& fields, std::initializer_list<std::string_view> bases) {
  for (const Field& field : fields) {
    std::string base = NormaliseColumnName(field.text).base;
    if (std::find(bases.begin(), bases.end(), base) != bases.end()) return true;
  }
  return false;
}

bool LooksLikeEagleRow(const std::vector<Field>& fields) {
  if (fields.size() < 5) return false;
  for (std::size_t f = 1; f <= 3; ++f) {
    if (ParseLength(fields[f].text, LengthUnit::kMm, false).status != Length::Status::kOk) return false;
  }
  return ParseLength(fields[0].text, LengthUnit::kMm, false).status != Length::Status::kOk;
}

std::optional<Format> FromHeaderLine(const Lines& lines, std::uint32_t number, const SourceManager& sources) {
  std::string_view text = lines.Text(number);
  char delimiter = GuessDelimiter(text);
  bool blanks = std::count(text.begin(), text.end(), delimiter) == 0;
  std::vector<Field> fields;
  Diagnostics quiet(sources);
  if (!SplitRecord(lines, number, blanks ? ' ' : delimiter, fields, quiet)) return std::nullopt;
  if (Names(fields, {"ref"}) && Names(fields, {"posx"})) return blanks ? Format::kKicadPos : Format::kKicadCsv;
  if (Names(fields, {"refdes"}) && Names(fields, {"x", "centerx"})) return Format::kDipTrace;
  if (Names(fields, {"designator"})) {
    // EasyEDA keeps Protel's Mid/Ref/Pad columns with a Layer column (Altium's
    // older reports have TB instead), separated by tabs.
    if (!blanks && Names(fields, {"midx"}) && Names(fields, {"refx"}) && Names(fields, {"padx"}) &&
        Names(fields, {"layer"})) {
      return Format::kEasyEda;
    }
    bool altium_names = Names(fields, {"centerx", "refx", "padx", "tb"});
    if (blanks || altium_names) return Format::kAltium;
    if (Names(fields, {"midx", "posx"})) return Format::kJlcpcb;
  }
  if (blanks && LooksLikeEagleRow(fields)) return Format::kEagle;
  return std::nullopt;
}

}  // namespace

std::optional<Format> DetectFormat(const Lines& lines, const SourceManager& sources) {
  const std::uint32_t last = std::min(lines.count(), kDetectLines);
  // A preamble's signs, wherever they are in it.
  for (std::uint32_t number = 1; number <= last; ++number) {
    std::string lower = AsciiLowercase(Unquote(lines.Text(number)));
    if ((lower.starts_with("###") && lower.find("positions") != std::string::npos) ||
        lower.starts_with("## unit") || lower.starts_with("# ref ")) {
      return Format::kKicadPos;
    }
    if (lower.starts_with("altium designer pick and place") || lower.find("units used:") != std::string::npos) {
      return Format::kAltium;
    }
  }
  // Else the first line with content, as a header or (Eagle) a row.
  for (std::uint32_t number = 1; number <= last; ++number) {
    if (!lines.IsFiller(number)) return FromHeaderLine(lines, number, sources);
  }
  return std::nullopt;
}

}  // namespace smtcal::cad
