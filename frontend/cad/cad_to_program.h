// From CAD rows to a .place program (`smtcal import`, docs/import.md).
//
// The importer takes rows one at a time (Add), decides for each whether it is
// placed or skipped (other side, DNP, excluded, no feeder with
// --skip-unmapped; each skip is a warning at the row), and Finish builds the
// program:
//   Program, Units mm, Fixture <fixture>, Vacuum <n>
//   a Local per board of the panel, In the fixture
//   the feeders' pick points (robot base), as Points or Pallets
//   one Point per part and board, In its board's Local
//   Function Main with Cycle <fixture>: a Pick/Place pair per part, grouped
//   by feeder (in the feeders' order), designator, value and package in a
//   trailing comment.
// Every generated statement borrows the location of what caused it (the
// part's row, the feeder's table, the list's first line), so the IR passes
// the verifier and a later diagnostic points into the list.
//
// Geometry (all in the fixture frame, mm and degrees): a part at (x, y, θ)
// of the list is placed at (±x, ±y, place_z, u) in its board's Local, where
// the mirror flips the coordinate across the board's axis for the side that
// is turned over, and u is θ mapped by the mirror (180° - θ across x, -θ
// across y, unless the list already gives bottom rotations as seen from
// below), plus the feeder's rotation offset, normalised. Board (c, r) of
// the panel sits at origin + R(rotation) · ((c-1)·pitch_x, (r-1)·pitch_y).
#pragma once

#include <array>
#include <map>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "base/diagnostics.h"
#include "frontend/cad/cad_bottom.h"
#include "frontend/cad/cad_reader.h"
#include "frontend/cad/cad_row.h"
#include "frontend/feeders_toml.h"
#include "ir/ir.h"

namespace smtcal {

// Which board coordinate changes sign when the board is turned over to
// place its bottom side: x (turned about its y axis, the default), y, or none
// (the list already gives bottom-side positions as seen from below).
enum class ImportMirror { kNone, kX, kY };
// How the list writes the rotation of bottom-side parts.
enum class BottomRotation { kTopView, kBottomView };
// Rotations of the program: (-180, 180] or [0, 360).
enum class AngleRange { kSigned, kPositive };

struct ImportOptions {
  std::optional<cad::Side> side;  // nullopt: the only side the list has parts on
  std::optional<ImportMirror> mirror;  // nullopt: none for top, x for bottom
  // nullopt: decided from the list (cad_bottom.h)
  std::optional<cad::BottomPositions> bottom_positions;
  BottomRotation bottom_rotation = BottomRotation::kTopView;
  AngleRange angles = AngleRange::kSigned;
  double origin_x_mm = 0;  // the board origin in the fixture frame
  double origin_y_mm = 0;
  // false: the origin was not given, so the parts (of the whole panel) are
  // centred on `centre_spot` (a point of the fixture frame: the centre of
  // the largest calibrated region on the fixture), or, without one, the
  // origin is (0, 0); the summary says which.
  bool origin_given = true;
  // The board's outline in the list's coordinates seen from the top (x0, y0,
  // x1, y1; --board). nullopt: the list gives none, so the bounding box of
  // the list's parts (both sides) stands for it, with a warning when it
  // decides where the board goes. A part outside a given outline is an error.
  std::optional<std::array<double, 4>> board;
  // The fixture's pocket for the board (the cell's pocket_x_mm, pocket_y_mm:
  // x lo, y lo, x hi, y hi in the fixture frame). Without --origin the
  // board's outline, turned over for the bottom side and turned by
  // rotation_deg, goes into its lower left corner, so both sides of one
  // board use the same pocket.
  std::optional<std::array<double, 4>> pocket;
  SourceRange pocket_range;  // the pocket's keys in the cell
  std::optional<std::array<double, 2>> centre_spot;
  std::string centre_spot_name;  // "region 'layer1'", for the program and the summary
  // The cell and the fixture the board is on (the fixture's nominal pose):
  // when the cell has calibrated regions, every part as placed must land in
  // one, or the import stops before it writes anything
  // (ImportBoardOverRegion names the parts' and the region's extents and
  // the --origin that centres them on it). Null: not checked.
  const cell::Cell* cell = nullptr;
  const cell::Fixture* cell_fixture = nullptr;
  double rotation_deg = 0;  // the board's x axis against the fixture's
  int columns = 1;          // panel
  int rows = 1;
  double pitch_x_mm = 0;
  double pitch_y_mm = 0;
  double place_z_mm = 0;  // z of the placements in the board frame (the robot z of the board's top)
  int vacuum = 8;         // the program's Vacuum output
  bool skip_unmapped = false;
  bool keep_dnp = false;
  bool default_excludes = true;  // FID*, *Fiducial*, *MountingHole* (docs/import.md)
  std::vector<std::string> exclude_designators;  // globs
  std::vector<std::string> exclude_packages;
  cad::TextEncoding encoding = cad::TextEncoding::kUtf8;  // what the list was decoded from (cad_encoding.h)
  std::string program_name;  // a valid name; the Program line
  std::string fixture;       // the cell fixture the board is on
  std::vector<std::string> header_lines;  // comment lines opening the program (what was imported, how)
  bool keep_fates = false;  // keep every row's fate for the import report (--report)
};

// Why rows were not placed.
enum class SkipReason { kOtherSide, kDnp, kExcluded, kUnmapped, kNoDesignator, kCount };
std::string_view SkipReasonName(SkipReason reason);

// Rows skipped for one reason and one rule: "no feeder holds package
// 'C_0402_1005Metric', value '100n'" and every designator it left out.
struct SkipGroup {
  SkipReason reason = SkipReason::kUnmapped;
  std::string why;                 // the rule, for the summary
  std::vector<std::string> names;  // designators as the list writes them (printable); "line N" without one
};

// What became of one row of the list (the import report, --report).
struct RowFate {
  cad::Row row;  // as the list writes it (only its line for a row without a designator)
  bool placed = false;
  SkipReason reason = SkipReason::kCount;  // when skipped
  std::string why;                         // when skipped: the rule
  // When placed: the feeder, its lane or pocket (0: its single pick point),
  // and the point in the program (on the first board of a panel) with its
  // board coordinates.
  std::string feeder;
  std::string slot_kind;  // "lane", "pocket" or ""
  int slot = 0;
  std::string point;
  std::array<double, 3> board_xyu{};  // x, y mm, u deg in the board's Local
};

// The feeder set-up sheet: which part goes in which feeder, lane or pocket.
// `smtcal import` fills it from the list; `smtcal setup-sheet` from a
// program's compile trace (backend/reports/setup_sheet.h, which prints both
// as text and CSV).
struct SetupSlot {
  std::string feeder;       // "?" for picks the sheet cannot place at a feeder (see note)
  std::string feeder_kind;  // "tape" or "tray"
  std::string slot_kind;    // "lane", "pocket" or "" (the feeder's single pick point)
  int slot = 0;
  std::array<double, 4> pick{};              // the pick point, robot base frame
  bool pick_known = true;                    // false: a Pick whose position only the run knows
  // The parts taken from it, in the order they are placed: designators
  // (first board of a panel; a pocket's part on a later board with it), or a
  // program's place targets as written ("R1 + X(dx) ×3" when placed 3 times).
  std::vector<std::string> designators;
  // What it holds: from the list (import: the distinct ones, in order of
  // appearance), or from the cell's feeder (a program: its package(s), the
  // lane's own on a bank with one package per lane, and its value).
  // The parts' own (the list's, a program's comments) first, then what the
  // feeders file's [[lane]] declares, then the feeder's own patterns.
  std::vector<std::string> values, packages;
  std::vector<std::string> part_numbers;  // a [[map]]'s, [[lane]]'s or the feeder's
  // Where the operator finds it: declared (`location`), else its row and
  // column on a pallet ("row 1 of 2, column 3 of 8"); "" for a single pick point.
  std::string location;
  std::optional<double> tape_width_mm, tape_pitch_mm;  // declared
  // Which way the part lies in the tape or pocket: the direction of its 0°
  // (as its CAD footprint draws it) in the robot base frame, degrees = the
  // pick's u less the rotation offset it is placed with; one per offset met.
  std::vector<double> in_tape_deg;
  // How far the nozzle turns the parts between pick and place (degrees,
  // (-180, 180]), each value once, in the order met.
  std::vector<double> turns_deg;
  std::size_t count = 0;  // picks per cycle (all boards of a panel)
  std::string note;       // why a row is special ("" for most)
};
struct SetupSheet {
  std::string program;  // the program's name
  std::string fixture;  // the fixture(s) its cycles are on
  std::size_t boards = 1;  // boards a cycle places (a panel's)
  std::string from;     // what the counts are of: "" for an import
  std::vector<SetupSlot> slots;  // feeder by feeder in the feeder order, slots ascending
  // The lot (--boards N): its boards (0: per cycle only), and the spares to
  // add to each slot's parts, a share of them rounded up (--spares).
  std::size_t lot_boards = 0;
  double spares_percent = 0;
  // Cycles the lot takes: its boards over the boards a cycle places, rounded up.
  std::size_t LotCycles() const { return boards == 0 ? 0 : (lot_boards + boards - 1) / boards; }
};

// A slot's description for the set-up sheet, from the feeders file and the
// feeder's geometry: its location, part number and tape (DescribeSlot
// leaves values, packages and counts alone). `k` is the pick point (0 or 1
// for a single one).
void DescribeSlot(SetupSlot& slot, const cad::FeederTable& feeders, std::size_t feeder, int k);

// An angle in degrees normalised into (-180, 180].
double SignedDegrees(double degrees);
// Adds `value` to `values` unless it is there (to 1e-9).
void AddDistinct(std::vector<double>& values, double value);

struct ImportSummary {
  std::size_t rows_read = 0;
  std::size_t rows_with_errors = 0;
  std::size_t parts_placed = 0;  // rows placed (on each board of the panel)
  std::size_t boards = 1;
  double origin_x_mm = 0;  // where the (first) board's origin went, in the fixture frame
  double origin_y_mm = 0;
  std::size_t feeders_used = 0;
  std::array<std::size_t, static_cast<int>(SkipReason::kCount)> skipped{};
  // Every skipped row, grouped by reason and rule, in the order of the
  // reasons and then of first appearance; the other side's rows are one
  // group that the summary prints as one line.
  std::vector<SkipGroup> skip_groups;
  cad::Side placed_side = cad::Side::kTop;
  // The board: its outline (list coordinates seen from the top) and how it
  // was found, and how its origin was chosen; empty when the import failed
  // before.
  std::string outline;  // "x 0..16.6, y 0..40.1 mm (--board)"
  std::string origin_how;  // "the board's lower left corner in the pocket of fixture Board (pocket_x_mm, pocket_y_mm)"
  std::string format;  // "KiCad CSV, mm" (", Windows-1252 text" when it was decoded)
  cad::TextEncoding encoding = cad::TextEncoding::kUtf8;
  // How the bottom side was read, when it is placed: "x negated in the list
  // (KiCad 6.0.11 writes them so (line 2)); rotations as seen from the top;
  // turned over about the board's y axis".
  std::string bottom;
  bool failed = false;  // errors stopped the import: nothing is placed
};
// "import: 12 rows read: 9 placed (x 4 boards = 36 placements, 3 feeders),
// 3 skipped (2 other side, 1 DNP)" and the like, one line each.
std::string FormatImportSummary(const ImportSummary& summary);

class CadImporter {
 public:
  // `list_file` is the list's SourceManager id (locations of generated
  // statements); `feeders` must outlive the importer.
  CadImporter(const cad::FeederTable& feeders, ImportOptions options, std::uint32_t list_file, Diagnostics& diags);

  // One row of the list: kept as a placement, or reported as skipped.
  void Add(const cad::Row& row);
  // The program, or nullopt when anything was an error (unmapped parts,
  // mixed sides without --side, a full pallet, nothing to place). `reader`
  // gives the row counts for the summary.
  std::optional<ir::Program> Finish(const cad::ListReader& reader);

  const ImportSummary& summary() const { return summary_; }
  // Every row's fate in list order (with ImportOptions::keep_fates), and the
  // set-up sheet (after a successful Finish).
  const std::vector<RowFate>& fates() const { return fates_; }
  const SetupSheet& setup_sheet() const { return setup_; }

 private:
  struct Part {
    std::uint32_t line = 0;
    std::string designator;
    std::string value;
    std::string package;
    double x_mm = 0;
    double y_mm = 0;
    double rotation_deg = 0;
    cad::Side side = cad::Side::kTop;
    std::optional<cad::FeederMatch> feeder;  // nullopt: no feeder holds it
    // A skip that does not depend on the side (DNP, excluded), with what the
    // warning says about it.
    std::optional<SkipReason> skip;
    int skip_detail = -1;  // index into skip_details_
    SourceRange designator_range;
    SourceRange side_range;
    SourceRange skip_range;
  };

  bool Classify(const cad::Row& row, Part& part);
  std::optional<cad::FeederMatch> FindFeeder(const cad::Row& row);
  // Files a skipped row under its reason and rule (one warning per group, at
  // its first row, comes from ReportSkipGroups).
  void Skip(const Part& part, cad::Side placed_side);
  void ReportSkipGroups(cad::Side placed_side);
  void ReportUnmapped(const std::vector<const Part*>& unmapped);
  // How the bottom side is read (option or cad_bottom.h); fills summary_.bottom.
  cad::BottomPositions DescribeBottom(const cad::ListReader& reader);
  cad::BottomDecision DecideBottom(const cad::ListReader& reader) const;
  std::size_t FateIndex(const Part& part) const;  // the part's index in parts_ and fates_
  // Adds a part (on board `board` of the panel) to its feeder slot of the set-up sheet.
  void AddToSetup(SetupSlot& slot, const cad::FeederSpec& feeder, int k, bool is_lane, const Part& part,
                  std::size_t board, const std::string& board_name);
  // Tapes hold one kind of part (package and value): per feeder, the lane
  // of each part (by index into `parts`) of a bank of tapes; warns about a
  // single tape given several kinds.
  // The board's outline in the list's coordinates seen from the top: --board,
  // or the bounding box of every part the list gives (both sides).
  std::array<double, 4> Outline(cad::BottomPositions bottom_positions) const;
  // Sets the origin from the outline (on board coordinates, turned over for
  // the bottom side): into the pocket, or its centre on the centre spot.
  // False after reporting a board that does not fit its pocket.
  bool PlaceBoard(const std::array<double, 4>& on_board_outline, double angle);
  // Reports the parts (on_board: each part's board coordinates; board_frames:
  // each board's x, y, rotation in the fixture) that land outside every
  // calibrated region; false when any does.
  bool CheckRegions(const std::vector<const Part*>& parts, const std::vector<std::array<double, 2>>& on_board,
                    const std::vector<std::array<double, 3>>& board_frames, const std::array<double, 4>& outline);
  std::vector<std::unordered_map<std::size_t, int>> AssignTapeLanes(
      const std::vector<const Part*>& parts, const std::vector<std::vector<std::size_t>>& by_feeder);
  std::optional<ir::Program> Build(const std::vector<const Part*>& parts, cad::Side side,
                                   cad::BottomPositions bottom_positions);

  const cad::FeederTable& feeders_;
  ImportOptions options_;
  std::uint32_t list_file_;
  Diagnostics& diags_;
  std::vector<Part> parts_;  // every row read cleanly, in list order
  // Feeder lookups by package and value, when no [[map]] looks at designators.
  std::unordered_map<std::string, std::optional<cad::FeederMatch>> feeder_cache_;
  std::string cache_key_;
  std::vector<std::array<std::string, 4>> skip_details_;  // what the skip warnings say
  std::map<std::pair<int, std::string>, std::size_t> group_of_;  // (reason, rule) -> index into summary_.skip_groups
  std::vector<const Part*> group_first_;  // per group: its first row
  std::vector<std::size_t> fate_of_part_;  // per parts_ index: index into fates_ (keep_fates)
  std::vector<RowFate> fates_;
  SetupSheet setup_;
  ImportSummary summary_;
  // How Build turns the placed side's rotations (for the set-up sheet's turns).
  ImportMirror placed_mirror_ = ImportMirror::kNone;
  bool placed_mirror_rotation_ = false;
};

// A name for the .place language from any text: letters, digits and '_'
// kept, everything else '_', a leading digit prefixed with '_', a keyword
// followed by '_'. Never empty.
std::string MakeIdentifier(std::string_view text);

}  // namespace smtcal
