// The semantic diff of two .place programs (`smtcal diff OLD NEW`, docs/diff.md):
// "what changes on the machine if I deploy NEW instead of OLD?".
//
// Both programs must have parsed and passed the checks. Declarations are
// matched by name (case-insensitive, like the language; pallets by number),
// functions by name, and the statements of each pair of functions by an
// alignment of their statement sequences on a signature that ignores
// coordinates and comments, so a moved target is "moved", an inserted
// Pick/Place pair is "added". Every target (a point declaration or the point
// of a Jump/Go/Move/Pick/Place) that is matched gets its displacement in the
// frame it is written in, in the root frame of its Local chain (a fixture or
// the robot base) and, when a cell gives the fixtures' nominal poses, in the
// robot base frame.
//
// The result is a value; rendering it (text, JSON, SVG) is in diff_report.h.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "base/diagnostics.h"
#include "base/source.h"
#include "calibration/cell.h"
#include "ir/ir.h"
#include "passes/correction/compile_state.h"

namespace smtcal::diff {

// A displacement NEW - OLD in one frame. Lengths in µm, angles in degrees
// (the report's units: moves are small).
struct Displacement {
  std::string frame;  // what the numbers are in: "Layer1", "Board", "robot base", ...
  double dx_um = 0, dy_um = 0, dz_um = 0;
  double du_deg = 0;
  double d_um = 0;             // |(dx, dy)|
  double direction_deg = 0;    // atan2(dy, dx), -180..180; meaningless when d_um is 0
};

// Where a statement or declaration is, on one side.
struct Side {
  SourceLoc loc;     // unknown (file 0) when the side is missing
  std::string text;  // its line in canonical form, without the comment
};

enum class ChangeKind {
  kMoved,    // a target whose position changed, nothing else
  kChanged,  // something other than coordinates changed (possibly also moved)
  kAdded,    // only in NEW
  kRemoved,  // only in OLD
};
std::string_view ChangeKindName(ChangeKind kind);  // moved | changed | added | removed

struct Change {
  ChangeKind kind = ChangeKind::kChanged;
  std::string what;      // "point R1", "Local Layer1", "Place R1 + X(dx)", "Function Extra"
  std::string function;  // the function of a statement; empty for a declaration
  bool is_target = false;  // a point declaration or a motion statement
  Side old_side, new_side;
  // Targets: the displacement in each frame it can be given in, the frame it
  // is written in first and the robot base frame last. Empty when the two
  // positions cannot be compared (note says why).
  std::vector<Displacement> moves;
  bool moved = false;         // some of `moves` is not zero
  double gate_um = 0;         // the move the threshold judges: the last of `moves`
  bool beyond_threshold = false;
  std::string note;           // e.g. "frame Layer1 -> Layer2", "depends on k at run time"
  // Static positions for the board plot: robot base when it can be resolved,
  // else the root frame (plot_frame names it). Unset when not static.
  std::optional<Pose4> old_plot, new_plot;
  std::string plot_frame;
};

struct DiffOptions {
  double threshold_um = 10;
  const cell::Cell* cell = nullptr;  // fixtures' nominal poses; may be null
};

struct Summary {
  std::size_t targets_compared = 0;  // targets present on both sides
  std::size_t targets_moved = 0;     // of them, moved at all (beyond kDiffSamePositionMm)
  std::size_t beyond_threshold = 0;  // moved by more than the threshold
  std::size_t not_comparable = 0;    // matched targets whose positions cannot be compared
  std::size_t added = 0, removed = 0, changed = 0;  // statements and declarations
  std::size_t largest = 0;           // index into ProgramDiff::changes; valid when largest_um > 0
  double largest_um = 0;
  // The deployment gate (docs/diff.md): passes when nothing was added or
  // removed, nothing changed other than coordinates, no move could not be
  // compared, and no target moved by more than the threshold.
  bool gate_passes() const { return beyond_threshold == 0 && added == 0 && removed == 0 && changed == 0; }
};

struct ProgramDiff {
  std::string old_file, new_file;  // as given
  double threshold_um = 10;
  bool base_frame_known = false;   // a cell gave the fixtures' nominal poses, or there are no fixtures
  std::vector<Change> changes;     // in NEW's source order (removed ones after their neighbours)
  // Targets that did not move, for the board plot (position as in Change).
  std::vector<Pose4> unchanged_plot;
  std::vector<std::string> unchanged_plot_frame;
  Summary summary;
};

// Compares two checked programs. Reports what makes the comparison
// meaningless (diagnostic_kinds_diff.def) to `diags`; when that has errors the
// returned value must not be shown.
ProgramDiff DiffPrograms(const ir::Program& old_program, const ir::Program& new_program, const DiffOptions& options,
                         Diagnostics& diags);

// ------------------------------------------------------------------ matching
// Exposed for the unit tests.

// One aligned pair of sequence positions; an index is npos on the missing side.
struct Aligned {
  std::size_t old_index = npos, new_index = npos;
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
};
// Aligns two sequences: elements may be matched only when their signatures
// are equal; among the alignments with the most matches, the one with the
// largest total `similarity` (0..1, e.g. 1 for identical text) wins, so an
// inserted Pick does not shift every later Pick by one. Large inputs whose
// middle (after the identical prefix and suffix) exceeds kDiffMaxAlignCells
// fall back to Myers' O(ND) alignment, where elements are equal when their
// signatures are and their similarity is at least 0.5 (and beyond
// kDiffMaxEditDistance edits, to "the rest removed, then added"). The result
// lists every element of both sequences once, in order. `similarity` is 1
// exactly for identical elements.
std::vector<Aligned> Align(const std::vector<std::string>& old_signatures,
                           const std::vector<std::string>& new_signatures,
                           const std::function<double(std::size_t, std::size_t)>& similarity);

}  // namespace smtcal::diff
