// The review text, JSON and SVG board plot of a ProgramDiff (diff_report.h).
// Numbers are rounded where they are printed (0.1 µm and 0.0001° in the
// text; in JSON 0.0001 µm, 0.0001° for directions, 1e-7° for du), never in
// the diff itself.
#include "backend/diff/diff_report.h"

#include <algorithm>
#include <cmath>
#include <map>

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

std::string ChangeLine(const ProgramDiff& diff, const Change& change) {
  const std::string was = change.old_side.loc.known() ? Loc(diff.old_file, change.old_side.loc) : "";
  const std::string now = change.new_side.loc.known() ? Loc(diff.new_file, change.new_side.loc) : "";
  std::string line;
  switch (change.kind) {
    case ChangeKind::kMoved:
      line = fmt::format("{}: moved {}{} (was {}): {}", now, change.what, Where(change), was, DescribeMoves(change));
      break;
    case ChangeKind::kChanged: {
      line = fmt::format("{}: changed {}{} (was {}: {})", now, change.what, Where(change), was, change.old_side.text);
      std::string details = change.note;
      std::string moves = DescribeMoves(change);
      if (!moves.empty()) details += (details.empty() ? "" : "; ") + moves;
      if (!details.empty()) line += ": " + details;
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
  }
  if (change.beyond_threshold) line += fmt::format(" [more than {} µm]", Um(diff.threshold_um));
  return line + "\n";
}

std::string LargestWhere(const ProgramDiff& diff) {
  const Change& c = diff.changes[diff.summary.largest];
  return fmt::format("{}, {}{}", Loc(diff.new_file, c.new_side.loc), c.what, Where(c));
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
  return fmt::format("gate: failed: {}\n", fmt::join(why, ", "));
}

}  // namespace

std::string FormatDiffText(const ProgramDiff& diff) {
  std::string text = fmt::format("diff {} -> {} (threshold {} µm{})\n", diff.old_file, diff.new_file,
                                 Um(diff.threshold_um),
                                 diff.base_frame_known ? "" : "; fixture frames not resolved: no --cell");
  for (const Change& change : diff.changes) text += ChangeLine(diff, change);
  if (diff.changes.empty()) text += "no changes\n";
  const Summary& s = diff.summary;
  text += fmt::format("summary: {} targets compared, {} moved, {} by more than {} µm", s.targets_compared,
                      s.targets_moved, s.beyond_threshold, Um(diff.threshold_um));
  if (s.largest_um > 0) text += fmt::format(", largest {} µm ({})", Um(s.largest_um), LargestWhere(diff));
  text += fmt::format("; {} not comparable; {} added, {} removed, {} changed\n", s.not_comparable, s.added, s.removed,
                      s.changed);
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

}  // namespace

std::string FormatDiffJson(const ProgramDiff& diff) {
  ordered_json root;
  root["schema"] = "smtcal-diff/1";
  root["old"] = diff.old_file;
  root["new"] = diff.new_file;
  root["threshold_um"] = JsonNumber(diff.threshold_um);
  root["base_frame_known"] = diff.base_frame_known;
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
    for (const Displacement& d : change.moves) {
      ordered_json m;
      m["frame"] = d.frame;
      m["dx_um"] = JsonNumber(d.dx_um);
      m["dy_um"] = JsonNumber(d.dy_um);
      m["dz_um"] = JsonNumber(d.dz_um);
      m["du_deg"] = JsonNumber(d.du_deg, 7);
      m["d_um"] = JsonNumber(d.d_um);
      m["direction_deg"] = JsonNumber(d.direction_deg);
      moves.push_back(m);
    }
    c["moves"] = moves;
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
  if (s.largest_um > 0) {
    const Change& c = diff.changes[s.largest];
    summary["largest"] = {{"d_um", JsonNumber(s.largest_um)}, {"what", c.what},
                          {"function", c.function.empty() ? ordered_json() : ordered_json(c.function)},
                          {"new_line", c.new_side.loc.line}};
  } else {
    summary["largest"] = ordered_json();
  }
  summary["gate"] = s.gate_passes() ? "passed" : "failed";
  root["summary"] = summary;
  return JsonText(root);
}

// ------------------------------------------------------------------ SVG

namespace {

constexpr double kPanelPx = 560;      // the longer side of a panel's plot area
constexpr double kMarginPx = 60;
constexpr double kArrowFill = 0.12;   // the largest move drawn as this share of the panel's span
constexpr std::size_t kLabelled = 5;  // the largest moves get a label
constexpr double kUmPerMm = 1000;

std::string Num(double v) { return fmt::format("{:.2f}", NoNegativeZero(v, 0.01)); }

// The largest 1, 2 or 5 times a power of ten not above v (v > 0).
double NiceFloor(double v) {
  double power = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {5.0, 2.0, 1.0}) {
    if (m * power <= v) return m * power;
  }
  return power;
}

struct Mark {
  const Change* change = nullptr;  // null: an unchanged target
  Pose4 at{};                      // old position (or new for added)
  std::optional<Pose4> to;         // new position of a moved target
};

struct Panel {
  std::string frame;
  std::vector<Mark> marks;
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;  // mm
  double left = 0, top = 0, scale = 1, width = 0, height = 0;
  double Px(double x) const { return left + (x - x0) * scale; }
  double Py(double y) const { return top + (y1 - y) * scale; }  // y up, as on the robot
};

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

}  // namespace

std::string PlotDiffSvg(const ProgramDiff& diff) {
  // Group what can be drawn by frame: robot base first, then fixtures by name.
  std::map<std::string, Panel> by_frame;
  for (const Change& change : diff.changes) {
    if (!change.is_target || change.plot_frame.empty()) continue;
    Mark mark;
    mark.change = &change;
    if (change.old_plot && change.new_plot) {
      mark.at = *change.old_plot;
      mark.to = *change.new_plot;
    } else if (change.old_plot) {
      mark.at = *change.old_plot;
    } else if (change.new_plot) {
      mark.at = *change.new_plot;
    } else {
      continue;
    }
    by_frame[change.plot_frame].marks.push_back(mark);
  }
  for (std::size_t i = 0; i < diff.unchanged_plot.size(); ++i) {
    by_frame[diff.unchanged_plot_frame[i]].marks.push_back({nullptr, diff.unchanged_plot[i], std::nullopt});
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

  // One enlargement for all panels: the largest move spans kArrowFill of the
  // widest panel.
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
  const double enlarge = largest_mm > 0 ? NiceFloor(kArrowFill * span_mm / largest_mm) : 1;
  const double pad_mm = std::max(0.08 * span_mm, enlarge * largest_mm);
  double x = kMarginPx, height = 0;
  for (Panel& p : panels) {
    p.x0 -= pad_mm;
    p.x1 += pad_mm;
    p.y0 -= pad_mm;
    p.y1 += pad_mm;
    p.scale = kPanelPx / std::max(p.x1 - p.x0, p.y1 - p.y0);
    p.width = (p.x1 - p.x0) * p.scale;
    p.height = (p.y1 - p.y0) * p.scale;
    p.left = x;
    p.top = 110;
    x += p.width + kMarginPx;
    height = std::max(height, p.height);
  }
  const double width = std::max(x + 80, 900.0);  // room for the labels of the rightmost targets
  const double total_height = 110 + height + 70;

  // The largest moves get labels.
  std::vector<const Change*> ranked;
  for (const Change& c : diff.changes) {
    if (c.is_target && c.old_plot && c.new_plot && c.moved) ranked.push_back(&c);
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const Change* a, const Change* b) { return a->gate_um > b->gate_um; });
  if (ranked.size() > kLabelled) ranked.resize(kLabelled);

  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\">\n",
      Num(width), Num(total_height));
  svg += "  <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg += fmt::format("  <text x=\"{}\" y=\"28\" font-size=\"17\" font-weight=\"bold\">What moves: {} -&gt; {}</text>\n",
                     Num(kMarginPx), SvgEscape(diff.old_file), SvgEscape(diff.new_file));
  svg += fmt::format(
      "  <text x=\"{}\" y=\"50\" fill=\"#333\">grey: unchanged; blue dot and arrow: moved, old position to new, "
      "the arrow {} times enlarged (red: more than {} µm)</text>\n",
      Num(kMarginPx), fmt::format("{:g}", enlarge), Um(diff.threshold_um));
  svg += fmt::format(
      "  <text x=\"{}\" y=\"68\" fill=\"#333\">green +: added; red ×: removed. Coordinates in mm; "
      "{}</text>\n",
      Num(kMarginPx),
      diff.base_frame_known ? "fixture targets at the fixtures' nominal poses (--cell)"
                            : "fixture targets in their fixture's frame (no --cell)");
  if (panels.empty()) {
    svg += fmt::format("  <text x=\"{}\" y=\"130\">no target has a static position to draw</text>\n", Num(kMarginPx));
  }
  for (const Panel& p : panels) {
    svg += fmt::format("  <!-- panel: {} -->\n", SvgEscape(p.frame));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"14\" font-weight=\"bold\">{} ({} targets)</text>\n",
                       Num(p.left), Num(p.top - 12), SvgEscape(p.frame), p.marks.size());
    svg += fmt::format("  <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#999\"/>\n",
                       Num(p.left), Num(p.top), Num(p.width), Num(p.height));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" fill=\"#555\">x {}..{} mm, y {}..{} mm</text>\n", Num(p.left),
                       Num(p.top + p.height + 16), Num(p.x0), Num(p.x1), Num(p.y0), Num(p.y1));
    svg += "  <g>\n";
    for (const Mark& m : p.marks) {
      double px = p.Px(m.at[0]), py = p.Py(m.at[1]);
      if (m.change == nullptr) {
        svg += fmt::format("    <circle cx=\"{}\" cy=\"{}\" r=\"2.2\" fill=\"#aaa\"/>\n", Num(px), Num(py));
      } else if (m.change->kind == ChangeKind::kAdded) {
        svg += fmt::format("    <path d=\"M{} {}h10M{} {}v10\" stroke=\"#1a9641\" stroke-width=\"2\"/>\n",
                           Num(px - 5), Num(py), Num(px), Num(py - 5));
      } else if (m.change->kind == ChangeKind::kRemoved) {
        svg += fmt::format("    <path d=\"M{} {}l8 8M{} {}l-8 8\" stroke=\"#d7191c\" stroke-width=\"2\"/>\n",
                           Num(px - 4), Num(py - 4), Num(px + 4), Num(py - 4));
      } else {
        svg += fmt::format("    <circle cx=\"{}\" cy=\"{}\" r=\"2.6\" fill=\"#2b83ba\"/>\n", Num(px), Num(py));
        if (m.to) {
          double tx = m.at[0] + enlarge * ((*m.to)[0] - m.at[0]);
          double ty = m.at[1] + enlarge * ((*m.to)[1] - m.at[1]);
          Arrow(svg, px, py, p.Px(tx), p.Py(ty), m.change->beyond_threshold ? "#d7191c" : "#2b83ba");
        }
      }
    }
    for (std::size_t rank = 0; rank < ranked.size(); ++rank) {
      const Change* c = ranked[rank];
      if (c->plot_frame != p.frame) continue;
      double tx = (*c->old_plot)[0] + enlarge * ((*c->new_plot)[0] - (*c->old_plot)[0]);
      double ty = (*c->old_plot)[1] + enlarge * ((*c->new_plot)[1] - (*c->old_plot)[1]);
      svg += fmt::format("    <text x=\"{}\" y=\"{}\" font-size=\"11\">{}: {} µm</text>\n", Num(p.Px(tx) + 6),
                         Num(p.Py(ty) + (rank % 2 == 0 ? -4.0 : 12.0)), SvgEscape(ShortName(*c)), Um(c->gate_um));
    }
    svg += "  </g>\n";
  }
  // The scale bar: an arrow of a round number of µm, enlarged like the others.
  if (largest_mm > 0 && !panels.empty()) {
    const Panel& p = panels.front();
    double bar_um = NiceFloor(largest_mm * kUmPerMm);
    double bar_px = bar_um / kUmPerMm * enlarge * p.scale;
    double y = p.top + p.height + 44;
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
