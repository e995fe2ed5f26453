// The shared row model of CAD placement lists (docs/import.md): whatever the
// EDA tool wrote, each data row becomes one Row: designator, value, package,
// position, rotation and side, each with the SourceRange of the field it came
// from so every later diagnostic can point at it. Lengths are converted to mm
// and rounded to kCadResolutionMm; rotations stay in degrees as written.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "base/diagnostics.h"

namespace smtcal::cad {

// The list formats smtcal reads (one reader per family, see cad_reader.h).
enum class Format {
  kKicadPos,    // KiCad ASCII .pos ("Module positions" / "Footprint positions")
  kKicadCsv,    // KiCad CSV: Ref,Val,Package,PosX,PosY,Rot,Side
  kJlcpcb,      // JLCPCB CPL and the KiCad Fabrication Toolkit's CSV
  kEasyEda,     // EasyEDA pick and place (UTF-16, tabs): Designator Footprint Mid X .. Layer Rotation Comment
  kAltium,      // Altium pick-and-place report, text or CSV, both generations
  kEagle,       // Eagle mountsmd.ulp .mnt/.mnb
  kDipTrace,    // DipTrace 3.x and 4.x CSV
  kGenericCsv,  // any CSV, columns named on the command line
};

// The --format names, in the order of the enum.
inline constexpr std::string_view kFormatNames[] = {"kicad-pos", "kicad-csv", "jlcpcb",   "easyeda",
                                                    "altium",    "eagle",     "diptrace", "csv"};
std::string_view FormatName(Format format);
// A person's name for the format: "KiCad .pos", "JLCPCB CPL", ...
std::string_view FormatTitle(Format format);
std::optional<Format> FormatFromName(std::string_view name);

enum class LengthUnit { kMm, kMil, kInch };
std::string_view UnitName(LengthUnit unit);  // mm | mil | in
double MmPer(LengthUnit unit);               // 1, 0.0254, 25.4

enum class Side { kTop, kBottom };
std::string_view SideName(Side side);  // top | bottom

// How a list writes the x of its bottom-side parts: as seen from the top
// through the board (most tools), or negated, as seen from the bottom
// (KiCad 6 and older always; KiCad 7 and later when "negative X" is asked
// for). Rotations are a separate matter (BottomRotation in cad_to_program.h).
enum class BottomPositions { kTopView, kNegatedX };

// Which column of a list a field plays; also the --columns keys.
enum class Column { kDesignator, kValue, kPackage, kX, kY, kRotation, kSide, kDnp };
inline constexpr int kColumnCount = 8;
inline constexpr std::string_view kColumnKeys[] = {"designator", "value", "package", "x",
                                                   "y",          "rotation", "side", "dnp"};

struct Row {
  std::uint32_t line = 0;  // the row's (first) line
  std::string designator;
  std::string value;    // empty when the list has no value column
  std::string package;  // empty when the list has no package column
  double x_mm = 0;
  double y_mm = 0;
  double rotation_deg = 0;  // as the list writes it (not normalised)
  Side side = Side::kTop;
  bool side_given = false;  // false: the list has no side column (side from the options)
  bool dnp = false;         // a DNP column marks it "do not place"
  SourceRange designator_range;
  SourceRange value_range;  // the row's start when there is no such column
  SourceRange package_range;
  SourceRange x_range;
  SourceRange y_range;
  SourceRange rotation_range;
  SourceRange side_range;
  SourceRange dnp_range;
};

}  // namespace smtcal::cad
