// The picture of `smtcal simulate --svg` (backend/reports/simulate_report.h)
// as a reader sees it: scatter panels with both axes ticked and labelled in
// µm, a histogram with a labelled share scale, and a mode that placed nothing
// drawn as a note naming the checks that stopped it, with no empty axes and
// no flat curve; the paper's modes say they run without scan checks. Built from a hand-made SimResult, so every number is known.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "backend/reports/simulate_report.h"

namespace smtcal {
namespace {

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The part of the picture between "<!-- panel: NAME -->" and the next panel
// or the histogram.
std::string PanelOf(const std::string& svg, const std::string& name) {
  const std::size_t start = svg.find("<!-- panel: " + name + " -->");
  if (start == std::string::npos) return "";
  std::size_t end = svg.find("<!-- panel:", start + 1);
  if (end == std::string::npos) end = svg.find("Error length histogram", start);
  return svg.substr(start, end - start);
}

struct SimRun {
  cell::Cell cell;
  TruthSpec truth;
  SimResult result;
  std::string Svg() const {
    SimulateContext context;
    context.program = "board.place";
    context.cell = &cell;
    context.truth = &truth;
    return SimulateReportSvg(result, context);
  }
};

// Two modes: `none` placed three parts, `periphery` stopped all 4 cycles
// (3 by length_l1, 1 by squareness).
SimRun TwoModes() {
  SimRun run;
  run.cell.name = "test-cell";
  run.result.cycles = 4;
  run.result.tolerance_mm = 0.1;
  ModeResult placed;
  placed.mode = SimMode::kNone;
  placed.cycles = 4;
  placed.placements = 3;
  placed.within = 2;
  placed.errors_um = {20, 60, 140};
  placed.scatter_um = {{20, 0}, {0, -60}, {140, 0}};
  ModeResult stopped;
  stopped.mode = SimMode::kPeripheryOnly;
  stopped.cycles = 4;
  stopped.faults = 4;
  stopped.fault_checks = {{"length_l1", 3}, {"squareness", 1}};
  run.result.modes = {placed, stopped};
  return run;
}

TEST(SimulateSvg, ScatterPanelsHaveBothAxesTickedInMicrometres) {
  SimRun run = TwoModes();
  const std::string svg = run.Svg();
  const std::string none = PanelOf(svg, "none");
  ASSERT_FALSE(none.empty()) << svg;
  EXPECT_NE(none.find(">x error (µm)</text>"), std::string::npos);
  EXPECT_NE(none.find(">y error (µm)</text>"), std::string::npos);
  EXPECT_NE(none.find("rotate(-90"), std::string::npos) << "the y label runs along the axis";
  // ±250 µm (2.5 x the tolerance), ticked every 100 µm on both axes.
  for (const char* tick : {">-200</text>", ">-100</text>", ">0</text>", ">100</text>", ">200</text>"}) {
    EXPECT_EQ(Count(none, tick), 2u) << tick;
  }
  EXPECT_NE(none.find("stroke-dasharray=\"5,4\""), std::string::npos) << "the tolerance circle";
}

TEST(SimulateSvg, HistogramHasALabelledShareScale) {
  SimRun run = TwoModes();
  const std::string svg = run.Svg();
  const std::string histogram = svg.substr(svg.find("Error length histogram"));
  EXPECT_NE(histogram.find(">share of placed parts (%)</text>"), std::string::npos);
  EXPECT_NE(histogram.find(">error length (µm)</text>"), std::string::npos);
  // One part in three per bin at most: 33.3 %, ticked 0..40 % every 10 %.
  for (const char* tick : {">0%</text>", ">10%</text>", ">20%</text>", ">30%</text>", ">40%</text>"}) {
    EXPECT_NE(histogram.find(tick), std::string::npos) << tick;
  }
  EXPECT_EQ(histogram.find(">50%</text>"), std::string::npos);
}

TEST(SimulateSvg, ModeThatPlacedNothingIsANoteNotAnEmptyAxis) {
  SimRun run = TwoModes();
  const std::string svg = run.Svg();
  const std::string periphery = PanelOf(svg, "periphery");
  ASSERT_FALSE(periphery.empty()) << svg;
  EXPECT_NE(periphery.find(">no placements: every cycle stopped by</text>"), std::string::npos) << periphery;
  EXPECT_NE(periphery.find(">length_l1 (3 cycles)</text>"), std::string::npos);
  EXPECT_NE(periphery.find(">squareness (1 cycle)</text>"), std::string::npos);
  EXPECT_EQ(periphery.find("error (µm)"), std::string::npos) << "no axes";
  EXPECT_EQ(periphery.find("<circle"), std::string::npos) << "no tolerance circle, no dots";
  // In the histogram: a curve for the mode that placed, a note in the legend
  // for the one that did not.
  EXPECT_EQ(Count(svg, "<polyline"), 1u);
  EXPECT_NE(svg.find(">periphery (nothing placed)</text>"), std::string::npos);
}

TEST(SimulateSvg, PartlyStoppedModeWithNothingPlacedSaysHowMany) {
  SimRun run = TwoModes();
  run.result.modes[1].faults = 3;
  run.result.modes[1].fault_checks = {{"length_l1", 3}};
  const std::string svg = run.Svg();
  EXPECT_NE(PanelOf(svg, "periphery").find(">no placements: 3 of 4 cycles stopped by</text>"), std::string::npos);
}

TEST(SimulateSvg, ThePapersModesSayTheyRunWithoutChecksAndWhatTheChecksWouldStop) {
  SimRun run = TwoModes();
  ModeResult& periphery = run.result.modes[1];
  periphery.faults = 0;
  periphery.fault_checks.clear();
  periphery.would_stop = 4;
  periphery.would_stop_checks = {{"length_l1", 4}};
  periphery.placements = 4;
  periphery.errors_um = {5000, 3000, 9000, 80};  // Eq. 4 on short edges: millimetres off
  periphery.scatter_um = {{5000, 0}, {0, 3000}, {9000, 0}, {80, 0}};
  const std::string svg = run.Svg();
  EXPECT_NE(PanelOf(svg, "periphery").find("no scan checks (the cell's would stop 4)"), std::string::npos) << svg;
  EXPECT_EQ(PanelOf(svg, "none").find("no scan checks"), std::string::npos) << "only the paper's modes";
  // Three of its four parts in the last bin: the scale stays the others'
  // (one part in three: 40 %), the last bin is clipped and written out.
  const std::string histogram = svg.substr(svg.find("Error length histogram"));
  EXPECT_NE(histogram.find(">40%</text>"), std::string::npos);
  EXPECT_EQ(histogram.find(">80%</text>"), std::string::npos);
  EXPECT_NE(histogram.find(">periphery: 75.0% at 295 µm or more (last bin, clipped)</text>"), std::string::npos)
      << histogram;
}

TEST(SimulateSvg, HistogramOfNoPlacementSaysSo) {
  SimRun run = TwoModes();
  run.result.modes.erase(run.result.modes.begin());
  const std::string svg = run.Svg();
  EXPECT_EQ(Count(svg, "<polyline"), 0u);
  EXPECT_NE(svg.find(">no mode placed a part: nothing to count</text>"), std::string::npos);
}

}  // namespace
}  // namespace smtcal
