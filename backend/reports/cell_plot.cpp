// The picture of a cell (see cell_plot.h). Plain SVG 1.1, no external
// assets; coordinates printed with 2 decimals. Every panel maps the robot
// base frame (mm, y up) onto its own area with one scale for x and y, so
// shapes are true to size.
#include "backend/reports/cell_plot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "backend/reports/svg_text.h"
#include "calibration/fixture_geometry.h"

namespace smtcal {
namespace {

// Colours (ColorBrewer-like, distinct in print and for the colour-blind).
constexpr std::string_view kTravel = "#8c8c8c";
constexpr std::string_view kRegion = "#3f7cb8", kRegionFill = "#dbe8f5";
constexpr std::string_view kFixture = "#d9822b";
constexpr std::string_view kMarker = "#b2182b";
constexpr std::string_view kPocket = "#1a9641";
constexpr std::string_view kFeeder = "#7b3294";
constexpr std::string_view kPlace = "#1b1b1b";
constexpr std::string_view kFinding = "#e31a1c";  // errors and warnings: red, the picture's only red fill

constexpr double kLeft = 70;          // room for the y ticks
constexpr double kPanelWidth = 760;   // the widest a panel's plot area gets
constexpr double kGapBelow = 96;      // below a plot area: x ticks, axis name, scale bar
constexpr double kTitleHeight = 34;   // above a plot area: its title
constexpr double kLegendWidth = 300;
constexpr double kFindingRadius = 7;   // px: the ring around a finding's place
constexpr double kFindingRow = 16;     // px: one line of the findings' list
constexpr double kListCharPx = 6.2;    // px: a generous character of the list's 11 px text
constexpr std::size_t kFindingLines = 4;  // a finding's words take at most this many lines

std::string Num(double v) { return SvgNum(v); }

struct Box {
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  void Add(double x, double y) {
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
  }
  void Add(const Eigen::Vector2d& p) { Add(p.x(), p.y()); }
  bool empty() const { return !(x0 <= x1); }
  double w() const { return x1 - x0; }
  double h() const { return y1 - y0; }
  // Grown by `fraction` of its larger side on every side (at least `at_least` mm).
  Box Padded(double fraction, double at_least) const {
    const double m = std::max(at_least, fraction * std::max(w(), h()));
    return {x0 - m, y0 - m, x1 + m, y1 + m};
  }
};

// One panel: a world box drawn into a plot area.
struct View {
  Box world;
  double left = 0, top = 0, scale = 1;  // px per mm
  double width() const { return world.w() * scale; }
  double height() const { return world.h() * scale; }
  double Px(double x) const { return left + (x - world.x0) * scale; }
  double Py(double y) const { return top + (world.y1 - y) * scale; }
  std::string P(const Eigen::Vector2d& p) const { return Num(Px(p.x())) + "," + Num(Py(p.y())); }
};

View Fit(const Box& world, double left, double top, double max_width, double max_height) {
  View view;
  view.world = world;
  view.left = left;
  view.top = top;
  view.scale = std::min(max_width / world.w(), max_height / world.h());
  return view;
}

// The pick points of a feeder in Pallet(n, k) order.
std::vector<Eigen::Vector2d> PickPoints(const cell::Feeder& feeder) {
  std::vector<Eigen::Vector2d> points;
  for (int k = 1; k <= feeder.pick_points(); ++k) {
    const std::array<double, 4> p = feeder.PickPoint(k);
    points.emplace_back(p[0], p[1]);
  }
  return points;
}

// The fixture frame's corners S1, S2, S2 + S3 - S1, S3 in the base frame.
std::array<Eigen::Vector2d, 4> FrameCorners(const cell::Fixture& fixture) {
  const Eigen::Affine3d fix = NominalFix(fixture);
  return {ToBase(fix, {0, 0}), ToBase(fix, {fixture.l1_mm, 0}), ToBase(fix, {fixture.l1_mm, fixture.l2_mm}),
          ToBase(fix, {0, fixture.l2_mm})};
}

std::array<Eigen::Vector2d, 4> PocketCorners(const cell::Fixture& fixture) {
  const Eigen::Affine3d fix = NominalFix(fixture);
  const auto& [x, y] = *fixture.pocket_mm;
  return {ToBase(fix, {x.lo, y.lo}), ToBase(fix, {x.hi, y.lo}), ToBase(fix, {x.hi, y.hi}), ToBase(fix, {x.lo, y.hi})};
}

// A name to write beside a mark of the picture (px). Labels are placed
// after every mark of a panel is drawn, so none covers a mark or another
// label: each tries places around its mark, nearest first (its preferred
// side first), and is drawn with a thin leader line when it had to move
// away or to another side; one that finds no room is left out and counted (the panel says how
// many).
struct Label {
  std::string text;
  double x = 0, y = 0;  // the mark, px
  double font = 9;
  std::string_view color = "#000";
  int prefer = 0;       // index into kDirections: the side it is tried on first
  double gap = 3;       // px between the mark and the text
};

struct Rect {
  double x0, y0, x1, y1;
  bool Overlaps(const Rect& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  bool Inside(const Rect& o) const { return x0 >= o.x0 && x1 <= o.x1 && y0 >= o.y0 && y1 <= o.y1; }
};

// Right, left, above, below, then the diagonals (screen directions, y down).
constexpr std::array<std::array<int, 2>, 8> kDirections = {
    {{1, 0}, {-1, 0}, {0, -1}, {0, 1}, {1, -1}, {-1, -1}, {1, 1}, {-1, 1}}};
constexpr int kSideRight = 0, kSideLeft = 1, kSideAbove = 2, kSideBelow = 3, kSideBelowRight = 6;

class LabelPlacer {
 public:
  explicit LabelPlacer(const Rect& area) : area_(area) {}

  // A mark labels must not cover (a square of half side `half` around x, y).
  void Block(double x, double y, double half) { taken_.push_back({x - half, y - half, x + half, y + half}); }
  void Add(Label label) { labels_.push_back(std::move(label)); }
  // A label placed before every other (a finding's number).
  void AddFirst(Label label) { labels_.insert(labels_.begin() + static_cast<std::ptrdiff_t>(first_++), std::move(label)); }

  // Places the labels in the order they were added; returns how many found
  // no room.
  int Draw(std::string& svg) {
    int left_out = 0;
    for (const Label& label : labels_) {
      // A mark outside the panel (clipped away) is not named here.
      if (label.x < area_.x0 || label.x > area_.x1 || label.y < area_.y0 || label.y > area_.y1) continue;
      // Text extent: a generous average glyph width of a sans-serif face.
      const double w = 0.6 * label.font * static_cast<double>(Utf8Columns(label.text)), h = label.font;
      bool placed = false;
      for (double ring : {0.0, 6.0, 14.0, 26.0, 40.0}) {
        for (std::size_t i = 0; i < kDirections.size() && !placed; ++i) {
          const auto& [ux, uy] = kDirections[(static_cast<std::size_t>(label.prefer) + i) % kDirections.size()];
          const double r = label.gap + ring;
          const double cx = label.x + ux * (r + w / 2), cy = label.y + uy * (r + h / 2);
          const Rect box{cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2};
          if (!box.Inside(area_) ||
              std::any_of(taken_.begin(), taken_.end(), [&](const Rect& t) { return t.Overlaps(box); })) {
            continue;
          }
          taken_.push_back(box);
          // Away from its mark, or on another side than its own: a leader
          // says whose name it is.
          if (ring > 0 || i > 0) {
            const double px = std::clamp(label.x, box.x0, box.x1), py = std::clamp(label.y, box.y0, box.y1);
            svg += fmt::format("    <line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#888\" stroke-width=\"0.5\"/>\n",
                               Num(label.x), Num(label.y), Num(px), Num(py));
          }
          svg += fmt::format(
              "    <text x=\"{}\" y=\"{}\" font-size=\"{}\" fill=\"{}\" stroke=\"white\" stroke-width=\"2\" "
              "paint-order=\"stroke\">{}</text>\n",
              Num(box.x0), Num(cy + 0.35 * h), Num(label.font), label.color, SvgEscape(label.text));
          placed = true;
        }
        if (placed) break;
      }
      if (!placed) ++left_out;
    }
    return left_out;
  }

 private:
  Rect area_;
  std::vector<Rect> taken_;
  std::vector<Label> labels_;
  std::size_t first_ = 0;  // labels added with AddFirst
};

class CellPainter {
 public:
  CellPainter(const cell::Cell& cell, const std::vector<PlottedTarget>& targets,
              const std::vector<PlotFinding>& findings)
      : cell_(cell), targets_(targets), findings_(findings) {}

  // What the whole-cell panel shows: the travel and everything in the cell.
  Box CellBox() const {
    Box box;
    const auto& limits = cell_.robot.limits;
    box.Add(limits[0].lo, limits[1].lo);
    box.Add(limits[0].hi, limits[1].hi);
    for (const cell::Region& region : cell_.regions) {
      box.Add(region.domain.x0, region.domain.y0);
      box.Add(region.domain.x1, region.domain.y1);
    }
    for (std::size_t f = 0; f < cell_.fixtures.size(); ++f) AddFixture(box, f);
    AddFeeders(box);
    for (const PlottedTarget& target : targets_) box.Add(target.x_mm, target.y_mm);
    for (const PlotFinding& finding : findings_) {
      for (const Eigen::Vector2d& p : finding.marks_mm) box.Add(p);
    }
    return box.Padded(0.04, 5);
  }
  Box FixtureBox(std::size_t f) const {
    Box box;
    AddFixture(box, f);
    for (const PlottedTarget& target : targets_) {
      if (target.fixture == static_cast<int>(f)) box.Add(target.x_mm, target.y_mm);
    }
    return box.Padded(0.05, 4);
  }
  Box FeedersBox() const {
    Box box;
    AddFeeders(box);
    return box.empty() ? box : box.Padded(0.12, 6);
  }

  // Everything, into one panel; `detail` numbers trips and lanes and names
  // the placements (the close-ups). Returns how many names found no room.
  // The group carries the panel's mapping from mm to px (cell_plot.h).
  int Draw(std::string& svg, const View& view, const std::string& clip, bool detail) const {
    svg += fmt::format(
        "  <g clip-path=\"url(#{})\" data-x0-mm=\"{}\" data-y1-mm=\"{}\" data-px-per-mm=\"{}\" "
        "data-left-px=\"{}\" data-top-px=\"{}\">\n",
        clip, fmt::format("{:.6f}", view.world.x0), fmt::format("{:.6f}", view.world.y1),
        fmt::format("{:.9f}", view.scale), Num(view.left), Num(view.top));
    LabelPlacer labels({view.left + 2, view.top + 2, view.left + view.width() - 2, view.top + view.height() - 2});
    DrawTravel(svg, view);
    DrawRegions(svg, view, detail, labels);
    for (std::size_t f = 0; f < cell_.fixtures.size(); ++f) DrawFixture(svg, view, cell_.fixtures[f], detail, labels);
    DrawFeeders(svg, view, detail, labels);
    DrawTargets(svg, view, detail, labels);
    DrawFindings(svg, view, labels);
    const int left_out = labels.Draw(svg);
    svg += "  </g>\n";
    return left_out;
  }

 private:
  void AddFixture(Box& box, std::size_t f) const {
    const cell::Fixture& fixture = cell_.fixtures[f];
    for (const Eigen::Vector2d& corner : FrameCorners(fixture)) box.Add(corner);
    for (const auto& path : ScanPathsInBase(fixture, NominalFix(fixture))) {
      for (const Eigen::Vector2d& p : path) box.Add(p);
    }
    if (fixture.pocket_mm) {
      for (const Eigen::Vector2d& corner : PocketCorners(fixture)) box.Add(corner);
    }
  }
  void AddFeeders(Box& box) const {
    for (const cell::Feeder& feeder : cell_.feeders) {
      for (const Eigen::Vector2d& p : PickPoints(feeder)) box.Add(p);
    }
  }

  void DrawTravel(std::string& svg, const View& view) const {
    const auto& limits = cell_.robot.limits;
    svg += fmt::format(
        "    <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" "
        "stroke-dasharray=\"8 4\"/>\n",
        Num(view.Px(limits[0].lo)), Num(view.Py(limits[1].hi)), Num((limits[0].hi - limits[0].lo) * view.scale),
        Num((limits[1].hi - limits[1].lo) * view.scale), kTravel);
  }

  void DrawRegions(std::string& svg, const View& view, bool detail, LabelPlacer& labels) const {
    for (const cell::Region& region : cell_.regions) {
      svg += fmt::format(
          "    <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"0.8\" "
          "stroke-dasharray=\"3 2\"/>\n",
          Num(view.Px(region.domain.x0)), Num(view.Py(region.domain.y1)),
          Num((region.domain.x1 - region.domain.x0) * view.scale), Num((region.domain.y1 - region.domain.y0) * view.scale),
          "none", kRegion);
      svg += fmt::format(
          "    <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\" fill-opacity=\"0.75\" stroke=\"{}\" "
          "stroke-width=\"1\"/>\n",
          Num(view.Px(region.x_mm.lo)), Num(view.Py(region.y_mm.hi)), Num((region.x_mm.hi - region.x_mm.lo) * view.scale),
          Num((region.y_mm.hi - region.y_mm.lo) * view.scale), kRegionFill, kRegion);
      // The name inside the region's upper left corner.
      const double font = detail ? 11 : 10;
      labels.Add({region.name, view.Px(region.x_mm.lo) + 1, view.Py(region.y_mm.hi) + 1, font, kRegion, kSideBelowRight, 0});
    }
  }

  void DrawFixture(std::string& svg, const View& view, const cell::Fixture& fixture, bool detail,
                   LabelPlacer& labels) const {
    const Eigen::Affine3d fix = NominalFix(fixture);
    const std::array<Eigen::Vector2d, 4> frame = FrameCorners(fixture);
    svg += fmt::format("    <polygon points=\"{} {} {} {}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\" "
                       "stroke-dasharray=\"6 3\"/>\n",
                       view.P(frame[0]), view.P(frame[1]), view.P(frame[2]), view.P(frame[3]), kFixture);
    if (fixture.pocket_mm) {
      const std::array<Eigen::Vector2d, 4> pocket = PocketCorners(fixture);
      svg += fmt::format("    <polygon points=\"{} {} {} {}\" fill=\"{}\" fill-opacity=\"0.10\" stroke=\"{}\" "
                         "stroke-width=\"1.2\" stroke-dasharray=\"4 2\"/>\n",
                         view.P(pocket[0]), view.P(pocket[1]), view.P(pocket[2]), view.P(pocket[3]), kPocket, kPocket);
      if (detail) labels.Add({"pocket", view.Px(pocket[3].x()), view.Py(pocket[3].y()), 10, kPocket, kSideBelowRight, 2});
    }
    for (const auto& path : ScanPathsInBase(fixture, fix)) {
      std::string points;
      for (const Eigen::Vector2d& p : path) points += (points.empty() ? "" : " ") + view.P(p);
      svg += fmt::format("    <polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\"/>\n", points,
                         kFixture);
      svg += fmt::format("    <circle cx=\"{}\" cy=\"{}\" r=\"2.5\" fill=\"{}\"/>\n", Num(view.Px(path.front().x())),
                         Num(view.Py(path.front().y())), kFixture);
      labels.Block(view.Px(path.front().x()), view.Py(path.front().y()), 2.5);
    }
    for (const cell::MarkerEdge& edge : fixture.edges) {
      const Eigen::Vector2d a = ToBase(fix, edge.from), b = ToBase(fix, edge.to);
      svg += fmt::format("    <line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{}\" stroke-width=\"2.5\" "
                         "stroke-linecap=\"round\"/>\n",
                         Num(view.Px(a.x())), Num(view.Py(a.y())), Num(view.Px(b.x())), Num(view.Py(b.y())), kMarker);
      if (detail) {
        labels.Add({edge.name, view.Px((a.x() + b.x()) / 2), view.Py((a.y() + b.y()) / 2), 9, kMarker, kSideAbove, 3});
      }
    }
    const std::vector<Eigen::Vector2d> trips = NominalTrips(fixture, fix);
    for (std::size_t k = 0; k < trips.size(); ++k) {
      const double x = view.Px(trips[k].x()), y = view.Py(trips[k].y()), r = 3;
      svg += fmt::format("    <path d=\"M{} {}L{} {}M{} {}L{} {}\" stroke=\"#000\" stroke-width=\"1.2\"/>\n", Num(x - r),
                         Num(y - r), Num(x + r), Num(y + r), Num(x - r), Num(y + r), Num(x + r), Num(y - r));
      labels.Block(x, y, r);
    }
    // The fixture's name at S1 in the overview (a close-up's title names
    // it); in a close-up S1, S2, S3 and the trips.
    if (!detail) {
      labels.Add({"fixture " + fixture.name, view.Px(frame[0].x()), view.Py(frame[0].y()), 10, kFixture, kSideBelowRight, 2});
      return;
    }
    const std::array<std::string_view, 4> corner_names = {"S1", "S2", "", "S3"};
    const std::array<int, 4> corner_side = {kSideBelowRight, 7, 0, 4};  // S1, S2 below the frame; S3 above
    for (std::size_t c = 0; c < 4; ++c) {
      if (corner_names[c].empty()) continue;
      labels.Add({std::string(corner_names[c]), view.Px(frame[c].x()), view.Py(frame[c].y()), 10, kFixture,
                  corner_side[c], 3});
    }
    // Trips closer than a mark's width (0.2 mm apart, a leg's way in and its
    // way out) are one mark: one label names them all, "T2, T3".
    std::vector<bool> named(trips.size(), false);
    for (std::size_t k = 0; k < trips.size(); ++k) {
      if (named[k]) continue;
      std::string text = TripName(k);
      for (std::size_t j = k + 1; j < trips.size(); ++j) {
        if (!named[j] && (trips[j] - trips[k]).norm() * view.scale < 6) {
          named[j] = true;
          text += ", " + TripName(j);
        }
      }
      labels.Add({text, view.Px(trips[k].x()), view.Py(trips[k].y()), 9, "#000", k % 2 == 0 ? kSideRight : kSideLeft, 4});
    }
  }

  void DrawFeeders(std::string& svg, const View& view, bool detail, LabelPlacer& labels) const {
    for (const cell::Feeder& feeder : cell_.feeders) {
      const std::vector<Eigen::Vector2d> points = PickPoints(feeder);
      const double half = detail ? 3.5 : 2.5;
      Box box;
      for (std::size_t k = 0; k < points.size(); ++k) {
        const double x = view.Px(points[k].x()), y = view.Py(points[k].y());
        box.Add(points[k]);
        svg += fmt::format("    <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"/>\n", Num(x - half),
                           Num(y - half), Num(2 * half), Num(2 * half), kFeeder);
        labels.Block(x, y, half);
        if (detail && points.size() > 1) labels.Add({std::to_string(k + 1), x, y, 9, "#000", kSideBelow, half + 1});
      }
      const std::string kind = feeder.kind == cell::FeederKind::kTray ? "tray" : points.size() > 1 ? "tapes" : "tape";
      const std::string slots = feeder.kind == cell::FeederKind::kTray ? "pockets" : "lanes";
      const std::string name =
          detail && points.size() > 1
              ? fmt::format("{} ({} {}, {} 1..{})", feeder.name, points.size(), kind, slots, points.size())
              : feeder.name;
      // Above the feeder's upper left pick point.
      labels.Add({name, view.Px(box.x0) - half, view.Py(box.y1) - half, detail ? 11.0 : 10.0, kFeeder, 4, 2});
    }
  }

  void DrawTargets(std::string& svg, const View& view, bool detail, LabelPlacer& labels) const {
    for (const PlottedTarget& target : targets_) {
      if (!target.place) continue;
      const double x = view.Px(target.x_mm), y = view.Py(target.y_mm);
      const double r = detail ? 2.2 : 1.6;
      // The part's orientation: a tick from the dot toward its u (0° along
      // +x, counter-clockwise; y is up in the world, down on the screen).
      const double tick = detail ? 7 : 4.5, u = target.u_deg * std::numbers::pi / 180;
      svg += fmt::format("    <line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{}\" stroke-width=\"{}\"/>\n",
                         Num(x), Num(y), Num(x + tick * std::cos(u)), Num(y - tick * std::sin(u)), kPlace,
                         detail ? 1.1 : 0.8);
      svg += fmt::format("    <circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\"/>\n", Num(x), Num(y), r, kPlace);
      labels.Block(x, y, r);
      labels.Block(x + tick * std::cos(u), y - tick * std::sin(u), 1);
      if (!detail) continue;
      const std::string name =
          target.runs > 1 ? fmt::format("{} ({}/{})", target.name, target.run, target.runs) : target.name;
      labels.Add({name, x, y, 7, "#333", kSideRight, tick + 2});  // clear of the tick
    }
  }

  // Every finding's places: a red ring each (a shape it concerns outlined
  // in red), numbered as in the list below the panels.
  void DrawFindings(std::string& svg, const View& view, LabelPlacer& labels) const {
    for (std::size_t i = 0; i < findings_.size(); ++i) {
      const PlotFinding& finding = findings_[i];
      if (finding.outline_mm.size() > 1) {
        std::string points;
        for (const Eigen::Vector2d& p : finding.outline_mm) points += (points.empty() ? "" : " ") + view.P(p);
        svg += fmt::format("    <polygon points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\" "
                           "stroke-dasharray=\"5 3\"/>\n",
                           points, kFinding);
      }
      for (const Eigen::Vector2d& p : finding.marks_mm) {
        const double x = view.Px(p.x()), y = view.Py(p.y());
        svg += fmt::format(
            "    <circle class=\"finding\" data-finding=\"{}\" data-kind=\"{}\" data-x-mm=\"{}\" data-y-mm=\"{}\" "
            "cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"/>\n",
            i + 1, DiagKindName(finding.kind), fmt::format("{:.4f}", p.x()), fmt::format("{:.4f}", p.y()), Num(x),
            Num(y), Num(kFindingRadius), kFinding, finding.severity == Severity::Error ? 2.5 : 1.5);
        labels.Block(x, y, kFindingRadius);
        labels.AddFirst({std::to_string(i + 1), x, y, 10, kFinding, kSideAbove, kFindingRadius});
      }
    }
  }

  const cell::Cell& cell_;
  const std::vector<PlottedTarget>& targets_;
  const std::vector<PlotFinding>& findings_;
};

// Axes in mm around a plot area, ticks at round numbers, and a scale bar.
void DrawAxes(std::string& svg, const View& view) {
  const double width = view.width(), height = view.height();
  svg += fmt::format("  <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444\"/>\n",
                     Num(view.left), Num(view.top), Num(width), Num(height));
  const double step = SvgTickStep(std::max(view.world.w(), view.world.h()), 8);
  for (double x : SvgTicks(view.world.x0, view.world.x1, step)) {
    svg += fmt::format("  <line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#444\"/>\n", Num(view.Px(x)),
                       Num(view.top + height), Num(view.top + height + 5));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", Num(view.Px(x)),
                       Num(view.top + height + 18), SvgTickText(x, step));
  }
  for (double y : SvgTicks(view.world.y0, view.world.y1, step)) {
    svg += fmt::format("  <line x1=\"{0}\" y1=\"{2}\" x2=\"{1}\" y2=\"{2}\" stroke=\"#444\"/>\n", Num(view.left - 5),
                       Num(view.left), Num(view.Py(y)));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" text-anchor=\"end\">{}</text>\n", Num(view.left - 8),
                       Num(view.Py(y) + 4), SvgTickText(y, step));
  }
  svg += fmt::format("  <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">x (mm, robot base frame)</text>\n",
                     Num(view.left + width / 2), Num(view.top + height + 36));
  svg += fmt::format(
      "  <text x=\"{0}\" y=\"{1}\" text-anchor=\"middle\" transform=\"rotate(-90 {0} {1})\">y (mm)</text>\n",
      Num(view.left - 50), Num(view.top + height / 2));
  // The scale bar: a round length near a fifth of the panel.
  const double bar_mm = SvgTickStep(view.world.w() / 5, 1);
  const double bar_y = view.top + height + 62;
  svg += fmt::format("  <path d=\"M{0} {1}V{2}H{3}V{1}\" fill=\"none\" stroke=\"#000\" stroke-width=\"1.5\"/>\n",
                     Num(view.left), Num(bar_y - 5), Num(bar_y), Num(view.left + bar_mm * view.scale));
  svg += fmt::format("  <text x=\"{}\" y=\"{}\">{} mm</text>\n", Num(view.left + bar_mm * view.scale + 8),
                     Num(bar_y + 1), SvgTickText(bar_mm, bar_mm));
}

void DrawLegend(std::string& svg, double x, double y, bool program, bool findings) {
  struct Entry {
    std::string mark;
    std::string_view text;
  };
  const double mx = x + 14;
  std::vector<Entry> entries = {
      {fmt::format("<line x1=\"{}\" y1=\"0\" x2=\"{}\" y2=\"0\" stroke=\"{}\" stroke-width=\"1.5\" "
                   "stroke-dasharray=\"8 4\"/>",
                   Num(mx - 12), Num(mx + 12), kTravel),
       "the robot's travel (x_mm, y_mm of [robot])"},
      {fmt::format("<rect x=\"{}\" y=\"-6\" width=\"24\" height=\"12\" fill=\"{}\" stroke=\"{}\"/>", Num(mx - 12),
                   kRegionFill, kRegion),
       "a calibrated region: its bounds"},
      {fmt::format("<rect x=\"{}\" y=\"-6\" width=\"24\" height=\"12\" fill=\"none\" stroke=\"{}\" "
                   "stroke-width=\"0.8\" stroke-dasharray=\"3 2\"/>",
                   Num(mx - 12), kRegion),
       "its error table's extent (domain)"},
      {fmt::format("<line x1=\"{}\" y1=\"0\" x2=\"{}\" y2=\"0\" stroke=\"{}\" stroke-width=\"1.2\" "
                   "stroke-dasharray=\"6 3\"/>",
                   Num(mx - 12), Num(mx + 12), kFixture),
       "a fixture at its nominal pose: S1, S2, S3"},
      {fmt::format("<line x1=\"{}\" y1=\"0\" x2=\"{}\" y2=\"0\" stroke=\"{}\" stroke-width=\"2.5\"/>", Num(mx - 12),
                   Num(mx + 12), kMarker),
       "a marker edge the sensor sees (p1..p4)"},
      {fmt::format("<line x1=\"{}\" y1=\"0\" x2=\"{}\" y2=\"0\" stroke=\"{}\" stroke-width=\"1.2\"/><circle cx=\"{}\" "
                   "cy=\"0\" r=\"2.5\" fill=\"{}\"/>",
                   Num(mx - 12), Num(mx + 12), kFixture, Num(mx - 12), kFixture),
       "a scan path (from its dot)"},
      {fmt::format("<path d=\"M{} -3L{} 3M{} 3L{} -3\" stroke=\"#000\" stroke-width=\"1.2\"/>", Num(mx - 3), Num(mx + 3),
                   Num(mx - 3), Num(mx + 3)),
       "a nominal trip of the scan (T1, T2, ...)"},
      {fmt::format("<rect x=\"{}\" y=\"-6\" width=\"24\" height=\"12\" fill=\"{}\" fill-opacity=\"0.10\" "
                   "stroke=\"{}\" stroke-dasharray=\"4 2\"/>",
                   Num(mx - 12), kPocket, kPocket),
       "the pocket boards go in (pocket_x_mm, _y_mm)"},
      {fmt::format("<rect x=\"{}\" y=\"-3.5\" width=\"7\" height=\"7\" fill=\"{}\"/>", Num(mx - 3.5), kFeeder),
       "a feeder's pick point (lane or pocket k)"},
  };
  if (program) {
    entries.push_back({fmt::format("<circle cx=\"{}\" cy=\"0\" r=\"2.2\" fill=\"{}\"/><line x1=\"{}\" y1=\"0\" "
                                   "x2=\"{}\" y2=\"0\" stroke=\"{}\" stroke-width=\"1.1\"/>",
                                   Num(mx), kPlace, Num(mx), Num(mx + 7), kPlace),
                       "a placement (nominal pose), tick: its u"});
  }
  if (findings) {
    entries.push_back({fmt::format("<circle cx=\"{}\" cy=\"0\" r=\"{}\" fill=\"none\" stroke=\"{}\" "
                                   "stroke-width=\"2.5\"/>",
                                   Num(mx), Num(kFindingRadius), kFinding),
                       "an error where it is (numbered, listed below)"});
    entries.push_back({fmt::format("<circle cx=\"{}\" cy=\"0\" r=\"{}\" fill=\"none\" stroke=\"{}\" "
                                   "stroke-width=\"1.5\"/>",
                                   Num(mx), Num(kFindingRadius), kFinding),
                       "a warning where it is (numbered, listed below)"});
  }
  svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"13\" font-weight=\"bold\">Legend</text>\n", Num(x),
                     Num(y));
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double row = y + 24 + 22 * static_cast<double>(i);
    svg += fmt::format("  <g transform=\"translate(0 {})\">{}<text x=\"{}\" y=\"4\" font-size=\"11\">{}</text></g>\n",
                       Num(row), entries[i].mark, Num(x + 36), SvgEscape(entries[i].text));
  }
}

// A finding's words wrapped into lines of at most `chars` characters (a
// word longer than a line gets a line of its own), at most `max_lines` of
// them, the last ending in "…" when words were left.
std::vector<std::string> Wrapped(const std::string& text, std::size_t chars, std::size_t max_lines) {
  std::vector<std::string> lines(1);
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    start = end + 1;
    if (!lines.back().empty() && Utf8Columns(lines.back()) + 1 + Utf8Columns(word) > chars) {
      if (lines.size() == max_lines) {
        lines.back() += " …";
        return lines;
      }
      lines.emplace_back();
    }
    lines.back() += (lines.back().empty() ? "" : " ") + word;
  }
  return lines;
}

// The list's lines: per finding, its head (severity, kind, where, what is
// marked) and its words wrapped to the picture's width.
std::vector<std::vector<std::string>> FindingLines(const std::vector<PlotFinding>& findings, double width) {
  const std::size_t chars = static_cast<std::size_t>(std::max(60.0, (width - 20 - 24 - 20) / kListCharPx));
  std::vector<std::vector<std::string>> out;
  for (const PlotFinding& finding : findings) {
    std::vector<std::string> lines = {fmt::format(
        "{} {}{}{}{}", SeverityName(finding.severity), DiagKindName(finding.kind),
        finding.where.empty() ? "" : " at " + finding.where,
        finding.subject.empty() ? "" : fmt::format(": {}", finding.subject),
        finding.marks_mm.empty() ? " [not drawn]" : "")};
    for (std::string& line : Wrapped(finding.message, chars, kFindingLines)) lines.push_back(std::move(line));
    out.push_back(std::move(lines));
  }
  return out;
}

double FindingListHeight(const std::vector<std::vector<std::string>>& lines) {
  double height = 20;
  for (const auto& finding : lines) height += kFindingRow * static_cast<double>(finding.size()) + 4;
  return height;
}

// The findings under the panels: number, severity, kind, where, what is
// marked (bold), then the diagnostic's words.
void DrawFindingList(std::string& svg, const std::vector<PlotFinding>& findings,
                     const std::vector<std::vector<std::string>>& lines, double x, double y) {
  std::size_t errors = 0, unmarked = 0;
  for (const PlotFinding& finding : findings) {
    errors += finding.severity == Severity::Error;
    unmarked += finding.marks_mm.empty();
  }
  svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"14\" font-weight=\"bold\">{} error{}, {} warning{}{}</text>\n",
                     Num(x), Num(y), errors, errors == 1 ? "" : "s", findings.size() - errors,
                     findings.size() - errors == 1 ? "" : "s",
                     unmarked == 0 ? std::string(": each ringed in red where it is")
                                   : fmt::format(", each ringed in red where it is ({} with no place in the picture: "
                                                 "listed only)",
                                                 unmarked));
  double row = y + 20;
  for (std::size_t i = 0; i < findings.size(); ++i) {
    svg += fmt::format("  <g class=\"finding-entry\" data-finding=\"{}\" font-size=\"11\">", i + 1);
    svg += fmt::format("<text x=\"{}\" y=\"{}\" font-weight=\"bold\" fill=\"{}\">{}</text>", Num(x), Num(row), kFinding,
                       i + 1);
    for (std::size_t l = 0; l < lines[i].size(); ++l) {
      svg += fmt::format("<text x=\"{}\" y=\"{}\"{}>{}</text>", Num(x + 24),
                         Num(row + kFindingRow * static_cast<double>(l)), l == 0 ? " font-weight=\"bold\"" : "",
                         SvgEscape(lines[i][l]));
    }
    svg += "</g>\n";
    row += kFindingRow * static_cast<double>(lines[i].size()) + 4;
  }
}

}  // namespace

std::string PlotCellSvg(const cell::Cell& cell, std::string_view title, std::string_view program,
                        const std::vector<PlottedTarget>& targets, const std::vector<PlotFinding>& findings,
                        std::string_view program_note) {
  CellPainter painter(cell, targets, findings);
  struct Panel {
    View view;
    std::string title;
    bool detail = false;
  };
  std::vector<Panel> panels;
  double top = 64 + kTitleHeight;
  const Box cell_box = painter.CellBox();
  panels.push_back({Fit(cell_box, kLeft, top, kPanelWidth, 520), "The cell: travel, regions, fixtures, feeders", false});
  top += panels.back().view.height() + kGapBelow + kTitleHeight;
  for (std::size_t f = 0; f < cell.fixtures.size(); ++f) {
    panels.push_back({Fit(painter.FixtureBox(f), kLeft, top, kPanelWidth, 480),
                      fmt::format("Fixture {} close up: markers, scan paths, trips{}", cell.fixtures[f].name,
                                  targets.empty() ? "" : ", placements"),
                      true});
    top += panels.back().view.height() + kGapBelow + kTitleHeight;
  }
  if (const Box feeders = painter.FeedersBox(); !feeders.empty()) {
    panels.push_back({Fit(feeders, kLeft, top, kPanelWidth, 300), "The feeders close up: lanes and pockets numbered (Pallet(n, k))",
                      true});
    top += panels.back().view.height() + kGapBelow + kTitleHeight;
  }
  const double width = kLeft + kPanelWidth + 40 + kLegendWidth;
  double height = top - kTitleHeight + 10;
  const double list_top = height + 10;
  const std::vector<std::vector<std::string>> finding_lines = FindingLines(findings, width);
  if (!findings.empty()) height = list_top + FindingListHeight(finding_lines) + 10;

  std::string svg;
  svg += fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\">\n",
      Num(width), Num(height));
  svg += "  <defs>\n";
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const View& view = panels[p].view;
    svg += fmt::format("    <clipPath id=\"panel{}\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/></clipPath>\n", p,
                       Num(view.left), Num(view.top), Num(view.width()), Num(view.height()));
  }
  svg += "  </defs>\n";
  svg += "  <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg += fmt::format("  <text x=\"20\" y=\"28\" font-size=\"17\" font-weight=\"bold\">Cell '{}' ({})</text>\n",
                     SvgEscape(cell.name), SvgEscape(title));
  svg += fmt::format(
      "  <text x=\"20\" y=\"50\" fill=\"#333\">robot base frame, mm, y up; robot {}{}</text>\n",
      SvgEscape(cell.robot.model.empty() ? std::string("(no model given)") : cell.robot.model),
      program.empty()        ? std::string()
      : program_note.empty() ? fmt::format("; the placements of {} at the fixture's nominal pose", SvgEscape(program))
                             : fmt::format("; {}", SvgEscape(program_note)));
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const Panel& panel = panels[p];
    svg += fmt::format("  <!-- panel: {} -->\n", SvgEscape(panel.title));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"14\" font-weight=\"bold\">{}</text>\n",
                       Num(panel.view.left), Num(panel.view.top - 10), SvgEscape(panel.title));
    const int left_out = painter.Draw(svg, panel.view, fmt::format("panel{}", p), panel.detail);
    DrawAxes(svg, panel.view);
    if (left_out > 0) {
      svg += fmt::format("  <text x=\"{}\" y=\"{}\" text-anchor=\"end\" font-size=\"11\" fill=\"#333\">{} name{} left "
                         "out: no room beside {} mark</text>\n",
                         Num(panel.view.left + panel.view.width()), Num(panel.view.top + panel.view.height() + 62),
                         left_out, left_out == 1 ? "" : "s", left_out == 1 ? "its" : "their");
    }
  }
  DrawLegend(svg, kLeft + kPanelWidth + 40, panels.front().view.top + 4, !targets.empty(), !findings.empty());
  if (!findings.empty()) DrawFindingList(svg, findings, finding_lines, 20, list_top);
  svg += "</svg>\n";
  return svg;
}

}  // namespace smtcal
