// The pictures of the broken cells of tests/golden/cell-plot mark every
// finding where it is. `smtcal cell plot` runs as a user runs it; the SVG is
// read back: every finding of the list below the panels is ringed (none
// "[not drawn]"), each ring lies at its finding's place in mm through the
// mapping of the panel it is drawn in, and the places this test expects —
// worked out by hand from the cells' numbers, in the robot base frame — are
// ringed with the right kind.
#include <cmath>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/unit/test_support.h"

namespace {

struct Mark {
  std::string kind;
  double x_mm = 0, y_mm = 0;  // as the mark says
  double cx = 0, cy = 0;      // where it is drawn, px
  // The panel's mapping it is drawn under.
  double x0 = 0, y1 = 0, scale = 0, left = 0, top = 0;
};

double Attribute(const std::string& text, const std::string& name) {
  std::smatch m;
  const std::regex re(" " + name + "=\"(-?[0-9.]+)\"");
  if (!std::regex_search(text, m, re)) {
    ADD_FAILURE() << "no " << name << " in " << text;
    return 0;
  }
  return std::stod(m[1]);
}

std::vector<Mark> Marks(const std::string& svg) {
  std::vector<Mark> marks;
  Mark panel;
  std::size_t start = 0;
  while (start < svg.size()) {
    std::size_t end = svg.find('\n', start);
    if (end == std::string::npos) end = svg.size();
    const std::string line = svg.substr(start, end - start);
    start = end + 1;
    if (line.find("<g clip-path=") != std::string::npos) {
      panel.x0 = Attribute(line, "data-x0-mm");
      panel.y1 = Attribute(line, "data-y1-mm");
      panel.scale = Attribute(line, "data-px-per-mm");
      panel.left = Attribute(line, "data-left-px");
      panel.top = Attribute(line, "data-top-px");
    }
    if (line.find("class=\"finding\"") == std::string::npos) continue;
    Mark mark = panel;
    std::smatch kind;
    EXPECT_TRUE(std::regex_search(line, kind, std::regex("data-kind=\"([A-Za-z]+)\""))) << line;
    mark.kind = kind[1];
    mark.x_mm = Attribute(line, "data-x-mm");
    mark.y_mm = Attribute(line, "data-y-mm");
    mark.cx = Attribute(line, "cx");
    mark.cy = Attribute(line, "cy");
    marks.push_back(mark);
  }
  return marks;
}

struct Expected {
  std::string kind;
  double x_mm, y_mm;
};

void CheckPicture(const std::string& name, const std::string& args, int exit_code,
                  const std::vector<Expected>& expected) {
  SCOPED_TRACE(name);
  const std::filesystem::path suite = std::filesystem::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "cell-plot";
  const smtcal::test::SmtcalRun run = smtcal::test::RunSmtcal("cell plot " + name + args + " -o -", suite);
  ASSERT_EQ(run.exit_code, exit_code) << run.err;
  ASSERT_NE(run.out.find("</svg>"), std::string::npos) << "no picture written";
  EXPECT_EQ(run.out.find("[not drawn]"), std::string::npos) << "a finding has no mark";
  const std::vector<Mark> marks = Marks(run.out);
  ASSERT_FALSE(marks.empty());
  // Every ring is where its finding is, in the panel it is drawn in (2
  // decimals of px, as the picture writes them).
  for (const Mark& mark : marks) {
    EXPECT_NEAR(mark.cx, mark.left + (mark.x_mm - mark.x0) * mark.scale, 0.01) << mark.kind;
    EXPECT_NEAR(mark.cy, mark.top + (mark.y1 - mark.y_mm) * mark.scale, 0.01) << mark.kind;
  }
  // Every finding the list names has a ring.
  std::size_t listed = 0;
  for (std::size_t at = run.out.find("class=\"finding-entry\""); at != std::string::npos;
       at = run.out.find("class=\"finding-entry\"", at + 1)) {
    ++listed;
    const std::string number = "data-finding=\"" + std::to_string(listed) + "\"";
    EXPECT_NE(run.out.find("class=\"finding\" " + number), std::string::npos) << "finding " << listed << " not ringed";
  }
  EXPECT_GT(listed, 0u);
  for (const Expected& e : expected) {
    bool found = false;
    for (const Mark& mark : marks) {
      found = found || (mark.kind == e.kind && std::abs(mark.x_mm - e.x_mm) < 1e-3 && std::abs(mark.y_mm - e.y_mm) < 1e-3);
    }
    EXPECT_TRUE(found) << e.kind << " not ringed at (" << e.x_mm << ", " << e.y_mm << ")";
  }
}

// Marker 2 moved 12 mm along the board (S1 at (138, 40), angle 0): T1 on p3
// at (202, 85.9) and T4 at (202, 86.1) in the fixture frame, their windows
// reaching past x = 338, the edge of region marker2's table.
TEST(CellPlotMarks, TripsOutsideEveryTableAreRingedAtTheTrips) {
  CheckPicture("marker2_moved.toml", "", 0,
               {{"CellTripUncalibrated", 340.0, 125.9}, {"CellTripUncalibrated", 340.0, 126.1}});
}

// The pocket x 25..72, y 21..68 mm of the fixture lies at x 163..210, y 61..108
// in the base frame: its corner (210, 61) is the first farthest past layer1's
// x = 199.5.
TEST(CellPlotMarks, APocketOverItsRegionIsRingedAtItsCornerFarthestOut) {
  CheckPicture("pocket_over_region.toml", "", 0, {{"CellPocketOverRegion", 210.0, 61.0}});
}

// Feeder Bank3's one pick point at (410, 10), beyond the travel x 0..400.
TEST(CellPlotMarks, AFeederOutsideTheTravelIsDrawnAndRinged) {
  CheckPicture("fail_feeder_outside_travel.toml", "", 1, {{"CellOutsideRobotLimits", 410.0, 10.0}});
}

// Leg 7 of M2 runs along y = 91 of the fixture from x 194.1 to 183, over the
// top end (190, 90) of edge p3: nearest to the edge at (190, 91), in the base
// frame (328, 131).
TEST(CellPlotMarks, ALegThatCrossesAnotherEdgeIsRingedWhereItPassesTheEdge) {
  CheckPicture("leg_crosses_edge.toml", "", 0, {{"CellScanCaptureRange", 328.0, 131.0}});
}

// With the example program: besides the trips, its placements are drawn
// and each placement the scan takes out of tolerance is ringed where it is:
// layers.place's R1 + X(dx) of layer 1 at (138 + 12 + 5.08, 40 + 20 + 7.62),
// of layer 2 55.8 mm further in x.
TEST(CellPlotMarks, AProgramsErrorsAreRingedAtItsPlacements) {
  CheckPicture("fail_marker2_moved_program.toml", " --program ../../../examples/paper-cell/layers.place", 1,
               {{"CellTripUncalibrated", 340.0, 125.9},
                {"CellTripUncalibrated", 340.0, 126.1},
                {"BudgetOverTolerance", 155.08, 67.62},
                {"BudgetOverTolerance", 155.08 + 55.8, 67.62}});
}

}  // namespace
