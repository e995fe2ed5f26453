// The error-table plot (see table_plot.h). Plain SVG 1.1 with no external
// assets: rectangles for the colour map, a linear gradient for the legend,
// lines and polygons for the arrows. Coordinates are printed with 2 decimals.
#include "backend/reports/table_plot.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "backend/reports/svg_text.h"
#include "base/check.h"

namespace smtcal {
namespace {

constexpr double kUmPerMm = 1000.0;
constexpr double kPlotPx = 400;       // the longer side of a panel's plot area
constexpr int kSubdivisions = 5;      // colour patches per cell side (smooth look)
constexpr double kArrowFill = 0.8;    // the longest arrow spans this much of a pitch
constexpr double kMarginLeft = 64, kMarginTop = 86, kLegendGap = 18, kLegendWidth = 14;
constexpr double kPanelGap = 70, kMarginBottom = 96;

// ColorBrewer RdBu, 7 classes, from -1 (blue) through 0 (near white) to +1 (red).
constexpr std::array<std::array<int, 3>, 7> kPalette = {{{33, 102, 172},
                                                         {103, 169, 207},
                                                         {209, 229, 240},
                                                         {247, 247, 247},
                                                         {253, 219, 199},
                                                         {239, 138, 98},
                                                         {178, 24, 43}}};

std::string Colour(double t) {  // t in [-1, 1]
  t = std::clamp(t, -1.0, 1.0);
  double position = (t + 1) / 2 * (kPalette.size() - 1);
  std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(position), kPalette.size() - 2);
  double f = position - static_cast<double>(k);
  int rgb[3];
  for (int c = 0; c < 3; ++c) {
    rgb[c] = static_cast<int>(std::lround(kPalette[k][c] * (1 - f) + kPalette[k + 1][c] * f));
  }
  return fmt::format("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]);
}

// The smallest of 1, 2, 2.5, 5 x 10^k that is >= v (v > 0).
double NiceCeil(double v) {
  double base = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (m * base >= v * (1 - 1e-12)) return m * base;
  }
  return 10 * base;
}
// The legend's range: v rounded up to a value whose half is round too
// (153 -> 160, 71 -> 80).
double LegendCeil(double v) {
  double base = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 1.2, 1.6, 2.0, 2.4, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0}) {
    if (m * base >= v * (1 - 1e-12)) return m * base;
  }
  return 10 * base;
}
// The largest of 1, 2, 5 x 10^k that is <= v (v > 0).
double NiceFloor(double v) {
  double base = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {5.0, 2.0, 1.0}) {
    if (m * base <= v * (1 + 1e-12)) return m * base;
  }
  return base;
}

std::string Num(double v) { return SvgNum(v); }

// A tick label: up to 3 decimals, trailing zeros dropped.
std::string Tick(double v) {
  std::string text = fmt::format("{:.3f}", v);
  while (text.back() == '0') text.pop_back();
  if (text.back() == '.') text.pop_back();
  return text == "-0" ? "0" : text;
}

struct Panel {
  TableAxis axis;
  double left, top;  // plot area, px
  double scale;      // px per mm
  double width, height;
  double pad_mm;     // room around the grid for the arrows
  const AxisTable* table;
  double x0() const { return table->xs.front() - pad_mm; }
  double y1() const { return table->ys.back() + pad_mm; }
  double Px(double x) const { return left + (x - x0()) * scale; }
  double Py(double y) const { return top + (y1() - y) * scale; }
};

double Bilinear(const AxisTable& t, std::size_t i, std::size_t j, double s, double u) {
  return (1 - u) * ((1 - s) * t.At(i, j) + s * t.At(i + 1, j)) +
         u * ((1 - s) * t.At(i, j + 1) + s * t.At(i + 1, j + 1));
}

void DrawColourMap(std::string& svg, const Panel& p, double range_mm) {
  const AxisTable& t = *p.table;
  svg += "  <g shape-rendering=\"crispEdges\">\n";
  for (std::size_t j = 0; j + 1 < t.ny(); ++j) {
    for (std::size_t i = 0; i + 1 < t.nx(); ++i) {
      for (int v = 0; v < kSubdivisions; ++v) {
        for (int u = 0; u < kSubdivisions; ++u) {
          double s0 = static_cast<double>(u) / kSubdivisions, s1 = static_cast<double>(u + 1) / kSubdivisions;
          double t0 = static_cast<double>(v) / kSubdivisions, t1 = static_cast<double>(v + 1) / kSubdivisions;
          double value = Bilinear(t, i, j, (s0 + s1) / 2, (t0 + t1) / 2);
          double xa = t.xs[i] + s0 * (t.xs[i + 1] - t.xs[i]), xb = t.xs[i] + s1 * (t.xs[i + 1] - t.xs[i]);
          double ya = t.ys[j] + t0 * (t.ys[j + 1] - t.ys[j]), yb = t.ys[j] + t1 * (t.ys[j + 1] - t.ys[j]);
          // A quarter pixel of overlap hides the seams between patches.
          svg += fmt::format("    <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"/>\n",
                             Num(p.Px(xa)), Num(p.Py(yb)), Num((xb - xa) * p.scale + 0.25),
                             Num((yb - ya) * p.scale + 0.25), Colour(value / range_mm));
        }
      }
    }
  }
  svg += "  </g>\n";
}

void DrawAxes(std::string& svg, const Panel& p) {
  const AxisTable& t = *p.table;
  svg += fmt::format("  <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444\"/>\n",
                     Num(p.left), Num(p.top), Num(p.width), Num(p.height));
  // Ticks at round numbers over the whole panel (the grid may start at 150.004).
  const double view_x0 = p.x0(), view_x1 = p.x0() + p.width / p.scale;
  const double view_y1 = p.y1(), view_y0 = p.y1() - p.height / p.scale;
  double span = std::max(t.xs.back() - t.xs.front(), t.ys.back() - t.ys.front());
  double step = NiceCeil(span / 6);
  for (double x = std::ceil(view_x0 / step) * step; x <= view_x1; x += step) {
    double px = p.Px(x);
    svg += fmt::format("  <line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#444\"/>\n", Num(px),
                       Num(p.top + p.height), Num(p.top + p.height + 5));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", Num(px),
                       Num(p.top + p.height + 19), Tick(x));
  }
  for (double y = std::ceil(view_y0 / step) * step; y <= view_y1; y += step) {
    double py = p.Py(y);
    svg += fmt::format("  <line x1=\"{0}\" y1=\"{2}\" x2=\"{1}\" y2=\"{2}\" stroke=\"#444\"/>\n",
                       Num(p.left - 5), Num(p.left), Num(py));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" text-anchor=\"end\">{}</text>\n", Num(p.left - 8),
                       Num(py + 4), Tick(y));
  }
  svg += fmt::format("  <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">x (mm)</text>\n",
                     Num(p.left + p.width / 2), Num(p.top + p.height + 38));
  svg += fmt::format(
      "  <text x=\"{0}\" y=\"{1}\" text-anchor=\"middle\" transform=\"rotate(-90 {0} {1})\">y (mm)</text>\n",
      Num(p.left - 46), Num(p.top + p.height / 2));
}

void DrawLegend(std::string& svg, const Panel& p, double range_um) {
  double x = p.left + p.width + kLegendGap;
  svg += fmt::format(
      "  <rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"url(#diverging)\" stroke=\"#444\"/>\n",
      Num(x), Num(p.top), Num(kLegendWidth), Num(p.height));
  for (int k = -2; k <= 2; ++k) {
    double py = p.top + p.height / 2 - k * p.height / 4;
    double value = range_um * k / 2;
    svg += fmt::format("  <line x1=\"{0}\" y1=\"{2}\" x2=\"{1}\" y2=\"{2}\" stroke=\"#444\"/>\n",
                       Num(x + kLegendWidth), Num(x + kLegendWidth + 4), Num(py));
    svg += fmt::format("  <text x=\"{}\" y=\"{}\">{}{}</text>\n", Num(x + kLegendWidth + 7), Num(py + 4),
                       value > 0 ? "+" : "", Tick(value));
  }
  svg += fmt::format("  <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">µm</text>\n",
                     Num(x + kLegendWidth / 2), Num(p.top - 8));
}

void DrawArrow(std::string& svg, double x0, double y0, double x1, double y1) {
  double dx = x1 - x0, dy = y1 - y0, length = std::hypot(dx, dy);
  if (length < 1.5) return;  // shorter than the dot under it
  double ux = dx / length, uy = dy / length;
  double head = std::min(6.0, 0.45 * length);
  double bx = x1 - ux * head, by = y1 - uy * head;
  svg += fmt::format("    <line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n", Num(x0), Num(y0), Num(bx), Num(by));
  svg += fmt::format("    <polygon points=\"{},{} {},{} {},{}\"/>\n", Num(x1), Num(y1),
                     Num(bx - uy * head * 0.45), Num(by + ux * head * 0.45), Num(bx + uy * head * 0.45),
                     Num(by - ux * head * 0.45));
}

}  // namespace

std::string PlotTableSvg(const ErrorTable& table, std::string_view title) {
  return PlotTableSvg(table, TablePlotWords{fmt::format("Error tables of {}", title), "the error of the axis",
                                            "the error vector (Δx, Δy)", "Δ{0}: the {0} errors"});
}

std::string PlotTableSvg(const ErrorTable& table, const TablePlotWords& words) {
  SMTCAL_CHECK(HasUsableShape(table), "plotting a table that is not usable");
  CalibrationMap map(table);

  // Arrows: the error vector at every node of both grids, one exaggeration
  // for both panels, chosen so the longest arrow spans most of a pitch.
  double longest_mm = 0, pitch_mm = INFINITY;
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    for (std::size_t i = 0; i + 1 < t.nx(); ++i) pitch_mm = std::min(pitch_mm, t.xs[i + 1] - t.xs[i]);
    for (std::size_t j = 0; j + 1 < t.ny(); ++j) pitch_mm = std::min(pitch_mm, t.ys[j + 1] - t.ys[j]);
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) {
        double dx = map.AxisDelta(TableAxis::X, t.xs[i], t.ys[j]);
        double dy = map.AxisDelta(TableAxis::Y, t.xs[i], t.ys[j]);
        longest_mm = std::max(longest_mm, std::hypot(dx, dy));
      }
    }
  }
  const double exaggeration = longest_mm > 0 ? NiceFloor(kArrowFill * pitch_mm / longest_mm) : 1;
  const double scale_bar_um = longest_mm > 0 ? NiceFloor(longest_mm * kUmPerMm) : 0;
  const double pad_fraction = 0.03;  // of the grid's span, beside the arrows' room

  std::array<Panel, 2> panels;
  double x = kMarginLeft, height = 0;
  for (TableAxis axis : kTableAxes) {
    const AxisTable& t = table[axis];
    Panel& p = panels[static_cast<int>(axis)];
    p.axis = axis;
    p.table = &t;
    double w = t.xs.back() - t.xs.front(), h = t.ys.back() - t.ys.front();
    p.pad_mm = exaggeration * longest_mm + pad_fraction * std::max(w, h);
    w += 2 * p.pad_mm;
    h += 2 * p.pad_mm;
    p.scale = kPlotPx / std::max(w, h);
    p.width = w * p.scale;
    p.height = h * p.scale;
    p.left = x;
    p.top = kMarginTop;
    x += p.width + kLegendGap + kLegendWidth + kPanelGap + kMarginLeft;
    height = std::max(height, p.height);
  }
  const double svg_width = x - kMarginLeft;
  const double svg_height = kMarginTop + height + kMarginBottom;

  std::string svg;
  svg += fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\">\n",
      Num(svg_width), Num(svg_height));
  svg += "  <defs>\n    <linearGradient id=\"diverging\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">\n";
  for (std::size_t k = 0; k < kPalette.size(); ++k) {
    svg += fmt::format("      <stop offset=\"{}\" stop-color=\"{}\"/>\n",
                       Num(static_cast<double>(k) / (kPalette.size() - 1)),
                       Colour(-1 + 2.0 * static_cast<double>(k) / (kPalette.size() - 1)));
  }
  svg += "    </linearGradient>\n  </defs>\n";
  svg += "  <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg += fmt::format("  <text x=\"{}\" y=\"26\" font-size=\"17\" font-weight=\"bold\">{}</text>\n",
                     Num(kMarginLeft - 40), SvgEscape(words.heading));
  svg += fmt::format(
      "  <text x=\"{}\" y=\"46\" fill=\"#333\">colour: {} (µm, blue negative, red positive); arrows: {} at each "
      "node, {} times enlarged{}; dots: grid nodes</text>\n",
      Num(kMarginLeft - 40), SvgEscape(words.field), SvgEscape(words.arrows), Tick(exaggeration),
      words.state_arrow_fill ? fmt::format(" (the longest: {:g} pitch)", kArrowFill)
                             : std::string());

  for (const Panel& p : panels) {
    const AxisTable& t = *p.table;
    double max_abs = 0;
    for (double v : t.error_mm) max_abs = std::max(max_abs, std::abs(v));
    const double range_um = max_abs > 0 ? LegendCeil(max_abs * kUmPerMm) : 1;
    std::string_view name = AxisName(p.axis);
    svg += fmt::format("  <!-- panel: the {} table -->\n", name);
    svg += fmt::format("  <text x=\"{}\" y=\"{}\" font-size=\"14\" font-weight=\"bold\">{}, {} x {} nodes</text>\n",
                       Num(p.left), Num(p.top - 12), SvgEscape(fmt::format(fmt::runtime(words.panel), name)), t.nx(),
                       t.ny());
    DrawColourMap(svg, p, range_um / kUmPerMm);
    DrawAxes(svg, p);
    DrawLegend(svg, p, range_um);
    svg += "  <g fill=\"#222\">\n";
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) {
        svg += fmt::format("    <circle cx=\"{}\" cy=\"{}\" r=\"1.8\"/>\n", Num(p.Px(t.xs[i])), Num(p.Py(t.ys[j])));
      }
    }
    svg += "  </g>\n  <g stroke=\"#111\" stroke-width=\"1.3\" fill=\"#111\">\n";
    for (std::size_t j = 0; j < t.ny(); ++j) {
      for (std::size_t i = 0; i < t.nx(); ++i) {
        double dx = map.AxisDelta(TableAxis::X, t.xs[i], t.ys[j]);
        double dy = map.AxisDelta(TableAxis::Y, t.xs[i], t.ys[j]);
        if (words.own_component) (p.axis == TableAxis::X ? dy : dx) = 0;
        DrawArrow(svg, p.Px(t.xs[i]), p.Py(t.ys[j]), p.Px(t.xs[i] + exaggeration * dx),
                  p.Py(t.ys[j] + exaggeration * dy));
      }
    }
    // The scale bar: an arrow of scale_bar_um, drawn like the others.
    double bar_y = p.top + p.height + 66;
    double bar_px = scale_bar_um / kUmPerMm * exaggeration * p.scale;
    if (scale_bar_um > 0) DrawArrow(svg, p.left, bar_y, p.left + bar_px, bar_y);
    svg += "  </g>\n";
    if (scale_bar_um > 0) {
      svg += fmt::format("  <text x=\"{}\" y=\"{}\">= {} µm (arrows {} times enlarged)</text>\n",
                         Num(p.left + bar_px + 8), Num(bar_y + 4), Tick(scale_bar_um), Tick(exaggeration));
    }
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace smtcal
