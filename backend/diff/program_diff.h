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
#include "passes/machine_targets.h"

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
  // The same line (the same position) in both, at another place in its
  // function's sequence: a change of sequence, not a move.
  kReordered,
};
std::string_view ChangeKindName(ChangeKind kind);  // moved | changed | added | removed | reordered

// One position a matched motion statement commands, compared on the machine
// (docs/diff.md, "On the machine"): each program through its own cell, on a
// robot that moves as NEW's cell says.
struct MachineMove {
  std::size_t index = 0;  // NEW's position index-th (0-based) of the statement's...
  std::size_t count = 0;  // ... `count` (OLD's when NEW has fewer)
  std::string board;      // the fixture whose poses it was evaluated at ("" for a base target)
  std::string region;     // the region that corrects it at the nominal pose, in NEW ("" none)
  Pose4 required{};       // where NEW wants the part at the nominal pose (base frame)
  bool located = false;   // `required` holds it (not for a position known only at run time)
  bool comparable = true;  // false: note says why (the scan refuses a pose, a point the tables refuse, ...)
  std::string note;
  Displacement command;   // the command's move at the nominal pose, in the robot base frame
  Displacement lands;     // where the part lands, at the nominal pose
  Displacement worst;     // the larger of the command's and the landing's move, at the worst pose
  std::string worst_pose;  // that pose ("" for a base target: there is only one)
  bool moved = false;     // any move beyond kDiffSamePositionMm (kDiffSameAngleDeg for u)
  bool beyond_threshold = false;
};

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
  bool comparable = true;     // false: the positions cannot be compared (note says why)
  std::string note;           // e.g. "frame Layer1 -> Layer2", "depends on k at run time"
  // Static positions for the board plot: robot base when it can be resolved,
  // else the root frame (plot_frame names it). Unset when not static.
  std::optional<Pose4> old_plot, new_plot;
  std::string plot_frame;
  // On the machine (both cells known): one entry per position the statement
  // commands that moved or cannot be compared; the gate judges these, not
  // `moves`, for motion statements.
  std::vector<MachineMove> machine;
};

struct DiffOptions {
  double threshold_um = 10;
  // NEW's cell: the fixtures' nominal poses for the frames of the text; may
  // be null. Every fixture of NEW must be in it.
  const cell::Cell* cell = nullptr;
  // OLD's cell, when it has another (every fixture of OLD must be in it).
  const cell::Cell* old_cell = nullptr;
};

struct Summary {
  // Targets are point declarations and motion statements; on the machine a
  // motion statement counts once per position it commands.
  std::size_t targets_compared = 0;  // targets present on both sides
  std::size_t targets_moved = 0;     // of them, moved at all (beyond kDiffSamePositionMm)
  std::size_t beyond_threshold = 0;  // moved by more than the threshold
  std::size_t not_comparable = 0;    // matched targets whose positions cannot be compared
  std::size_t added = 0, removed = 0, changed = 0;  // statements and declarations
  std::size_t reordered = 0;                        // statements the same, in another order
  std::size_t largest = 0;           // index into ProgramDiff::changes; valid when largest_um > 0
  double largest_um = 0;
  std::size_t largest_position = 0;  // on the machine: the index into changes[largest].machine
  std::size_t points_moved_in_text = 0;  // on the machine: point declarations whose coordinates moved (not gated)
  // The deployment gate (docs/diff.md): passes when nothing was added,
  // removed or reordered, nothing changed other than coordinates, no move
  // could not be compared, and no target moved by more than the threshold.
  bool gate_passes() const {
    return beyond_threshold == 0 && added == 0 && removed == 0 && changed == 0 && reordered == 0 &&
           not_comparable == 0;
  }
};

// A motion statement matched in both programs, for the comparison on the
// machine (CompareOnMachine), which may find it moved where its text did not.
struct MatchedStatement {
  const ir::Stmt* old_stmt = nullptr;
  const ir::Stmt* new_stmt = nullptr;
  SourceLoc old_loc, new_loc;
  std::string text;        // NEW's line, canonical, without comment
  std::string function;
  std::size_t change = npos;  // its entry in ProgramDiff::changes, when the text made one
  std::size_t insert_at = 0;  // else where one goes: before the change of this index
  bool is_target = true;
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
};

// What one side was evaluated with on the machine.
struct DiffSideCell {
  std::string program;    // the file as given
  bool compiled = false;  // smtcal output (else a source, compiled here for the cell)
  std::string cell_name;
  std::vector<cell::CellFile> files;  // the cell's files with their SHA-256
  std::string how;        // "the cell it was compiled with", "given by --old-cell", ...
};

struct ProgramDiff {
  std::string old_file, new_file;  // as given
  double threshold_um = 10;
  bool base_frame_known = false;   // a cell gave the fixtures' nominal poses, or there are no fixtures
  // On the machine: both programs evaluated with their cells (CompareOnMachine).
  bool on_machine = false;
  std::optional<DiffSideCell> old_cell, new_cell;
  std::vector<std::string> tables_differ;  // "region layer1" for each region whose tables differ
  // Whose cell describes the machine (the robot and the boards): "NEW" or "OLD".
  std::string machine = "NEW";
  std::size_t poses = 0;                    // board poses evaluated per fixture
  std::vector<std::string> refused_poses;   // "6 of Board's poses": both programs' scans refuse them
  // Per board whose programs' scans accept different poses: how (the poses
  // evaluated are the ones both accept; not gated).
  std::vector<std::string> acceptance;
  std::vector<MatchedStatement> matched;    // motion statements in both, in NEW's order
  // Targets compared: point declarations; motion statements as text; their
  // positions on the machine (Summary::targets_compared takes the first and
  // one of the others).
  std::size_t declarations_compared = 0, statements_compared = 0, positions_compared = 0;
  std::vector<Change> changes;     // in NEW's source order (removed ones after their neighbours)
  // Targets that did not move, for the board plot (position as in Change).
  std::vector<Pose4> unchanged_plot;
  std::vector<std::string> unchanged_plot_frame;
  std::vector<bool> unchanged_plot_statement;  // a motion statement's (replaced by its positions on the machine)
  Summary summary;
};

// A displacement b - a in `frame` (lengths mm in, µm out).
Displacement DisplacementBetween(const std::string& frame, const Pose4& a, const Pose4& b);
// No move beyond kDiffSamePositionMm (x, y, z) and kDiffSameAngleDeg (u).
bool IsZero(const Displacement& d);
// The summary (and every change's beyond_threshold) from the changes: in
// text, or on the machine when diff.on_machine.
void Summarize(ProgramDiff& diff);

// Replaces the line numbers of one side's changes by map[line - 1] (a
// LinuxCNC output's program is a text whose lines stand for .ngc lines).
void RemapLines(ProgramDiff& diff, bool new_side, const std::vector<std::uint32_t>& map);

// Compares two checked programs. Reports what makes the comparison
// meaningless (diagnostic_kinds_diff.def) to `diags`; when that has errors the
// returned value must not be shown.
ProgramDiff DiffPrograms(const ir::Program& old_program, const ir::Program& new_program, const DiffOptions& options,
                         Diagnostics& diags);

// One program as the machine runs it: its cell and what it commands.
struct MachineSide {
  const cell::Cell* cell = nullptr;
  const MachineTargets* targets = nullptr;
  DiffSideCell described;
};
// The comparison on the machine (docs/diff.md, "On the machine"): every
// position of every matched motion statement, each program through its own
// cell's constants on ONE machine (calibration/machine_model.h: the robot
// and the boards of NEW's cell, or OLD's with `old_is_machine`), at the
// nominal pose and the poses both programs' scans accept out to the check
// limits. Adds the moves to `diff` (a change for a statement whose text did
// not change but whose positions moved) and summarizes it again.
// `diff.matched`'s statements must still be alive.
void CompareOnMachine(ProgramDiff& diff, const MachineSide& old_side, const MachineSide& new_side,
                      bool old_is_machine = false);

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
