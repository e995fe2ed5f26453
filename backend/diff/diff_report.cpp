// The review text, JSON and SVG board plot of a ProgramDiff (diff_report.h).
// Numbers are rounded where they are printed (0.1 µm and 0.0001° in the
// text; in JSON 0.0001 µm, 0.0001° for directions, 1e-7° for du), never in
// the diff itself.
#include "backend/diff/diff_report.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "backend/reports/svg_text.h"
#include "base/field_text.h"
#include "base/json_text.h"

namespace smtcal::diff {
namespace {

// fmt prints -0.0 as "-0.0"; a move that rounds to zero has no sign.
double NoNegativeZero(double value, double resolution) {
  double rounded = std::round(value / resolution) * resolution;
  return rounded == 0 ? 0.0 : rounded;
}
std::string Um(double um) { return fmt::format("{:.1f}", NoNegativeZero(um, 0.1)); }
std::string SignedUm(double um) { return fmt::format("{:+.1f}", NoNegativeZero(um, 0.1)); }
std::string Deg(double deg) { return fmt::format("{:.1f}", NoNegativeZero(deg, 0.1)); }
std::string SignedDeg(double deg) { return fmt::format("{:+.4f}", NoNegativeZero(deg, 1e-4)); }

bool Shows(double um) { return NoNegativeZero(um, 0.1) != 0; }

std::string Loc(const std::string& file, const SourceLoc& loc) { return fmt::format("{}:{}", file, loc.line); }

// "12.0 µm toward 90.0° (dx +0.0 µm, dy +12.0 µm, du +0.0500°) in Layer1"
std::string DescribeMove(const Displacement& d) {
  const bool xy = Shows(d.d_um), z = Shows(d.dz_um), u = NoNegativeZero(d.du_deg, 1e-4) != 0;
  std::vector<std::string> parts;
  if (xy) parts.push_back(fmt::format("dx {} µm, dy {} µm", SignedUm(d.dx_um), SignedUm(d.dy_um)));
  if (z) parts.push_back(fmt::format("dz {} µm", SignedUm(d.dz_um)));
  if (u) parts.push_back(fmt::format("du {}°", SignedDeg(d.du_deg)));
  std::string text;
  if (xy) {
    text = fmt::format("{} µm toward {}° ({})", Um(d.d_um), Deg(d.direction_deg), fmt::join(parts, ", "));
  } else if (!parts.empty()) {
    text = fmt::format("{}", fmt::join(parts, ", "));
  } else {
    text = fmt::format("{} µm", Um(d.d_um));  // below the printed resolution
  }
  return text + " in " + d.frame;
}

// The frame a target is written in and the robot base frame (when they
// differ); intermediate frames are in the JSON.
std::string DescribeMoves(const Change& change) {
  if (change.moves.empty()) return "";
  std::string text = DescribeMove(change.moves.front());
  if (change.moves.size() > 1) text += "; " + DescribeMove(change.moves.back());
  return text;
}

std::string Where(const Change& change) { return change.function.empty() ? "" : " in " + change.function; }

// ", position 1 of 3, at (155.080, 67.620) in region layer1": which of a
// statement's positions, and where it must land.
std::string PositionText(const MachineMove& move) {
  std::string text = move.count > 1 ? fmt::format(", position {} of {}", move.index + 1, move.count) : "";
  if (!move.board.empty() && move.comparable) {
    text += fmt::format(", at ({:.3f}, {:.3f}) {}", move.required[0], move.required[1],
                        move.region.empty() ? std::string("outside every region") : "in region " + move.region);
  }
  return text;
}

// "command 12.0 µm toward 180.0° (...) in robot base with Board at its
// nominal pose, lands 12.0 µm; at most 12.1 µm with Board shifted ...".
std::string DescribeMachineMove(const MachineMove& move) {
  if (!move.comparable) return move.note;
  std::string text = "command " + DescribeMove(move.command);
  if (!move.board.empty()) text += fmt::format(" with {} at its nominal pose", move.board);
  text += fmt::format(", lands {} µm", Um(move.lands.d_um));
  if (!move.board.empty()) {
    text += fmt::format("; at most {} µm with {} {}", Um(move.worst.d_um), move.board,
                        move.worst_pose == "nominal pose" ? "at its nominal pose" : move.worst_pose);
  } else if (std::fabs(move.worst.d_um - move.command.d_um) >= 0.05) {
    text += fmt::format("; at most {} µm", Um(move.worst.d_um));
  }
  return text;
}

std::string MachineLines(const ProgramDiff& diff, const Change& change, const std::string& now, const std::string& was) {
  std::string lines;
  for (const MachineMove& move : change.machine) {
    lines += fmt::format("{}: {} {}{}{} (was {}): {}", now, move.comparable ? "moved" : "cannot compare", change.what,
                         Where(change), PositionText(move), was, DescribeMachineMove(move));
    if (move.beyond_threshold) lines += fmt::format(" [more than {} µm]", Um(diff.threshold_um));
    lines += "\n";
  }
  return lines;
}

std::string ChangeLine(const ProgramDiff& diff, const Change& change) {
  const std::string was = change.old_side.loc.known() ? Loc(diff.old_file, change.old_side.loc) : "";
  const std::string now = change.new_side.loc.known() ? Loc(diff.new_file, change.new_side.loc) : "";
  // A motion statement on the machine: its positions, not its text, moved.
  const bool machine = diff.on_machine && change.is_target && !change.function.empty() &&
                       (change.kind == ChangeKind::kMoved || change.kind == ChangeKind::kChanged ||
                        change.kind == ChangeKind::kReordered);
  std::string line;
  switch (change.kind) {
    case ChangeKind::kMoved:
      if (machine) return MachineLines(diff, change, now, was);
      line = fmt::format("{}: moved {}{} (was {}): {}", now, change.what, Where(change), was, DescribeMoves(change));
      if (diff.on_machine && change.is_target) line += " (in the text; the gate judges the positions that use it)";
      break;
    case ChangeKind::kChanged: {
      line = fmt::format("{}: changed {}{} (was {}: {})", now, change.what, Where(change), was, change.old_side.text);
      std::string details = change.note;
      std::string moves = machine ? std::string() : DescribeMoves(change);
      if (!moves.empty()) details += (details.empty() ? "" : "; ") + moves;
      if (!details.empty()) line += ": " + details;
      if (machine) return line + "\n" + MachineLines(diff, change, now, was);
      break;
    }
    case ChangeKind::kAdded:
      line = fmt::format("{}: added {}{}", now, change.what, Where(change));
      if (!change.note.empty()) line += " (" + change.note + ")";
      break;
    case ChangeKind::kRemoved:
      line = fmt::format("{}: removed {}{}", was, change.what,
                         change.function.empty() ? "" : " from " + change.function);
      if (!change.note.empty()) line += " (" + change.note + ")";
      break;
    case ChangeKind::kReordered:
      line = fmt::format("{}: reordered {}{} (was {}): the same {}, in another order", now, change.what, Where(change),
                         was, change.is_target ? "position" : "line");
      if (machine && !change.machine.empty()) return line + "\n" + MachineLines(diff, change, now, was);
      break;
  }
  if (change.beyond_threshold) line += fmt::format(" [more than {} µm]", Um(diff.threshold_um));
  return line + "\n";
}

std::string LargestWhere(const ProgramDiff& diff) {
  const Change& c = diff.changes[diff.summary.largest];
  std::string position;
  if (!c.machine.empty() && c.machine[diff.summary.largest_position].count > 1) {
    const MachineMove& move = c.machine[diff.summary.largest_position];
    position = fmt::format(", position {} of {}", move.index + 1, move.count);
  }
  return fmt::format("{}, {}{}{}", Loc(diff.new_file, c.new_side.loc), c.what, Where(c), position);
}

std::string GateLine(const ProgramDiff& diff) {
  const Summary& s = diff.summary;
  if (s.gate_passes()) {
    return fmt::format("gate: passed: no target moved more than {} µm, nothing was added, removed or changed\n",
                       Um(diff.threshold_um));
  }
  std::vector<std::string> why;
  if (s.beyond_threshold > 0) {
    why.push_back(fmt::format("{} target{} moved more than {} µm", s.beyond_threshold,
                              s.beyond_threshold == 1 ? "" : "s", Um(diff.threshold_um)));
  }
  if (s.added > 0) why.push_back(fmt::format("{} added", s.added));
  if (s.removed > 0) why.push_back(fmt::format("{} removed", s.removed));
  if (s.changed > 0) why.push_back(fmt::format("{} changed", s.changed));
  if (s.reordered > 0) {
    why.push_back(fmt::format("{} reordered (the same positions in another order: a change of sequence)", s.reordered));
  }
  if (s.not_comparable > 0 && s.changed == 0) why.push_back(fmt::format("{} not comparable", s.not_comparable));
  return fmt::format("gate: failed: {}\n", fmt::join(why, ", "));
}

// "old.place: cell paper-cell, the cell it was compiled with, paper.cell.toml (sha256 3f2a9c1b0d4e...)".
std::string SideCellLine(const std::string& file, const DiffSideCell& side) {
  std::string cell_file;
  for (const cell::CellFile& f : side.files) {
    if (!f.table) cell_file = fmt::format(" (cell file sha256 {}...)", f.sha256.substr(0, 12));
  }
  return fmt::format("{}: {}cell {}, {}{}\n", file, side.compiled ? "" : "a source program, compiled here for ",
                     side.cell_name, side.how, cell_file);
}

std::string MachineHeader(const ProgramDiff& diff) {
  std::string text = SideCellLine(diff.old_file, *diff.old_cell) + SideCellLine(diff.new_file, *diff.new_cell);
  text += diff.tables_differ.empty()
              ? std::string("the cells hold the same tables and fixtures\n")
              : fmt::format("the cells differ in: {}\n", fmt::join(diff.tables_differ, ", "));
  text += fmt::format(
      "on the machine: one robot and one board, as {0}'s cell describes them (--machine {1}); each program with its "
      "own cell's tables, marker geometry, estimator, scan paths and limits",
      diff.machine, diff.machine == "NEW" ? "new" : "old");
  if (diff.poses > 1) {
    text += fmt::format(
        "; board targets at {} poses within the fixtures' check limits, as far out as both programs' scans accept",
        diff.poses);
  }
  if (!diff.refused_poses.empty()) {
    text += fmt::format(" ({} refused by both programs' scans: not compared)", fmt::join(diff.refused_poses, ", "));
  }
  text += "\n";
  for (const std::string& acceptance : diff.acceptance) text += "accepted boards: " + acceptance + "\n";
  return text;
}

}  // namespace

std::string FormatDiffText(const ProgramDiff& diff) {
  std::string text = fmt::format("diff {} -> {} (threshold {} µm{})\n", diff.old_file, diff.new_file,
                                 Um(diff.threshold_um),
                                 diff.base_frame_known ? "" : "; fixture frames not resolved: no --cell");
  if (diff.on_machine) text += MachineHeader(diff);
  for (const Change& change : diff.changes) text += ChangeLine(diff, change);
  if (diff.changes.empty()) text += "no changes\n";
  const Summary& s = diff.summary;
  if (diff.on_machine) {
    text += fmt::format("summary: {} commanded positions compared on the machine, {} moved, {} by more than {} µm",
                        diff.positions_compared, s.targets_moved, s.beyond_threshold, Um(diff.threshold_um));
    if (s.largest_um > 0) text += fmt::format(", largest {} µm ({})", Um(s.largest_um), LargestWhere(diff));
    text += fmt::format("; {} points compared, {} moved in the text", diff.declarations_compared,
                        s.points_moved_in_text);
  } else {
    text += fmt::format("summary: {} targets compared, {} moved, {} by more than {} µm", s.targets_compared,
                        s.targets_moved, s.beyond_threshold, Um(diff.threshold_um));
    if (s.largest_um > 0) text += fmt::format(", largest {} µm ({})", Um(s.largest_um), LargestWhere(diff));
  }
  text += fmt::format("; {} not comparable; {} added, {} removed, {} changed", s.not_comparable, s.added, s.removed,
                      s.changed);
  if (s.reordered > 0) text += fmt::format(", {} reordered", s.reordered);
  text += "\n";
  return text + GateLine(diff);
}

// ------------------------------------------------------------------ JSON

namespace {

using nlohmann::ordered_json;

// A number written with `decimals` decimals and nothing after them (not
// 179.98430000000002), no "-0".
double JsonNumber(double value, int decimals = 4) { return RoundedToDecimals(value, decimals); }

ordered_json JsonSide(const Side& side) {
  if (!side.loc.known()) return ordered_json();
  ordered_json j;
  j["line"] = side.loc.line;
  j["text"] = side.text;
  return j;
}

ordered_json JsonMove(const Displacement& d) {
  ordered_json m;
  m["frame"] = d.frame;
  m["dx_um"] = JsonNumber(d.dx_um);
  m["dy_um"] = JsonNumber(d.dy_um);
  m["dz_um"] = JsonNumber(d.dz_um);
  m["du_deg"] = JsonNumber(d.du_deg, 7);
  m["d_um"] = JsonNumber(d.d_um);
  m["direction_deg"] = JsonNumber(d.direction_deg);
  return m;
}

ordered_json JsonCell(const DiffSideCell& side) {
  ordered_json j;
  j["program"] = side.program;
  j["compiled"] = side.compiled;
  j["cell"] = side.cell_name;
  j["how"] = side.how;
  ordered_json files = ordered_json::array();
  for (const cell::CellFile& file : side.files) {
    files.push_back({{"kind", file.table ? "table" : "cell"}, {"path", file.path}, {"sha256", file.sha256}});
  }
  j["files"] = files;
  return j;
}

ordered_json JsonMachineMove(const MachineMove& move) {
  ordered_json j;
  j["position"] = move.index + 1;
  j["of"] = move.count;
  j["board"] = move.board.empty() ? ordered_json() : ordered_json(move.board);
  j["comparable"] = move.comparable;
  j["note"] = move.note.empty() ? ordered_json() : ordered_json(move.note);
  if (move.comparable) {
    j["required"] = {{"x_mm", JsonNumber(move.required[0], 6)}, {"y_mm", JsonNumber(move.required[1], 6)}};
    j["region"] = move.region.empty() ? ordered_json() : ordered_json(move.region);
    j["command"] = JsonMove(move.command);
    j["lands"] = JsonMove(move.lands);
    j["worst"] = JsonMove(move.worst);
    j["worst_pose"] = move.worst_pose.empty() ? ordered_json() : ordered_json(move.worst_pose);
  }
  j["beyond_threshold"] = move.beyond_threshold;
  return j;
}

}  // namespace

std::string FormatDiffJson(const ProgramDiff& diff) {
  ordered_json root;
  root["schema"] = "smtcal-diff/2";
  root["old"] = diff.old_file;
  root["new"] = diff.new_file;
  root["threshold_um"] = JsonNumber(diff.threshold_um);
  root["base_frame_known"] = diff.base_frame_known;
  root["on_machine"] = diff.on_machine;
  if (diff.on_machine) {
    ordered_json differ = ordered_json::array();
    for (const std::string& what : diff.tables_differ) differ.push_back(what);
    ordered_json acceptance = ordered_json::array();
    for (const std::string& what : diff.acceptance) acceptance.push_back(what);
    root["cells"] = {{"old", JsonCell(*diff.old_cell)}, {"new", JsonCell(*diff.new_cell)}, {"differ", differ},
                     {"machine", diff.machine == "NEW" ? "new" : "old"}, {"poses", diff.poses},
                     {"acceptance", acceptance}};
  } else {
    root["cells"] = ordered_json();
  }
  ordered_json changes = ordered_json::array();
  for (const Change& change : diff.changes) {
    ordered_json c;
    c["kind"] = ChangeKindName(change.kind);
    c["what"] = change.what;
    c["function"] = change.function.empty() ? ordered_json() : ordered_json(change.function);
    c["target"] = change.is_target;
    c["old"] = JsonSide(change.old_side);
    c["new"] = JsonSide(change.new_side);
    ordered_json moves = ordered_json::array();
    for (const Displacement& d : change.moves) moves.push_back(JsonMove(d));
    c["moves"] = moves;
    ordered_json machine = ordered_json::array();
    for (const MachineMove& move : change.machine) machine.push_back(JsonMachineMove(move));
    c["machine"] = machine;
    c["beyond_threshold"] = change.beyond_threshold;
    c["note"] = change.note.empty() ? ordered_json() : ordered_json(change.note);
    changes.push_back(c);
  }
  root["changes"] = changes;
  const Summary& s = diff.summary;
  ordered_json summary;
  summary["targets_compared"] = s.targets_compared;
  summary["targets_moved"] = s.targets_moved;
  summary["beyond_threshold"] = s.beyond_threshold;
  summary["not_comparable"] = s.not_comparable;
  summary["added"] = s.added;
  summary["removed"] = s.removed;
  summary["changed"] = s.changed;
  summary["reordered"] = s.reordered;
  if (s.largest_um > 0) {
    const Change& c = diff.changes[s.largest];
    summary["largest"] = {{"d_um", JsonNumber(s.largest_um)}, {"what", c.what},
                          {"function", c.function.empty() ? ordered_json() : ordered_json(c.function)},
                          {"new_line", c.new_side.loc.line},
                          {"position", c.machine.empty() ? ordered_json()
                                                         : ordered_json(c.machine[s.largest_position].index + 1)}};
  } else {
    summary["largest"] = ordered_json();
  }
  summary["gate"] = s.gate_passes() ? "passed" : "failed";
  root["summary"] = summary;
  return JsonText(root);
}

// ------------------------------------------------------------------ SVG

namespace {

constexpr double kPanelPx = 560;        // the longer side of a panel's plot area
constexpr double kMinPanelWidthPx = 340;  // room for the title and the labels of a thin panel
constexpr double kMinPanelHeightPx = 220;
constexpr double kMarginPx = 60;        // left of the header
constexpr double kAxisRoomPx = 70;      // left of a panel: the y ticks and label
constexpr double kArrowFill = 0.12;     // the largest move drawn at most this share of the panel's span
constexpr double kArrowSpacingFill = 0.6;  // ... and of the targets' median spacing
constexpr std::size_t kHeaderChars = 125;   // a header line at 12 px fits the 900 px picture
constexpr std::size_t kLabelled = 5;    // the largest moves get a label
constexpr double kLabelFontPx = 11;
constexpr double kLeaderFromPx = 8;     // a label further than this from its arrow's tip gets a leader line
constexpr double kUmPerMm = 1000;

std::string Num(double v) { return fmt::format("{:.2f}", NoNegativeZero(v, 0.01)); }

// The largest 1, 2, 2.5 or 5 times a power of ten not above v (v > 0).
double NiceFloor(double v) {
  double power = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {5.0, 2.5, 2.0, 1.0}) {
    if (m * power <= v) return m * power;
  }
  return power;
}

struct Mark {
  const Change* change = nullptr;  // null: an unchanged target
  Pose4 at{};                      // old position (or new for added)
  std::optional<Pose4> to;         // new position of a moved target (on the machine: at + the worst move)
  double um = 0;                   // the move the gate judged
  bool beyond = false;             // more than the threshold
  bool not_comparable = false;     // a position that cannot be compared: a red ring
  std::string label;               // "R1", "line 66", "line 66 (1/3)"
};

struct Panel {
  std::string frame;
  std::vector<Mark> marks;
  std::size_t compared = 0, added = 0, removed = 0;  // what the marks are
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;  // mm
  double left = 0, top = 0, scale = 1, width = 0, height = 0;
  double Px(double x) const { return left + (x - x0) * scale; }
  double Py(double y) const { return top + (y1 - y) * scale; }  // y up, as on the robot
};

// What a panel's numbers are in: "robot base frame", "fixture Board's frame".
std::string FrameName(const std::string& frame) {
  return frame == "robot base" ? "robot base frame" : fmt::format("fixture {}'s frame", frame);
}

void Arrow(std::string& svg, double x0, double y0, double x1, double y1, std::string_view colour) {
  svg += fmt::format("    <line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{}\" stroke-width=\"1.4\"/>\n",
                     Num(x0), Num(y0), Num(x1), Num(y1), colour);
  double dx = x1 - x0, dy = y1 - y0, len = std::hypot(dx, dy);
  if (len < 1e-9) return;
  double ux = dx / len, uy = dy / len, head = std::min(7.0, 0.5 * len);
  svg += fmt::format("    <polygon points=\"{},{} {},{} {},{}\" fill=\"{}\"/>\n", Num(x1), Num(y1),
                     Num(x1 - ux * head - uy * head * 0.45), Num(y1 - uy * head + ux * head * 0.45),
                     Num(x1 - ux * head + uy * head * 0.45), Num(y1 - uy * head - ux * head * 0.45), colour);
}

// A label: the point's name, or the statement's line in NEW.
std::string ShortName(const Change& c) {
  if (c.function.empty()) return c.what;
  return fmt::format("line {}", c.new_side.loc.line);
}

// ---- label placement: boxes in pixels, greedy, nothing drawn over another

struct Box {
  double x0, y0, x1, y1;
  bool Overlaps(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  bool Inside(const Box& o) const { return x0 >= o.x0 && y0 >= o.y0 && x1 <= o.x1 && y1 <= o.y1; }
};

struct Segment {
  double x0, y0, x1, y1;
};

// Whether a segment passes through a box (Liang-Barsky clipping).
bool Crosses(const Segment& s, const Box& b) {
  double t0 = 0, t1 = 1;
  const double dx = s.x1 - s.x0, dy = s.y1 - s.y0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {s.x0 - b.x0, b.x1 - s.x0, s.y0 - b.y0, b.y1 - s.y0};
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0) {
      if (q[k] < 0) return false;
      continue;
    }
    const double t = q[k] / p[k];
    if (p[k] < 0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  return true;
}

// The width of a label in pixels, generously (sans-serif digits are 0.55 to 0.64 em, letters less).
double LabelWidth(std::string_view text) {
  std::size_t chars = 0;
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t length = Utf8Length(text, i);
    i += length == 0 ? 1 : length;
    ++chars;
  }
  return 0.56 * kLabelFontPx * static_cast<double>(chars);
}

// The distance from a point to a box (0 inside).
double Distance(double x, double y, const Box& b) {
  return std::hypot(x - std::clamp(x, b.x0, b.x1), y - std::clamp(y, b.y0, b.y1));
}

// Where a label goes: the first box around its arrow's tip (ax, ay), nearest
// first in eight directions, inside `area`, that covers no drawn mark, arrow
// or earlier label. Right beside the tip it must also be nearer its own tip
// than any other mark's point (`points`), so it cannot be read as another's;
// further away a leader line says whose it is. Else the box that covers
// fewest, another label last of all.
Box PlaceLabel(double ax, double ay, double width, const Box& area, const std::vector<Box>& marks,
               const std::vector<Segment>& arrows, const std::vector<Box>& labels,
               const std::vector<std::pair<double, double>>& points) {
  const double height = kLabelFontPx + 3;
  Box best{};
  int best_hits = -1;
  // Text over text is the worst a label can do, a leader line through
  // another label the next worst: they count as many hits.
  constexpr int kOverLabel = 100, kLeaderThroughLabel = 10;
  for (double d : {4.0, 12.0, 22.0, 34.0, 50.0, 70.0, 95.0, 125.0}) {
    for (int direction = 0; direction < 16; ++direction) {
      // E, W, N, S, NE, SE, NW, SW first, then the eight between them.
      static constexpr double kAngleDeg[16] = {0,    180,   90,    270,   45,    315,   135,  225,
                                               22.5, 157.5, 67.5,  112.5, 202.5, 247.5, 292.5, 337.5};
      const double c = std::cos(kAngleDeg[direction] * std::numbers::pi / 180);
      const double s = std::sin(kAngleDeg[direction] * std::numbers::pi / 180);
      const int hx = c > 0.3 ? 1 : c < -0.3 ? -1 : 0;
      const int vy = s > 0.3 ? -1 : s < -0.3 ? 1 : 0;
      // The first eight as they always were (diagonals at 0.7 d).
      const double along = direction < 8 && hx != 0 && vy != 0 ? 0.7 : 1.0;
      const double px = ax + d * (direction < 8 ? along * hx : c), py = ay + d * (direction < 8 ? along * vy : -s);
      const double left = hx > 0 ? px : hx < 0 ? px - width : px - width / 2;
      const double top = vy > 0 ? py : vy < 0 ? py - height : py - height / 2;
      const Box box{left, top, left + width, top + height};
      if (!box.Inside(area)) continue;
      int hits = 0;
      for (const Box& m : marks) hits += box.Overlaps(m);
      for (const Segment& a : arrows) hits += Crosses(a, box);
      for (const Box& l : labels) hits += kOverLabel * box.Overlaps(l);
      if (d <= kLeaderFromPx) {
        const double own = Distance(ax, ay, box);
        for (const auto& [x, y] : points) hits += Distance(x, y, box) < own + 6;
      } else {  // its leader line must not run through a label placed before
        const Segment leader{ax, ay, std::clamp(ax, box.x0, box.x1), std::clamp(ay, box.y0, box.y1)};
        for (const Box& l : labels) hits += kLeaderThroughLabel * Crosses(leader, l);
      }
      if (hits == 0) return box;
      if (best_hits < 0 || hits < best_hits) {
        best = box;
        best_hits = hits;
      }
    }
  }
  if (best_hits < 0) {  // the panel is smaller than the label: beside the tip
    best = {ax + 5, ay - height / 2, ax + 5 + width, ay + height / 2};
  }
  return best;
}

// The lines cut at spaces so none is longer than `width` characters (the
// header stays within the picture).
std::vector<std::string> Wrapped(const std::vector<std::string>& lines, std::size_t width) {
  std::vector<std::string> out;
  for (const std::string& line : lines) {
    std::string rest = line;
    while (rest.size() > width) {
      std::size_t cut = rest.rfind(' ', width);
      if (cut == std::string::npos || cut == 0) break;
      out.push_back(rest.substr(0, cut));
      rest = "  " + rest.substr(cut + 1);
    }
    out.push_back(rest);
  }
  return out;
}

// The median distance from a drawn target to its nearest neighbour (mm), 0
// for fewer than two: how far apart the targets are.
double MedianSpacingMm(const std::vector<Panel>& panels) {
  std::vector<double> nearest;
  for (const Panel& p : panels) {
    // Distinct positions only: a statement in a loop draws one dot per run.
    std::vector<std::pair<double, double>> at;
    for (const Mark& m : p.marks) at.emplace_back(m.at[0], m.at[1]);
    std::sort(at.begin(), at.end());
    at.erase(std::unique(at.begin(), at.end()), at.end());
    if (at.size() < 2) continue;
    for (std::size_t i = 0; i < at.size(); ++i) {
      double best = INFINITY;
      // Sorted by x: only neighbours nearer in x than the best so far can be nearer.
      for (std::size_t j = i + 1; j < at.size() && at[j].first - at[i].first < best; ++j) {
        best = std::min(best, std::hypot(at[j].first - at[i].first, at[j].second - at[i].second));
      }
      for (std::size_t j = i; j-- > 0 && at[i].first - at[j].first < best;) {
        best = std::min(best, std::hypot(at[j].first - at[i].first, at[j].second - at[i].second));
      }
      nearest.push_back(best);
    }
  }
  if (nearest.empty()) return 0;
  std::nth_element(nearest.begin(), nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2), nearest.end());
  return nearest[nearest.size() / 2];
}

}  // namespace

std::string PlotDiffSvg(const ProgramDiff& diff) {
  // Group what can be drawn by frame: robot base first, then fixtures by name.
  std::map<std::string, Panel> by_frame;
  std::size_t not_comparable = 0;   // red rings
  std::set<std::string> reasons;    // why they cannot be compared
  for (const Change& change : diff.changes) {
    if (!change.is_target) continue;
    const bool machine = diff.on_machine && !change.function.empty() &&
                         (change.kind == ChangeKind::kMoved || change.kind == ChangeKind::kChanged ||
                          change.kind == ChangeKind::kReordered);
    // On the machine the picture shows positions: a point's coordinates are text.
    if (diff.on_machine && change.function.empty()) continue;
    if (machine) {  // its positions, where NEW wants them at the nominal pose, and their worst moves
      Panel& panel = by_frame["robot base"];
      for (const MachineMove& move : change.machine) {
        if (!move.comparable) {  // a red ring where NEW puts it; the header says why
          if (!move.located) continue;
          Mark mark;
          mark.change = &change;
          mark.at = move.required;
          mark.not_comparable = true;
          mark.label = move.count > 1 ? fmt::format("line {} ({}/{}): not comparable", change.new_side.loc.line,
                                                    move.index + 1, move.count)
                                      : fmt::format("line {}: not comparable", change.new_side.loc.line);
          panel.marks.push_back(std::move(mark));
          ++panel.compared;
          ++not_comparable;
          reasons.insert(move.note);
          continue;
        }
        if (!move.moved) continue;
        Mark mark;
        mark.change = &change;
        mark.at = move.required;
        mark.to = Pose4{move.required[0] + move.worst.dx_um / kUmPerMm, move.required[1] + move.worst.dy_um / kUmPerMm,
                        move.required[2], move.required[3]};
        mark.um = move.worst.d_um;
        mark.beyond = move.beyond_threshold;
        mark.label = move.count > 1 ? fmt::format("line {} ({}/{})", change.new_side.loc.line, move.index + 1,
                                                  move.count)
                                    : ShortName(change);
        panel.marks.push_back(std::move(mark));
        ++panel.compared;
      }
      continue;
    }
    if (change.plot_frame.empty()) continue;
    Mark mark;
    mark.change = &change;
    mark.um = change.gate_um;
    mark.beyond = change.beyond_threshold;
    mark.label = ShortName(change);
    Panel& panel = by_frame[change.plot_frame];
    if (change.old_plot && change.new_plot) {
      mark.at = *change.old_plot;
      mark.to = *change.new_plot;
      ++panel.compared;
    } else if (change.old_plot) {
      mark.at = *change.old_plot;
      ++panel.removed;
    } else if (change.new_plot) {
      mark.at = *change.new_plot;
      ++panel.added;
    } else {
      continue;
    }
    panel.marks.push_back(mark);
  }
  for (std::size_t i = 0; i < diff.unchanged_plot.size(); ++i) {
    Panel& panel = by_frame[diff.unchanged_plot_frame[i]];
    Mark unchanged;
    unchanged.at = diff.unchanged_plot[i];
    panel.marks.push_back(std::move(unchanged));
    ++panel.compared;
  }
  std::vector<Panel> panels;
  if (auto base = by_frame.find("robot base"); base != by_frame.end()) {
    panels.push_back(std::move(base->second));
    panels.back().frame = "robot base";
    by_frame.erase(base);
  }
  for (auto& [frame, panel] : by_frame) {
    panels.push_back(std::move(panel));
    panels.back().frame = frame;
  }
  // The compared targets (the text report's "targets compared") that have
  // no single static position to draw.
  std::size_t drawn = 0;
  for (const Panel& p : panels) drawn += p.compared;
  const std::size_t compared = diff.on_machine ? diff.positions_compared : diff.summary.targets_compared;
  const std::string compared_what = diff.on_machine ? "commanded position" : "target";
  const std::size_t not_drawn = compared - std::min(drawn, compared);

  // One enlargement for all panels: the longest arrow spans at most
  // kArrowFill of the widest panel and kArrowSpacingFill of the median
  // spacing of the targets, so arrows neither run off a panel nor into
  // their neighbours.
  double largest_mm = 0, span_mm = 1;
  for (Panel& p : panels) {
    p.x0 = p.y0 = INFINITY;
    p.x1 = p.y1 = -INFINITY;
    for (const Mark& m : p.marks) {
      p.x0 = std::min(p.x0, m.at[0]);
      p.x1 = std::max(p.x1, m.at[0]);
      p.y0 = std::min(p.y0, m.at[1]);
      p.y1 = std::max(p.y1, m.at[1]);
      if (m.to) largest_mm = std::max(largest_mm, std::hypot((*m.to)[0] - m.at[0], (*m.to)[1] - m.at[1]));
    }
    span_mm = std::max({span_mm, p.x1 - p.x0, p.y1 - p.y0});
  }
  const double spacing_mm = MedianSpacingMm(panels);
  const double longest_mm = spacing_mm > 0 ? std::min(kArrowFill * span_mm, kArrowSpacingFill * spacing_mm)
                                           : kArrowFill * span_mm;
  const double enlarge = largest_mm > 0 ? std::max(1.0, NiceFloor(longest_mm / largest_mm)) : 1;
  const double pad_mm = std::max(0.08 * span_mm, enlarge * largest_mm);
  // The header: what the marks mean, then what the panels count.
  std::vector<std::string> header;
  header.push_back(
      largest_mm == 0 ? std::string("grey: unchanged (no drawn target moved)")
      : diff.on_machine
          ? fmt::format("grey: unchanged; blue dot and arrow: moved on the machine, the dot where NEW wants the part "
                        "(boards at their nominal poses), the arrow its worst move (red: more than {} µm)",
                        Um(diff.threshold_um))
          : fmt::format("grey: unchanged; blue dot and arrow: moved, old position to new (red: more than {} µm)",
                        Um(diff.threshold_um)));
  if (largest_mm > 0) {
    header.push_back(fmt::format(
        "arrows {} times enlarged: the longest, {} µm, is drawn {:.2f} mm long{}", fmt::format("{:g}", enlarge),
        Um(largest_mm * kUmPerMm), enlarge * largest_mm,
        spacing_mm > 0 ? fmt::format(", within {:g} of the targets' median spacing ({:.2f} mm) and {:g} of the panel",
                                     kArrowSpacingFill, spacing_mm, kArrowFill)
                       : fmt::format(", within {:g} of the panel", kArrowFill)));
  }
  if (not_comparable > 0) {
    header.push_back(fmt::format("red ring: a position that cannot be compared on the machine ({}), where NEW puts it: {}",
                                 not_comparable, fmt::join(reasons, "; ")));
  }
  header.push_back(fmt::format("green +: added; red ×: removed. {}",
                               diff.base_frame_known ? "Fixture targets at the fixtures' nominal poses (--cell)."
                                                     : "Fixture targets in their fixture's frame (no --cell)."));
  {
    std::vector<std::string> where;
    for (const Panel& p : panels) {
      if (p.compared > 0) where.push_back(fmt::format("{} in the {}", p.compared, FrameName(p.frame)));
    }
    if (not_drawn > 0) where.push_back(fmt::format("{} not drawn", not_drawn));
    std::string line = fmt::format("{} {}{} compared{} (as in the text report)", compared, compared_what,
                                   compared == 1 ? "" : "s", diff.on_machine ? " on the machine" : "");
    if (!where.empty()) line += ": " + fmt::format("{}", fmt::join(where, ", "));
    std::size_t added = 0, removed = 0;
    for (const Panel& p : panels) {
      added += p.added;
      removed += p.removed;
    }
    if (added + removed > 0) line += fmt::format("; also drawn: {} added, {} removed", added, removed);
    header.push_back(line);
  }
  if (not_drawn > 0) {
    header.push_back("not drawn: no single static position (offsets or pallet slots known only at run time, or a "
                     "frame that changed)");
  }
  header = Wrapped(header, kHeaderChars);
  const double panel_top = 50 + 18 * static_cast<double>(header.size()) + 50;
  double x = kAxisRoomPx, height = 0;
  for (Panel& p : panels) {
    p.x0 -= pad_mm;
    p.x1 += pad_mm;
    p.y0 -= pad_mm;
    p.y1 += pad_mm;
    p.scale = kPanelPx / std::max(p.x1 - p.x0, p.y1 - p.y0);
    // A thin panel is widened (or heightened) about its centre.
    const double grow_x = std::max(0.0, kMinPanelWidthPx / p.scale - (p.x1 - p.x0)) / 2;
    const double grow_y = std::max(0.0, kMinPanelHeightPx / p.scale - (p.y1 - p.y0)) / 2;
    p.x0 -= grow_x;
    p.x1 += grow_x;
    p.y0 -= grow_y;
    p.y1 += grow_y;
    p.width = (p.x1 - p.x0) * p.scale;
    p.height = (p.y1 - p.y0) * p.scale;
    p.left = x;
    p.top = panel_top;
    x += p.width + kAxisRoomPx + 20;
    height = std::max(height, p.height);
  }
  const double width = std::max(x, 900.0);
  const double total_height = panel_top + height + 80;

  // The largest moves get labels.
  std::vector<const Mark*> ranked;
  for (const Panel& p : panels) {
    for (const Mark& m : p.marks) {
      if (m.change != nullptr && m.to && m.um > 0) ranked.push_back(&m);
    }
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const Mark* a, const Mark* b) { return a->um > b->um; });
  if (ranked.size() > kLabelled) ranked.resize(kLabelled);
  // The positions that cannot be compared come first: the gate fails on them.
  std::vector<const Mark*> rings;
  for (const Panel& p : panels) {
    for (const Mark& m : p.marks) {
      if (m.not_comparable && rings.size() < kLabelled) rings.push_back(&m);
    }
  }
  ranked.insert(ranked.begin(), rings.begin(), rings.end());

  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\">\n",
      Num(width), Num(total_height));
  svg += "  <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg += fmt::format("  <text x=\"{}\" y=\"28\" font-size=\"17\" font-weight=\"bold\">What moves: {} -&gt; {}</text>\n",
                     Num(kMarginPx), SvgEscape(diff.old_file), SvgEscape(diff.new_file));
  for (std::size_t i = 0; i < header.size(); ++i) {
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" fill=\"#333\">{}</text>\n", Num(kMarginPx),
                       Num(50 + 18 * static_cast<double>(i)), SvgEscape(header[i]));
  }
  if (panels.empty()) {
    svg += fmt::format("  <text x=\"{}\" y=\"{}\">no target has a static position to draw</text>\n", Num(kMarginPx),
                       Num(panel_top));
  }
  for (const Panel& p : panels) {
    svg += fmt::format("  <!-- panel: {} -->\n", SvgEscape(p.frame));
    std::string counts = fmt::format("{} of the {} compared {}{}", p.compared, compared, compared_what,
                                     compared == 1 ? "" : "s");
    if (p.added > 0) counts += fmt::format("; {} added", p.added);
    if (p.removed > 0) counts += fmt::format("; {} removed", p.removed);
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"14\" font-weight=\"bold\">{}, mm</text>\n",
                       Num(p.left), Num(p.top - 28), SvgEscape(FrameName(p.frame)));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" fill=\"#333\">{}</text>\n", Num(p.left), Num(p.top - 10),
                       SvgEscape(counts));
    svg += fmt::format("  <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#999\"/>\n",
                       Num(p.left), Num(p.top), Num(p.width), Num(p.height));
    // Ticks at round millimetres, the same step on both axes (one scale).
    const double step = SvgTickStep(std::max(p.x1 - p.x0, p.y1 - p.y0), 7);
    svg += "  <g stroke=\"#eee\">\n";
    for (double t : SvgTicks(p.x0, p.x1, step)) {
      svg += fmt::format("    <line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\"/>\n", Num(p.Px(t)), Num(p.top),
                         Num(p.top + p.height));
    }
    for (double t : SvgTicks(p.y0, p.y1, step)) {
      svg += fmt::format("    <line x1=\"{1}\" y1=\"{0}\" x2=\"{2}\" y2=\"{0}\"/>\n", Num(p.Py(t)), Num(p.left),
                         Num(p.left + p.width));
    }
    svg += "  </g>\n  <g fill=\"#444\">\n";
    for (double t : SvgTicks(p.x0, p.x1, step)) {
      svg += fmt::format("    <line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#666\"/>"
                         "<text x=\"{0}\" y=\"{3}\" text-anchor=\"middle\">{4}</text>\n",
                         Num(p.Px(t)), Num(p.top + p.height), Num(p.top + p.height + 4), Num(p.top + p.height + 16),
                         SvgTickText(t, step));
    }
    for (double t : SvgTicks(p.y0, p.y1, step)) {
      svg += fmt::format("    <line x1=\"{0}\" y1=\"{2}\" x2=\"{1}\" y2=\"{2}\" stroke=\"#666\"/>"
                         "<text x=\"{3}\" y=\"{4}\" text-anchor=\"end\">{5}</text>\n",
                         Num(p.left - 4), Num(p.left), Num(p.Py(t)), Num(p.left - 6), Num(p.Py(t) + 4),
                         SvgTickText(t, step));
    }
    svg += fmt::format("    <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">x (mm)</text>\n",
                       Num(p.left + p.width / 2), Num(p.top + p.height + 32));
    svg += fmt::format("    <text x=\"{0}\" y=\"{1}\" text-anchor=\"middle\" transform=\"rotate(-90 {0} {1})\">"
                       "y (mm)</text>\n",
                       Num(p.left - 48), Num(p.top + p.height / 2));
    svg += "  </g>\n  <g>\n";
    std::vector<Box> mark_boxes;
    std::vector<Segment> arrows;
    std::vector<std::pair<const Mark*, std::pair<double, double>>> points;  // dots and arrow tips, by owner
    for (const Mark& m : p.marks) {
      double px = p.Px(m.at[0]), py = p.Py(m.at[1]);
      mark_boxes.push_back({px - 5, py - 5, px + 5, py + 5});
      points.push_back({&m, {px, py}});
      if (m.change == nullptr) {
        svg += fmt::format("    <circle cx=\"{}\" cy=\"{}\" r=\"2.2\" fill=\"#aaa\"/>\n", Num(px), Num(py));
      } else if (m.change->kind == ChangeKind::kAdded) {
        svg += fmt::format("    <path d=\"M{} {}h10M{} {}v10\" stroke=\"#1a9641\" stroke-width=\"2\"/>\n",
                           Num(px - 5), Num(py), Num(px), Num(py - 5));
      } else if (m.not_comparable) {
        svg += fmt::format("    <circle cx=\"{}\" cy=\"{}\" r=\"5\" fill=\"none\" stroke=\"#d7191c\" "
                           "stroke-width=\"2\"/>\n",
                           Num(px), Num(py));
      } else if (m.change->kind == ChangeKind::kRemoved) {
        svg += fmt::format("    <path d=\"M{} {}l8 8M{} {}l-8 8\" stroke=\"#d7191c\" stroke-width=\"2\"/>\n",
                           Num(px - 4), Num(py - 4), Num(px + 4), Num(py - 4));
      } else {
        svg += fmt::format("    <circle cx=\"{}\" cy=\"{}\" r=\"2.6\" fill=\"#2b83ba\"/>\n", Num(px), Num(py));
        if (m.to) {
          double tx = m.at[0] + enlarge * ((*m.to)[0] - m.at[0]);
          double ty = m.at[1] + enlarge * ((*m.to)[1] - m.at[1]);
          Arrow(svg, px, py, p.Px(tx), p.Py(ty), m.beyond ? "#d7191c" : "#2b83ba");
          arrows.push_back({px, py, p.Px(tx), p.Py(ty)});
          mark_boxes.push_back({p.Px(tx) - 4, p.Py(ty) - 4, p.Px(tx) + 4, p.Py(ty) + 4});
          points.push_back({&m, {p.Px(tx), p.Py(ty)}});
        }
      }
    }
    // Labels inside the frame, clear of every mark, arrow and other label;
    // a thin leader line when one had to move away from its arrow.
    const Box area{p.left + 2, p.top + 2, p.left + p.width - 2, p.top + p.height - 2};
    std::vector<Box> labels;
    for (const Mark* c : ranked) {
      if (c < p.marks.data() || c >= p.marks.data() + p.marks.size()) continue;  // another panel's
      const double tx = c->to ? p.Px(c->at[0] + enlarge * ((*c->to)[0] - c->at[0])) : p.Px(c->at[0]);
      const double ty = c->to ? p.Py(c->at[1] + enlarge * ((*c->to)[1] - c->at[1])) : p.Py(c->at[1]);
      const std::string text = c->not_comparable ? c->label : fmt::format("{}: {} µm", c->label, Um(c->um));
      std::vector<std::pair<double, double>> others;
      for (const auto& [owner, at] : points) {
        if (owner != c) others.push_back(at);
      }
      const Box box = PlaceLabel(tx, ty, LabelWidth(text), area, mark_boxes, arrows, labels, others);
      labels.push_back(box);
      const double nx = std::clamp(tx, box.x0, box.x1), ny = std::clamp(ty, box.y0, box.y1);
      if (std::hypot(nx - tx, ny - ty) > kLeaderFromPx) {
        svg += fmt::format("    <line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#777\" stroke-width=\"0.7\"/>\n",
                           Num(tx), Num(ty), Num(nx), Num(ny));
        arrows.push_back({tx, ty, nx, ny});
      }
      // The text hugs the side of its box that faces the tip (the width is an estimate).
      const bool left_of_tip = box.x1 <= tx, right_of_tip = box.x0 >= tx;
      svg += fmt::format("    <text x=\"{}\" y=\"{}\" font-size=\"{:g}\"{}>{}</text>\n",
                         Num(left_of_tip ? box.x1 - 1 : right_of_tip ? box.x0 + 1 : (box.x0 + box.x1) / 2),
                         Num(box.y1 - 3), kLabelFontPx,
                         left_of_tip ? " text-anchor=\"end\"" : right_of_tip ? "" : " text-anchor=\"middle\"",
                         SvgEscape(text));
    }
    svg += "  </g>\n";
  }
  // The scale bar: an arrow of a round number of µm, enlarged like the others.
  if (largest_mm > 0 && !panels.empty()) {
    const Panel& p = panels.front();
    double bar_um = NiceFloor(largest_mm * kUmPerMm);
    double bar_px = bar_um / kUmPerMm * enlarge * p.scale;
    double y = p.top + p.height + 58;
    svg += "  <g>\n";
    Arrow(svg, p.left, y, p.left + bar_px, y, "#2b83ba");
    svg += "  </g>\n";
    svg += fmt::format("  <text x=\"{}\" y=\"{}\">= {} µm (arrows {} times enlarged)</text>\n",
                       Num(p.left + bar_px + 8), Num(y + 4), fmt::format("{:g}", bar_um), fmt::format("{:g}", enlarge));
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace smtcal::diff
