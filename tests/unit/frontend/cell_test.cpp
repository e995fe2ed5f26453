// The cell loader (frontend/cell_toml.cpp): the shipped paper cell loads
// cleanly and fits the example program, and the loader's checks behave at
// their boundaries. (Every diagnostic's wording is in tests/golden/cell.)
// The property test prints its seed; set SMTCAL_TEST_SEED to vary it.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/fixture_geometry.h"
#include "calibration/placement_budget.h"
#include "calibration/scan_plan.h"
#include "calibration/tolerances.h"
#include "frontend/cell_toml.h"
#include "ir/ir.h"
#include "tests/unit/parse_text.h"
#include "tests/unit/test_support.h"

namespace fs = std::filesystem;

namespace smtcal::cell {
namespace {

const fs::path kSource = fs::path(SMTCAL_SOURCE_DIR);
const fs::path kPaperCell = kSource / "examples" / "paper-cell" / "paper.cell.toml";

std::uint64_t BaseSeed() {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : 19940601;
}

struct Loaded {
  std::optional<Cell> cell;
  std::string diagnostics;              // rendered
  std::vector<DiagKind> kinds;          // of every diagnostic
  std::vector<Diagnostic> all;          // as reported
  std::map<std::uint32_t, std::string> file_names;  // SourceManager id -> name
  std::size_t errors = 0;
  std::size_t count(DiagKind kind) const { return static_cast<std::size_t>(std::count(kinds.begin(), kinds.end(), kind)); }
};

Loaded LoadFile(const fs::path& path) {
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<Cell>> result = LoadCell(path.string(), sources, diags);
  Loaded loaded;
  if (!result) {
    ADD_FAILURE() << result.error().message;
    return loaded;
  }
  loaded.cell = std::move(result).value();
  loaded.diagnostics = diags.RenderText();
  loaded.all = diags.all();
  for (const Diagnostic& d : diags.all()) {
    loaded.kinds.push_back(d.kind);
    if (d.range.begin.file != 0) loaded.file_names[d.range.begin.file] = sources.File(d.range.begin.file).name;
  }
  loaded.errors = diags.error_count();
  return loaded;
}

// A scratch folder holding a cell file and the small tables of the golden suite.
class CellText : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("smtcal_cell_test_{}", ::getpid());
    fs::create_directories(dir_ / "tables");
    for (const char* table : {"small.csv", "right.csv", "folded.csv"}) {
      fs::copy_file(kSource / "tests" / "golden" / "cell" / "tables" / table, dir_ / "tables" / table,
                    fs::copy_options::overwrite_existing);
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  Loaded Load(const std::string& text) {
    std::ofstream(dir_ / "t.cell.toml", std::ios::binary) << text;
    return LoadFile(dir_ / "t.cell.toml");
  }

  fs::path dir_;
};

const std::string kRobot = R"([robot]
model = "test robot"
x_mm = [0, 400]
y_mm = [0, 300]
z_mm = [-30, 0]
u_deg = [-360, 360]
repeatability_mm = 0.005
safe_limz_mm = 0
xy_speed_mm_s = 800
xy_accel_mm_s2 = 3000
z_speed_mm_s = 300
z_accel_mm_s2 = 2000
u_speed_deg_s = 360
u_accel_deg_s2 = 1800
pick_time_s = 0.3
place_time_s = 0.3
)";

std::string RegionText(const std::string& name, const std::string& table, const std::string& extra = "") {
  return fmt::format(R"(
[[region]]
name = "{}"
table = "tables/{}"
difficulty = {{ level = 2, axes = ["x", "y"] }}
tolerance_mm = 0.1
{})",
                     name, table, extra);
}

// The paper's board at a nominal pose, with `teach` as teach_trips_mm ("" =
// none) and `l1` as l1_mm.
std::string FixtureText(double x, double y, double angle_deg, const std::string& teach, const std::string& l1 = "190") {
  return fmt::format(R"(
[[fixture]]
name = "Board"
origin_mm = [{}, {}]
angle_deg = {}
l1_mm = {}
l2_mm = 90
scan_z_mm = -2
scan_speed_mm_s = 12
trip_window_mm = 3
sensor_input = 10
sensor_accuracy_mm = 0.05
{}

[fixture.edges]
p1 = {{ from_mm = [0, 0], to_mm = [8, 0] }}
p2 = {{ from_mm = [0, 0], to_mm = [0, 8] }}
p3 = {{ from_mm = [190, 82], to_mm = [190, 90] }}
p4 = {{ from_mm = [182, 90], to_mm = [190, 90] }}

[[fixture.scan_path]]
name = "V1"
points_mm = [[-3, 6], [6, -3], [-3, 12]]

[[fixture.scan_path]]
name = "V2"
points_mm = [[193, 84], [184, 93], [193, 78]]

[fixture.limits]
max_shift_mm = 2
max_rotation_deg = 0.5
length_tolerance_mm = 0.1
squareness_deg = 0.2
max_line_residual_mm = 0.05
)",
                     x, y, angle_deg, l1, teach);
}

// The paper board's trip points in fixture coordinates, T1..T8.
// The V paths' trips (the cells written by these tests), and the example
// file's hairpins'.
const std::vector<Point2> kPaperTrips = {{0, 3},   {3, 0},   {4.2, 0},    {0, 7},
                                         {190, 87}, {187, 90}, {185.8, 90}, {190, 83}};
const std::vector<Point2> kExampleTrips = {{190, 85.9}, {185.9, 90}, {186.1, 90}, {190, 86.1},
                                           {0, 3.9},    {3.9, 0},    {4.1, 0},    {0, 4.1}};

std::string TeachTrips(const std::vector<Point2>& trips) {
  std::string text = "teach_trips_mm = [";
  for (const Point2& t : trips) text += fmt::format("[{:.17g}, {:.17g}], ", t.x(), t.y());
  return text + "]";
}

// ------------------------------------------------------------------ the paper cell

TEST(PaperCellFile, LoadsWithoutAnyDiagnostic) {
  Loaded loaded = LoadFile(kPaperCell);
  ASSERT_TRUE(loaded.cell.has_value()) << loaded.diagnostics;
  EXPECT_TRUE(loaded.kinds.empty()) << loaded.diagnostics;
  const Cell& cell = *loaded.cell;
  EXPECT_EQ(cell.name, "paper-cell");
  EXPECT_EQ(cell.robot.model, "SEIKO D-TRAN XY-2000");
  EXPECT_EQ(cell.robot.limits[0].hi, 400);
  EXPECT_EQ(cell.robot.limits[3].lo, -360);
  EXPECT_EQ(cell.robot.repeatability_mm, 0.005);

  EXPECT_EQ(cell.robot.uncalibrated_accuracy_mm, 0.25);
  EXPECT_EQ(cell.robot.servo_period_s, 0.001);

  ASSERT_EQ(cell.regions.size(), 6u);
  const char* names[] = {"layer1", "layer2", "layer3", "feeders", "marker1", "marker2"};
  for (std::size_t i = 0; i < 6; ++i) {
    const Region& region = cell.regions[i];
    EXPECT_EQ(region.name, names[i]);
    EXPECT_EQ(region.difficulty_level, 2);
    EXPECT_EQ(region.difficulty_axes, (std::vector<TaskAxis>{TaskAxis::X, TaskAxis::Y}));
    EXPECT_EQ(region.tolerance_mm, 0.1);
    EXPECT_EQ(region.outside, OutsidePolicy::kError);
    // Bounds inside the domain with a margin larger than every table error
    // (0.153 mm), so every required position has its nominal in the table.
    EXPECT_GE(region.x_mm.lo - region.domain.x0, 0.2) << region.name;
    EXPECT_GE(region.domain.x1 - region.x_mm.hi, 0.2) << region.name;
    EXPECT_GE(region.y_mm.lo - region.domain.y0, 0.2) << region.name;
    EXPECT_GE(region.domain.y1 - region.y_mm.hi, 0.2) << region.name;
  }
  EXPECT_EQ(cell.regions[0].table_path, "placing-table.csv");
  // Every trip of the marker scan is direct-calibrated, whatever pose the
  // checks let through: its whole window lies in a marker table.
  ASSERT_EQ(cell.fixtures.size(), 1u);
  for (int region : TripRegions(cell.fixtures[0], cell.regions)) {
    ASSERT_GE(region, 0);
    EXPECT_TRUE(cell.regions[static_cast<std::size_t>(region)].name.starts_with("marker"));
  }
  EXPECT_DOUBLE_EQ(cell.regions[0].domain.x0, 150.004);
  EXPECT_DOUBLE_EQ(cell.regions[0].domain.y1, 109.997);

  ASSERT_EQ(cell.fixtures.size(), 1u);
  const Fixture& board = cell.fixtures[0];
  EXPECT_EQ(board.origin_mm, Point2(138, 40));
  EXPECT_EQ(board.l1_mm, 190);
  EXPECT_EQ(board.l2_mm, 90);
  EXPECT_EQ(board.estimator, Estimator::kRigid);  // Eq. 4 extrapolates too far on this layout
  EXPECT_EQ(board.sensor_input, 10);
  EXPECT_EQ(board.sensor_accuracy_mm, 0.05);
  EXPECT_EQ(board.max_shift_mm, 2);
  EXPECT_EQ(board.teach_trips_mm.size(), 8u);
  EXPECT_EQ(board.teach_trip_ranges.size(), 8u);

  ASSERT_EQ(cell.feeders.size(), 2u);
  EXPECT_EQ(cell.feeders[0].package, "0805");
  EXPECT_EQ(cell.feeders[1].packages, (std::vector<std::string>{"SOT-23", "SOD-123", "SOIC-8*"}));
  EXPECT_EQ(cell.feeders[1].kind, FeederKind::kTape);
  EXPECT_EQ(board.place_z_mm, -3.0);
  EXPECT_EQ(cell.feeders[1].package, "SOT-23");
}

TEST(PaperCellFile, TripsAndTeachScanAreTheStatedGeometry) {
  Loaded loaded = LoadFile(kPaperCell);
  ASSERT_TRUE(loaded.cell.has_value()) << loaded.diagnostics;
  const Fixture& board = loaded.cell->fixtures[0];
  std::vector<ExpectedTrip> trips = ExpectedTrips(board);
  ASSERT_EQ(trips.size(), kExampleTrips.size());
  const int edges[] = {2, 3, 3, 2, 1, 0, 0, 1};  // p3 p4 p4 p3 p2 p1 p1 p2
  for (std::size_t k = 0; k < trips.size(); ++k) {
    EXPECT_LT((trips[k].in_fixture - kExampleTrips[k]).norm(), 1e-12) << "T" << k + 1;
    EXPECT_EQ(trips[k].edge, edges[k]) << "T" << k + 1;
  }
  // The teach scan: a board at (138.120, 39.950) turned by +0.050 deg,
  // written with 4 decimals (so within half a unit of the 4th decimal).
  const Eigen::Affine3d taught = PlanarFix(Point2(138.120, 39.950), 0.050 * kRadPerDeg);
  for (std::size_t k = 0; k < trips.size(); ++k) {
    Point2 exact = ToBase(taught, kExampleTrips[k]);
    EXPECT_LE((board.teach_trips_mm[k] - exact).cwiseAbs().maxCoeff(), 0.00005 + 1e-12) << "T" << k + 1;
  }
  // Two stages, and paths that take every board the limits accept.
  EXPECT_EQ(board.scan_speed_mm_s, 40);
  EXPECT_EQ(board.latch_speed_mm_s, 8);
  EXPECT_EQ(board.TripLatchSpeedMmS(), 8);
  EXPECT_GE(ScanCaptureRange(board).factor, 1.0) << ScanCaptureRange(board).limited_by;
}

// Every point of layers.place lies in the region it belongs to for every
// board shift up to the fixture's max_shift_mm, and the feeders are the
// program's pallets.
TEST(PaperCellFile, FitsTheExampleProgram) {
  Loaded loaded = LoadFile(kPaperCell);
  ASSERT_TRUE(loaded.cell.has_value()) << loaded.diagnostics;
  const Cell& cell = *loaded.cell;
  const Fixture& board = cell.fixtures[0];
  test::ParsedText parsed =
      test::ParseText(test::ReadFileText(kSource / "examples" / "paper-cell" / "layers.place"));
  ASSERT_TRUE(parsed.ok()) << parsed.diagnostics;

  std::map<std::string, Point2> locals;  // layer frames on the board
  std::map<std::string, std::array<double, 4>> base_points;
  std::vector<ir::PointDecl> layer1_points, taught;
  std::vector<ir::PalletDecl> pallets;
  for (const ir::StmtPtr& stmt : parsed.program.items) {
    if (const auto* local = std::get_if<ir::LocalDecl>(&stmt->node)) {
      ASSERT_EQ(local->frame, "Board");
      ASSERT_EQ(local->origin.values[3], 0);
      locals[local->name] = Point2(local->origin.values[0], local->origin.values[1]);
    } else if (const auto* point = std::get_if<ir::PointDecl>(&stmt->node)) {
      if (point->taught) {
        taught.push_back(*point);
      } else if (point->frame == "Layer1") {
        layer1_points.push_back(*point);
      } else if (point->frame.empty()) {
        base_points[point->name] = point->coords.values;
      }
    } else if (const auto* pallet = std::get_if<ir::PalletDecl>(&stmt->node)) {
      pallets.push_back(*pallet);
    }
  }
  ASSERT_EQ(locals.size(), 3u);
  ASSERT_EQ(layer1_points.size(), 13u);

  const Point2 shifts[] = {{0, 0}, {2, 0}, {-2, 0}, {0, 2}, {0, -2}, {1.41, 1.41}, {-1.41, -1.41}};
  const char* layers[] = {"Layer1", "Layer2", "Layer3"};
  const char* regions[] = {"layer1", "layer2", "layer3"};
  for (int layer = 0; layer < 3; ++layer) {
    for (const ir::PointDecl& point : layer1_points) {
      // The program places Layer1's points offset by layer * 55.8 along x:
      // exactly the Local frames of layers 2 and 3.
      Point2 on_board = locals["Layer1"] + Point2(point.coords.values[0] + layer * 55.8, point.coords.values[1]);
      EXPECT_LT((on_board - locals[layers[layer]] - Point2(point.coords.values[0], point.coords.values[1])).norm(),
                1e-9);
      for (const Point2& shift : shifts) {
        const Region* region = cell.RegionAt(board.origin_mm + on_board + shift);
        ASSERT_NE(region, nullptr) << point.name << " on " << layers[layer] << " shifted " << shift.transpose();
        EXPECT_EQ(region->name, regions[layer]) << point.name;
      }
    }
  }
  ASSERT_EQ(taught.size(), 1u);  // U3, taught in robot coordinates
  const Region* u3 = cell.RegionAt(Point2(taught[0].coords.values[0], taught[0].coords.values[1]));
  ASSERT_NE(u3, nullptr);
  EXPECT_EQ(u3->name, "layer1");

  ASSERT_EQ(pallets.size(), 2u);
  for (const ir::PalletDecl& pallet : pallets) {
    const Feeder& feeder = cell.feeders[static_cast<std::size_t>(pallet.number - 1)];
    EXPECT_EQ(feeder.name, fmt::format("Bank{}", pallet.number));
    EXPECT_EQ(feeder.pick, base_points[pallet.corners[0]]);
    EXPECT_EQ(feeder.pallet_last, base_points[pallet.corners[1]]);
    EXPECT_EQ(feeder.pallet_back, base_points[pallet.corners[2]]);
    EXPECT_EQ(feeder.columns, pallet.columns);
    EXPECT_EQ(feeder.rows, pallet.rows);
    for (const std::string& corner : pallet.corners) {
      const std::array<double, 4>& p = base_points[corner];
      const Region* region = cell.RegionAt(Point2(p[0], p[1]));
      ASSERT_NE(region, nullptr) << corner;
      EXPECT_EQ(region->name, "feeders");
    }
  }
}

TEST(PaperCellFile, IsTheExampleInDocsCellMd) {
  std::string doc = test::ReadFileText(kSource / "docs" / "cell.md");
  std::string example = test::ReadFileText(kPaperCell);
  ASSERT_FALSE(example.empty());
  EXPECT_NE(doc.find("```toml\n" + example + "```\n"), std::string::npos)
      << "docs/cell.md must quote examples/paper-cell/paper.cell.toml verbatim";
}

// ------------------------------------------------------------------ the loader

TEST_F(CellText, ReportsEveryMistakeInOneRun) {
  std::string text = kRobot + RegionText("a", "small.csv", "outside = \"clip\"") + RegionText("b", "missing.csv");
  text.replace(text.find("xy_speed_mm_s = 800"), 19, "xy_speed_mm_s = -8");
  text.replace(text.find("repeatability_mm"), 16, "repeatability");
  Loaded loaded = Load(text);
  EXPECT_FALSE(loaded.cell.has_value());
  EXPECT_EQ(loaded.count(DiagKind::CellValueOutOfRange), 1u) << loaded.diagnostics;
  EXPECT_EQ(loaded.count(DiagKind::CellMissingKey), 1u) << loaded.diagnostics;  // repeatability_mm
  EXPECT_EQ(loaded.count(DiagKind::CellUnknownKey), 1u) << loaded.diagnostics;  // repeatability
  EXPECT_EQ(loaded.count(DiagKind::CellUnknownChoice), 1u) << loaded.diagnostics;
  EXPECT_EQ(loaded.count(DiagKind::CellTableUnreadable), 1u) << loaded.diagnostics;
  EXPECT_EQ(loaded.errors, 5u) << loaded.diagnostics;
  EXPECT_NE(loaded.diagnostics.find("did you mean 'repeatability_mm'?"), std::string::npos) << loaded.diagnostics;
}

TEST_F(CellText, ColumnsCountBytesAfterUtf8Text) {
  std::string line = "difficulty = { note = \"Zupančič\", level = 2.5, axes = [\"x\", \"y\"] }";
  std::string text = kRobot + RegionText("a", "small.csv");
  text.replace(text.find("difficulty = {"), text.find('\n', text.find("difficulty = {")) - text.find("difficulty = {"),
               line);
  Loaded loaded = Load(text);
  ASSERT_EQ(loaded.count(DiagKind::CellWrongType), 1u) << loaded.diagnostics;
  for (const Diagnostic& d : loaded.all) {
    if (d.kind != DiagKind::CellWrongType) continue;
    EXPECT_EQ(d.range.begin.column, line.find("2.5") + 1) << loaded.diagnostics;
    EXPECT_EQ(d.range.length, 3u);
  }
}

TEST_F(CellText, BoundsDefaultToTheDomainAndSharedEdgesGoToTheFirstRegion) {
  Loaded loaded = Load(kRobot + RegionText("left", "small.csv") + RegionText("right", "right.csv"));
  ASSERT_TRUE(loaded.cell.has_value()) << loaded.diagnostics;
  const Cell& cell = *loaded.cell;
  EXPECT_EQ(cell.regions[0].x_mm.lo, 100);
  EXPECT_EQ(cell.regions[0].x_mm.hi, 120);
  EXPECT_EQ(cell.regions[1].x_mm.lo, 120);
  ASSERT_NE(cell.RegionAt(Point2(120, 110)), nullptr);
  EXPECT_EQ(cell.RegionAt(Point2(120, 110))->name, "left");
  EXPECT_EQ(cell.RegionAt(Point2(120.001, 110))->name, "right");
  EXPECT_EQ(cell.RegionAt(Point2(99.999, 110)), nullptr);
  EXPECT_EQ(cell.FindRegion("RIGHT"), &cell.regions[1]);
  EXPECT_EQ(cell.FindRegion("middle"), nullptr);
}

TEST_F(CellText, RegionsOverlappingByAHairAreRefused) {
  Loaded loaded = Load(kRobot + RegionText("left", "small.csv", "x_mm = [100, 110.001]") +
                       RegionText("right", "small.csv", "x_mm = [110, 120]"));
  EXPECT_FALSE(loaded.cell.has_value());
  EXPECT_EQ(loaded.count(DiagKind::CellRegionsOverlap), 1u) << loaded.diagnostics;
}

TEST_F(CellText, ATableSharedByTwoRegionsIsReadOnce) {
  Loaded loaded = Load(kRobot + RegionText("a", "folded.csv", "x_mm = [100, 110]") +
                       RegionText("b", "folded.csv", "x_mm = [110, 120]"));
  EXPECT_FALSE(loaded.cell.has_value());
  EXPECT_EQ(loaded.count(DiagKind::CellTableInvalid), 2u) << loaded.diagnostics;  // one per region
  std::size_t in_table = 0;
  for (const Diagnostic& d : loaded.all) {
    if (d.range.begin.file != 0 && loaded.file_names[d.range.begin.file].ends_with("folded.csv")) ++in_table;
  }
  EXPECT_EQ(in_table, 1u) << loaded.diagnostics;
}

TEST_F(CellText, MarkerGeometryToleranceIsAMicrometreFraction) {
  Loaded close = Load(kRobot + FixtureText(138, 40, 0, "", "190.0000005"));
  EXPECT_TRUE(close.cell.has_value()) << close.diagnostics;
  Loaded off = Load(kRobot + FixtureText(138, 40, 0, "", "190.000002"));
  EXPECT_FALSE(off.cell.has_value());
  EXPECT_EQ(off.count(DiagKind::CellMarkerGeometry), 1u) << off.diagnostics;
  EXPECT_GT(kMarkerGeometryTolMm, 5e-7);
  EXPECT_LT(kMarkerGeometryTolMm, 2e-6);
}

// Two-stage probing: the latch feed is optional, above 0, and never above
// the search's; the latency then follows it.
TEST_F(CellText, LatchSpeedIsTheSlowStage) {
  Loaded one = Load(kRobot + FixtureText(138, 40, 0, ""));
  ASSERT_TRUE(one.cell.has_value()) << one.diagnostics;
  EXPECT_EQ(one.cell->fixtures[0].latch_speed_mm_s, 0);
  EXPECT_EQ(one.cell->fixtures[0].TripLatchSpeedMmS(), 12);
  Loaded two = Load(kRobot + FixtureText(138, 40, 0, "latch_speed_mm_s = 4"));
  ASSERT_TRUE(two.cell.has_value()) << two.diagnostics;
  EXPECT_EQ(two.cell->fixtures[0].latch_speed_mm_s, 4);
  EXPECT_EQ(two.cell->fixtures[0].TripLatchSpeedMmS(), 4);
  for (const char* bad : {"latch_speed_mm_s = 0", "latch_speed_mm_s = -1", "latch_speed_mm_s = 13"}) {
    Loaded refused = Load(kRobot + FixtureText(138, 40, 0, bad));
    EXPECT_FALSE(refused.cell.has_value()) << bad;
    EXPECT_EQ(refused.count(DiagKind::CellValueOutOfRange), 1u) << bad << ": " << refused.diagnostics;
  }
  // The controller's turnaround per probe move: 0.025 s unless stated, 0 to 1 s.
  EXPECT_EQ(one.cell->robot.probe_turnaround_s, 0.025);
  Loaded turnaround = Load(kRobot + "probe_turnaround_s = 0.004\n" + FixtureText(138, 40, 0, ""));
  ASSERT_TRUE(turnaround.cell.has_value()) << turnaround.diagnostics;
  EXPECT_EQ(turnaround.cell->robot.probe_turnaround_s, 0.004);
  for (const char* bad : {"probe_turnaround_s = -0.01\n", "probe_turnaround_s = 2\n"}) {
    Loaded refused = Load(kRobot + bad + FixtureText(138, 40, 0, ""));
    EXPECT_FALSE(refused.cell.has_value()) << bad;
    EXPECT_EQ(refused.count(DiagKind::CellValueOutOfRange), 1u) << bad << ": " << refused.diagnostics;
  }
}

// Random nominal poses and teach-time boards near them: a teach scan is
// accepted exactly when every trip is within the trip window of where the
// nominal pose puts it, and trips out of order are refused.
TEST_F(CellText, TeachScansOfRandomBoardPoses) {
  const std::uint64_t seed = BaseSeed();
  SCOPED_TRACE(fmt::format("seed {} (set SMTCAL_TEST_SEED to vary)", seed));
  std::mt19937_64 rng(seed);
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  for (int round = 0; round < 20; ++round) {
    const Point2 nominal(uniform(100, 150), uniform(40, 80));
    const double nominal_deg = uniform(-20, 20);
    const Eigen::Affine3d nominal_fix = PlanarFix(nominal, nominal_deg * kRadPerDeg);
    const Eigen::Affine3d board = PlanarFix(nominal + Point2(uniform(-1, 1), uniform(-1, 1)),
                                            (nominal_deg + uniform(-0.3, 0.3)) * kRadPerDeg);
    std::vector<Point2> trips;
    double farthest = 0;
    for (const Point2& t : kPaperTrips) {
      trips.push_back(ToBase(board, t));
      farthest = std::max(farthest, (trips.back() - ToBase(nominal_fix, t)).norm());
    }
    Loaded good = Load(kRobot + FixtureText(nominal.x(), nominal.y(), nominal_deg, TeachTrips(trips)));
    EXPECT_EQ(good.cell.has_value(), farthest <= 3) << "round " << round << ": " << good.diagnostics;
    if (good.cell) {
      for (std::size_t k = 0; k < trips.size(); ++k) EXPECT_EQ(good.cell->fixtures[0].teach_trips_mm[k], trips[k]);
    }
    std::swap(trips[0], trips[4]);  // T1 <-> T5: across the board
    Loaded swapped = Load(kRobot + FixtureText(nominal.x(), nominal.y(), nominal_deg, TeachTrips(trips)));
    EXPECT_FALSE(swapped.cell.has_value());
    EXPECT_EQ(swapped.count(DiagKind::CellTeachTripFar), 2u) << "round " << round << ": " << swapped.diagnostics;
  }
}

TEST_F(CellText, FindIsCaseInsensitive) {
  std::string feeder = R"(
[[feeder]]
name = "Bank1"
pick = [160, 10, -12, 0]
)";
  Loaded loaded = Load(kRobot + FixtureText(138, 40, 0, "") + feeder);
  ASSERT_TRUE(loaded.cell.has_value()) << loaded.diagnostics;
  EXPECT_EQ(loaded.cell->FindFixture("BOARD"), &loaded.cell->fixtures[0]);
  EXPECT_EQ(loaded.cell->FindFeeder("bank1"), &loaded.cell->feeders[0]);
  EXPECT_EQ(loaded.cell->FindFixture("Tray"), nullptr);
  EXPECT_FALSE(loaded.cell->feeders[0].pallet_last.has_value());
  EXPECT_EQ(loaded.cell->feeders[0].columns, 1);
  EXPECT_EQ(loaded.cell->name, "t");  // t.cell.toml without a name key
}

TEST_F(CellText, AMissingFileIsAnIoErrorNotADiagnostic) {
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<Cell>> result = LoadCell((dir_ / "none.cell.toml").string(), sources, diags);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().message.find("none.cell.toml"), std::string::npos);
  EXPECT_TRUE(diags.all().empty());
}

TEST(CellNames, AreTheFileSpelling) {
  EXPECT_EQ(EstimatorName(Estimator::kPaper), "paper");
  EXPECT_EQ(EstimatorName(Estimator::kRigid), "rigid");
  EXPECT_EQ(EstimatorName(Estimator::kRigidScale), "rigid-scale");
  EXPECT_EQ(TaskAxisName(TaskAxis::X), "x");
  EXPECT_EQ(TaskAxisName(TaskAxis::U), "u");
  EXPECT_EQ(OutsidePolicyName(OutsidePolicy::kError), "error");
  EXPECT_EQ(OutsidePolicyName(OutsidePolicy::kClamp), "clamp");
  EXPECT_EQ(OutsidePolicyName(OutsidePolicy::kNone), "none");
}

}  // namespace
}  // namespace smtcal::cell
