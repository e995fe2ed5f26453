// The inputs of `smtcal measure program|read` (frontend/measurement_input.h):
// a plan read back against its cell, and the measuring program's log.
#include <string>

#include <gtest/gtest.h>

#include "frontend/measurement_input.h"

namespace smtcal::measure {
namespace {

const char* kPlan =
    "# a plan of two regions\n"
    "visit,region,axes,station,kind,node,x_mm,y_mm,set,repetitions\n"
    "1,layer1,xy,1,node,1,150,60,1,2\n"
    "2,layer1,xy,1,node,2,170,60,1,2\n"
    "3,layer1,xy,1,check,5,160,70,1,2\n"
    "4,layer1,xy,1,node,4,170,80,1,2\n"
    "5,layer1,xy,1,node,3,150,80,1,2\n"
    "6,Board_v1,xy,1,node,6,155,5,1,2\n"
    "7,Board_v1,xy,1,node,7,175,5,1,2\n"
    "8,Board_v1,xy,1,node,8,155,30,1,2\n"
    "9,Board_v1,xy,1,node,9,175,30,1,2\n";

cell::Cell ProbeCell() {
  cell::Cell c;
  c.name = "test";
  c.robot.final_approach_mm = Eigen::Vector2d(0.5, 0.5);
  cell::Measure m;
  m.device = cell::MeasureDevice::kProbe;
  c.measure = m;
  cell::Region layer1;
  layer1.name = "layer1";
  layer1.tolerance_mm = 0.1;
  c.regions.push_back(layer1);
  // The plan's second region is one it proposed under this fixture's
  // markers (FIXTURE_PATH), not a region of the cell.
  cell::Fixture board;
  board.name = "Board";
  cell::ScanPath v1;
  v1.name = "v1";
  board.scan_paths.push_back(v1);
  c.fixtures.push_back(board);
  return c;
}

struct Files {
  SourceManager sources;
  Diagnostics diags{sources};
  std::uint32_t Add(std::string name, std::string text) { return sources.Add(std::move(name), std::move(text)); }
};

TEST(MeasurementPlanFile, ReadsRegionsGridsAndVisits) {
  Files f;
  std::optional<LoadedPlan> plan = LoadPlan(f.Add("plan.csv", kPlan), ProbeCell(), f.diags);
  ASSERT_TRUE(plan) << f.diags.RenderText();
  ASSERT_EQ(plan->plan.regions.size(), 2u);
  const PlanRegion& layer1 = plan->plan.regions[0];
  EXPECT_EQ(layer1.xs, (std::vector<double>{150, 170}));  // the check point is no grid line
  EXPECT_EQ(layer1.ys, (std::vector<double>{60, 80}));
  EXPECT_FALSE(layer1.proposed);
  EXPECT_TRUE(plan->plan.regions[1].proposed);  // under the markers, not in the cell
  EXPECT_EQ(plan->plan.visits.size(), 9u);
  EXPECT_EQ(plan->plan.visits[2].kind, VisitKind::kCheck);
  EXPECT_EQ(plan->digest, PlanDigest(kPlan));
}

TEST(MeasurementPlanFile, RefusesVisitsOutOfOrderAMovedNodeAndAnotherDevice) {
  {
    Files f;
    std::string text = kPlan;
    text.replace(text.find("2,layer1"), 1, "9");
    EXPECT_FALSE(LoadPlan(f.Add("plan.csv", text), ProbeCell(), f.diags));
    EXPECT_NE(f.diags.RenderText().find("follows visit"), std::string::npos) << f.diags.RenderText();
  }
  {
    Files f;
    std::string text = kPlan;
    text.replace(text.find("7,Board_v1,xy,1,node,7"), 22, "7,Board_v1,xy,1,node,6");
    EXPECT_FALSE(LoadPlan(f.Add("plan.csv", text), ProbeCell(), f.diags));
    EXPECT_NE(f.diags.RenderText().find("a node is one point"), std::string::npos) << f.diags.RenderText();
  }
  {
    Files f;
    cell::Cell transducer = ProbeCell();
    transducer.measure->device = cell::MeasureDevice::kTransducer;
    EXPECT_FALSE(LoadPlan(f.Add("plan.csv", kPlan), transducer, f.diags));
    EXPECT_NE(f.diags.RenderText().find("plan again"), std::string::npos) << f.diags.RenderText();
  }
}

TEST(MeasuringLog, ReadsBlocksReadingsAndRefusesAnotherPlan) {
  Files f;
  std::optional<LoadedPlan> plan = LoadPlan(f.Add("plan.csv", kPlan), ProbeCell(), f.diags);
  ASSERT_TRUE(plan);
  const std::string header = "# smtcal measuring log: plan plan.csv digest " + plan->digest +
                             "; program measure_layer1; region layer1; axes xy; station 1; device probe; visits 1..5\n";
  std::string log = header +
                    "visit,node,set,repetition,x_mm,y_mm,a_mm,b_mm\n"
                    "1,1,1,1,150.000000,60.000000,151.400000,61.420000\n"
                    "1,1,1,2,150.000000,60.000000,151.401000,61.421000\n"
                    "# aborted at visit 2 repetition 1: no contact along x\n";
  std::optional<MeasuringLog> read = ReadMeasuringLog(f.Add("a.log", log), *plan, f.diags);
  ASSERT_TRUE(read) << f.diags.RenderText();
  ASSERT_EQ(read->blocks.size(), 1u);
  EXPECT_EQ(read->blocks[0].first_visit, 1);
  EXPECT_EQ(read->blocks[0].last_visit, 5);
  EXPECT_FALSE(read->blocks[0].ended);
  EXPECT_NE(read->blocks[0].stopped.find("no contact"), std::string::npos);
  ASSERT_EQ(read->readings.size(), 2u);
  EXPECT_DOUBLE_EQ(read->readings[1].a, 151.401);
  EXPECT_EQ(read->readings[1].at, Eigen::Vector2d(150, 60));

  std::string other = header;
  other.replace(other.find(plan->digest), plan->digest.size(), "0123456789abcdef");
  EXPECT_FALSE(ReadMeasuringLog(f.Add("b.log", other), *plan, f.diags));
  EXPECT_NE(f.diags.RenderText().find("another plan"), std::string::npos);

  Files g;
  ASSERT_TRUE(LoadPlan(g.Add("plan.csv", kPlan), ProbeCell(), g.diags));
  EXPECT_FALSE(ReadMeasuringLog(g.Add("c.log", "visit,node\n"), *plan, g.diags));
  EXPECT_NE(g.diags.RenderText().find("not a log"), std::string::npos);

  Files h;
  ASSERT_TRUE(LoadPlan(h.Add("plan.csv", kPlan), ProbeCell(), h.diags));
  EXPECT_FALSE(ReadMeasuringLog(h.Add("d.log", header + "3,2,1,1,150,60,0,0\n"), *plan, h.diags));
  EXPECT_NE(h.diags.RenderText().find("reading of visit 3 node 2"), std::string::npos) << h.diags.RenderText();
}

}  // namespace
}  // namespace smtcal::measure
