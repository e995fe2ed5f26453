// The LinuxCNC runtime (runtime/linuxcnc/*.ngc with the data of
// backend/linuxcnc/linuxcnc_data.h) run by LinuxCNC's own interpreter rs274 and
// compared with the C++ implementation (calibration/fixture_estimation.h): a
// harness writes known trips into the trip parameters (the standalone
// interpreter's probe never trips), calls smtcal_estimate and smtcal_correct
// and prints FIX, every check's value, the verdict and the corrected
// targets through (DEBUG, ...) with scaled values; a bad scan aborts before
// the first placement; the example cell's data loads; a replacement
// smtcal_probe_trips.ngc earlier on the subroutine path supplies trips. The
// cycle record every scan leaves (LOG lines, docs/monitor.md) is read back
// with smtcal's reader and equals the C++ scan to 1e-10 mm or deg, small
// values included (LinuxCNC prints a number below 1e-4 as 0: the record
// writes millionths).
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "backend/linuxcnc/embedded_files.h"
#include "backend/linuxcnc/linuxcnc_data.h"
#include "backend/linuxcnc/linuxcnc_record.h"
#include "backend/linuxcnc/linuxcnc_scan_abort.h"
#include "base/diagnostics.h"
#include "calibration/fixture_estimation.h"
#include "calibration/fixture_geometry.h"
#include "calibration/cycle_record.h"
#include "frontend/cell_toml.h"
#include "frontend/record_log.h"
#include "tests/unit/backend/rs274_runner.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;
namespace L = linuxcnc_layout;
using test::Uniform;

// rs274 computes in doubles like C++ (the same operations in the same
// order), only its angles go through degrees (ATAN). The harness prints
// values times 10^6 with 9 decimals (rs274 formats at most %.9f): 1e-15 mm
// or deg, below a double's rounding for positions of a few hundred mm; n and
// o of FIX are compared over a 1000 mm lever, so their printed resolution is
// 1e-12 mm. Measured: FIX within 6e-13 mm, commands 1.2e-13 mm, check values
// 1e-13, angles 3e-14 deg; the tolerance leaves a factor of 10 over that
// (the C runtime's test allows 1e-9 mm).
constexpr double kAgreeMm = 1e-11;
constexpr double kPrintScale = 1e6;
// A cycle record's value against C++: the record prints millionths with 9
// decimals, and LinuxCNC prints a number below 1e-4 as 0, so a value below
// 1e-10 mm or deg reads as 0 (docs/monitor.md); rs274's arithmetic adds at
// most kAgreeMm.
constexpr double kRecordAgree = 1e-10 + kAgreeMm;

const fs::path kPaperCell = fs::path(SMTCAL_SOURCE_DIR) / "examples" / "paper-cell" / "paper.cell.toml";

// A scratch directory with the runtime on its subroutine path: DIR/sub holds
// every embedded runtime file and the cell's smtcal_data.ngc; `first`, when
// given, comes before it on the path.
struct Workspace {
  fs::path dir, sub, ini;
  explicit Workspace(const std::string& name, const cell::Cell& cell, bool with_override_dir = false) {
    static int count = 0;
    dir = fs::temp_directory_path() / fmt::format("smtcal_lcnc_{}_{}_{}", name, ::getpid(), ++count);
    fs::remove_all(dir);
    sub = dir / "sub";
    fs::create_directories(sub);
    for (const EmbeddedFile& file : LinuxCncRuntimeFiles()) {
      std::ofstream(sub / file.name, std::ios::binary) << file.text;
    }
    std::ofstream(sub / "smtcal_data.ngc", std::ios::binary) << EmitLinuxCncData(cell);
    std::ofstream(sub / "smtcal_scan_abort.ngc", std::ios::binary) << EmitLinuxCncScanAbort(cell);
    std::ofstream(sub / "smtcal_record.ngc", std::ios::binary) << EmitLinuxCncRecord(cell);
    std::ofstream(sub / "smtcal_record_open.ngc", std::ios::binary) << EmitLinuxCncRecordOpen(cell);
    std::vector<fs::path> path;
    if (with_override_dir) {
      fs::create_directories(dir / "first");
      path.push_back(dir / "first");
    }
    path.push_back(sub);
    ini = test::WriteRs274Ini(dir, path);
  }
  ~Workspace() {
    if (std::getenv("SMTCAL_KEEP_RS274") == nullptr) fs::remove_all(dir);
  }
  test::Rs274Result Run(const std::string& program) const {
    const fs::path ngc = dir / "main.ngc";
    std::ofstream(ngc, std::ios::binary) << program;
    return test::RunRs274(ini, ngc);
  }
  void Write(const std::string& relative, const std::string& text) const {
    std::ofstream(dir / relative, std::ios::binary) << text;
  }
};

std::optional<cell::Cell> LoadPaperCell(std::string* diagnostics) {
  SourceManager sources;
  Diagnostics diags(sources);
  Result<std::optional<cell::Cell>> result = cell::LoadCell(kPaperCell.string(), sources, diags);
  *diagnostics = diags.RenderText();
  if (!result.ok() || !result.value()) return std::nullopt;
  return std::move(*result.value());
}

std::string Num(double value) { return LinuxCncNumber(value); }

// Prints fixture #2's last scan (#1: the case): "S case status trip has_fix",
// "F case" and FIX, and every check as "C case code evaluated value" (values
// x 10^6). Offsets: the fixture record of runtime/linuxcnc/README.md.
constexpr const char* kReportSub = R"(o<smtcal_test_report> sub
#<f> = #[#35 + #2]
#<_t_status> = #[#<f> + 41]
#<_t_trip> = #[#<f> + 42]
#<_t_has> = #[#<f> + 34]
(DEBUG, S %d#1 %d#<_t_status> %d#<_t_trip> %d#<_t_has>)
#<_t_a> = [#[#<f> + 35] * 1000000]
#<_t_b> = [#[#<f> + 36] * 1000000]
#<_t_c> = [#[#<f> + 37] * 1000000]
#<_t_d> = [#[#<f> + 38] * 1000000]
#<_t_e> = [#[#<f> + 39] * 1000000]
#<_t_g> = [#[#<f> + 40] * 1000000]
(DEBUG, F %d#1 %.9f#<_t_a> %.9f#<_t_b> %.9f#<_t_c> %.9f#<_t_d> %.9f#<_t_e> %.9f#<_t_g>)
#<c> = 1
o<smtcal_test_checks> while [#<c> LE 11]
  #<_t_e> = #[#<f> + 55 + #<c>]
  #<_t_v> = [#[#<f> + 43 + #<c>] * 1000000]
  (DEBUG, C %d#1 %d#<c> %d#<_t_e> %.9f#<_t_v>)
  #<c> = [#<c> + 1]
o<smtcal_test_checks> endwhile
o<smtcal_test_report> endsub
)";

// Prints the last smtcal_correct: "P case index status x y angle" (x 10^6).
constexpr const char* kPointSub = R"(o<smtcal_test_point> sub
#<_t_s> = #<_smtcal_status>
#<_t_x> = [#<_smtcal_x> * 1000000]
#<_t_y> = [#<_smtcal_y> * 1000000]
#<_t_u> = [#<_smtcal_angle> * 1000000]
(DEBUG, P %d#1 %d#2 %d#<_t_s> %.9f#<_t_x> %.9f#<_t_y> %.9f#<_t_u>)
o<smtcal_test_point> endsub
)";

// The G-code that puts trips (nullopt: not tripped) and a previous FIX into
// fixture k's parameters.
std::string SetTrips(int k, const std::vector<std::optional<Eigen::Vector2d>>& trips) {
  std::string out;
  for (std::size_t i = 0; i < trips.size(); ++i) {
    const Eigen::Vector2d t = trips[i].value_or(Eigen::Vector2d::Zero());
    out += fmt::format("#[#[#[#35 + {0}] + {5}] + {1}] = {2}\n#[#[#[#35 + {0}] + {5}] + {3}] = {4}\n", k, 2 * i,
                       Num(t.x()), 2 * i + 1, Num(t.y()), L::kFxTripsAt);
    out += fmt::format("#[#[#[#35 + {}] + {}] + {}] = {}\n", k, L::kFxTrippedAt, i, trips[i] ? 1 : 0);
  }
  return out;
}

std::string SetPrevious(int k, const std::optional<Eigen::Affine3d>& previous) {
  if (!previous) return fmt::format("#[#[#35 + {}] + {}] = 0\n", k, L::kFxHasFix);
  const Eigen::Matrix3d m = previous->linear();
  const Eigen::Vector3d p = previous->translation();
  const double values[6] = {m(0, 0), m(1, 0), m(0, 1), m(1, 1), p.x(), p.y()};
  std::string out = fmt::format("#[#[#35 + {}] + {}] = 1\n", k, L::kFxHasFix);
  for (int i = 0; i < 6; ++i) out += fmt::format("#[#[#35 + {}] + {}] = {}\n", k, L::kFxFix + i, Num(values[i]));
  return out;
}

// What the harness printed, by case.
struct Printed {
  struct Scan {
    int status = -1, trip = -2, has_fix = -1;
    std::array<double, 6> fix{};
    std::array<int, 12> evaluated{};
    std::array<double, 12> value{};
  };
  std::map<int, Scan> scans;
  std::map<std::pair<int, int>, std::array<double, 4>> points;  // status, x, y, angle
};

Printed ParseMessages(const std::vector<std::string>& messages) {
  Printed printed;
  for (const std::string& message : messages) {
    std::istringstream in(message);
    std::string tag;
    int c = 0;
    in >> tag >> c;
    if (tag == "S") {
      Printed::Scan& s = printed.scans[c];
      in >> s.status >> s.trip >> s.has_fix;
    } else if (tag == "F") {
      for (double& v : printed.scans[c].fix) {
        in >> v;
        v /= kPrintScale;
      }
    } else if (tag == "C") {
      int code = 0, evaluated = 0;
      double value = 0;
      in >> code >> evaluated >> value;
      printed.scans[c].evaluated.at(static_cast<std::size_t>(code)) = evaluated;
      printed.scans[c].value.at(static_cast<std::size_t>(code)) = value / kPrintScale;
    } else if (tag == "P") {
      int index = 0;
      std::array<double, 4> v{};
      in >> index >> v[0] >> v[1] >> v[2] >> v[3];
      for (int i = 1; i < 4; ++i) v[static_cast<std::size_t>(i)] /= kPrintScale;
      printed.points[{c, index}] = v;
    }
  }
  return printed;
}

std::string ProgramStart() { return "G21 G90 G17 G94\no<smtcal_data> call\n"; }
std::string ProgramEnd() { return "M2\n"; }

// ------------------------------------------------------------------ data

TEST(LinuxCncData, EveryRuntimeFileHoldsTheSubroutineOfItsName) {
  std::set<std::string> names;
  for (const EmbeddedFile& file : LinuxCncRuntimeFiles()) {
    ASSERT_TRUE(file.name.starts_with("smtcal_") && file.name.ends_with(".ngc")) << file.name;
    const std::string name = file.name.substr(0, file.name.size() - 4);
    names.insert(name);
    EXPECT_NE(file.text.find("\no<" + name + "> sub\n"), std::string::npos) << file.name;
    EXPECT_TRUE(file.text.ends_with("\no<" + name + "> endsub\n")) << file.name;
    // One subroutine per file, every line within rs274's 255 characters.
    std::size_t subs = 0;
    for (std::size_t at = file.text.find("> sub\n"); at != std::string::npos; at = file.text.find("> sub\n", at + 1)) {
      ++subs;
    }
    EXPECT_EQ(subs, 1u) << file.name;
    std::istringstream lines(file.text);
    std::string line;
    while (std::getline(lines, line)) EXPECT_LE(line.size(), 255u) << file.name << ": " << line;
  }
  for (const char* call : {"smtcal_scan", "smtcal_probe_trips", "smtcal_estimate", "smtcal_correct", "smtcal_invert"}) {
    EXPECT_EQ(names.count(call), 1u) << call;
  }
  EXPECT_EQ(names.count("smtcal_data"), 0u) << "generated per cell, not a runtime file";
  EXPECT_EQ(names.count("smtcal_scan_abort"), 0u) << "generated per cell, not a runtime file";
}

TEST(LinuxCncData, NumbersArePlainDecimalsThatReadBackExactly) {
  std::mt19937_64 rng(test::FixtureSeed());
  for (double v : {0.0, -0.0, 1.0, -2.5, 1e-5, 0.1, 123456.789, 1e-17, 6.02e23, 190.0}) {
    const std::string text = LinuxCncNumber(v);
    EXPECT_EQ(text.find_first_of("eE"), std::string::npos) << text;
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), v) << text;
  }
  EXPECT_EQ(LinuxCncNumber(-0.0), "0");
  EXPECT_EQ(LinuxCncNumber(0.1), "0.1");
  EXPECT_EQ(LinuxCncNumber(190), "190");
  for (int i = 0; i < 1000; ++i) {
    const double v = Uniform(rng, -1000, 1000) * std::pow(10.0, std::uniform_int_distribution<int>(-8, 3)(rng));
    EXPECT_EQ(std::strtod(LinuxCncNumber(v).c_str(), nullptr), v);
  }
}

// The fewest decimals that read back, correctly rounded: printf's %.Nf for
// N = 0, 1, ... until strtod gives the value back. LinuxCncNumber computes
// it faster (std::to_chars); this is its definition.
std::string FewestDecimalsReference(double value) {
  if (value == 0) return "0";
  for (int digits = 0;; ++digits) {
    std::string text = fmt::format("{:.{}f}", value, digits);
    if (std::strtod(text.c_str(), nullptr) == value) return text;
  }
}

TEST(LinuxCncData, NumbersAreTheFewestDecimalsCorrectlyRounded) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {}", seed));
  std::mt19937_64 rng(seed);
  std::vector<double> values = {1.0, 0.5, 0.25, 1024.0, 0x1p-20, 0x1p52, 0x1p53, 0x1p53 + 2, 0x1p60, 1e22, 1e23,
                                123456789012345680000.0, 4503599627370495.5, 2251799813685247.75, 0.1, 0.3,
                                1e-300, 5e-324, 1.7976931348623157e308, 160.0561725519, 9.9521064565};
  for (int i = 0; i < 10000; ++i) {
    // Coordinates and table values as smtcal writes them, and any double.
    const double coordinate = std::round(Uniform(rng, -1000, 1000) * 1e10) / 1e10;
    const double scaled = Uniform(rng, -1, 1) * std::pow(10.0, std::uniform_int_distribution<int>(-12, 18)(rng));
    const double power = std::ldexp(1.0, std::uniform_int_distribution<int>(-60, 70)(rng));
    std::uint64_t bits = rng();
    double any = 0;
    std::memcpy(&any, &bits, sizeof any);
    values.insert(values.end(), {coordinate, scaled, power, -power, std::nextafter(power, 0.0),
                                 std::nextafter(power, 1e300)});
    if (std::isfinite(any) && std::abs(any) > 1e-20 && std::abs(any) < 1e60) values.push_back(any);
  }
  for (double v : values) {
    ASSERT_EQ(LinuxCncNumber(v), FewestDecimalsReference(v)) << fmt::format("{:.17g}", v);
    ASSERT_EQ(LinuxCncNumber(-v), FewestDecimalsReference(-v)) << fmt::format("{:.17g}", -v);
  }
}

TEST(LinuxCncData, ExampleCellIsDeterministicAndSaysWhereItCameFrom) {
  std::string diagnostics;
  const std::optional<cell::Cell> cell = LoadPaperCell(&diagnostics);
  ASSERT_TRUE(cell) << diagnostics;
  EXPECT_EQ(LinuxCncDataProblem(*cell), std::nullopt);
  const std::string text = EmitLinuxCncData(*cell);
  EXPECT_EQ(text, EmitLinuxCncData(*cell));
  EXPECT_NE(text.find("cell paper-cell ("), std::string::npos);
  EXPECT_NE(text.find("paper.cell.toml"), std::string::npos);
  EXPECT_NE(text.find("o<smtcal_data> sub\n"), std::string::npos);
  EXPECT_TRUE(text.ends_with("o<smtcal_data> endsub\n"));
  // Every assignment's number is a plain decimal (rs274 reads no exponent).
  std::istringstream lines(text);
  std::string line;
  int assignments = 0;
  while (std::getline(lines, line)) {
    if (!line.starts_with("#")) continue;
    ++assignments;
    const std::string number = line.substr(line.find('=') + 2, line.find(' ', line.find('=') + 2) - line.find('=') - 2);
    EXPECT_EQ(number.find_first_not_of("-.0123456789"), std::string::npos) << line;
  }
  EXPECT_GT(assignments, 1000);
}

// Every program of a cell shares its runtime folder (compile --ini), the
// record's subroutines with it: they hold nothing of a program, and the
// runtime id the main program checks covers them.
TEST(LinuxCncData, RecordSubroutinesArePartOfTheSharedRuntime) {
  std::string diagnostics;
  std::optional<cell::Cell> cell = LoadPaperCell(&diagnostics);
  ASSERT_TRUE(cell) << diagnostics;
  ASSERT_TRUE(cell->linuxcnc && !cell->linuxcnc->record_file.empty());
  EXPECT_EQ(EmitLinuxCncRecordOpen(*cell).find("program="), std::string::npos);
  EXPECT_EQ(EmitLinuxCncRecord(*cell).find("program="), std::string::npos);
  const long id = LinuxCncRuntimeId(*cell);
  cell->linuxcnc->record_file = "other-" + cell->linuxcnc->record_file;
  EXPECT_NE(LinuxCncRuntimeId(*cell), id) << "the record's log file is not in the runtime id";
  cell->linuxcnc->record_file.clear();
  EXPECT_NE(LinuxCncRuntimeId(*cell), id) << "a runtime without a record has the id of one with it";
}

TEST(LinuxCncData, RefusesWhatDoesNotFitTheParameters) {
  std::mt19937_64 rng(7);
  cell::Cell cell;
  cell.name = "big";
  cell.regions.push_back(test::RegionOf("huge", test::RandomSmoothTable(rng, 0, 0, 400, 400, 50, 0.1)));
  const std::optional<std::string> problem = LinuxCncDataProblem(cell);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("#31 to #"), std::string::npos) << *problem;
  cell.regions[0] = test::RegionOf("small", test::RandomSmoothTable(rng, 0, 0, 400, 400, 20, 0.1));
  EXPECT_EQ(LinuxCncDataProblem(cell), std::nullopt);
}

// ------------------------------------------------------------------ the harness

// The faults the harness injects, one per case in turn, so every check's
// verdict comes up in every run of the test.
enum class Fault {
  kNone, kMissingTrip, kTripWindow, kCoincidentTrips, kOutlier, kNominalShift, kNominalRotation, kCycleShift,
  kCycleRotation, kNoisyPrevious
};
constexpr int kFaultCount = 10;

// A cell for one rs274 run: the paper's board anywhere in the plane with the
// given estimator, a table over the board's middle (the points' region, a
// random outside policy) and, now and then, one over marker 1 (its trips are
// direct-calibrated). A wide trip window, so shifted boards reach the later
// checks.
cell::Cell HarnessCell(std::mt19937_64& rng, cell::Estimator estimator) {
  cell::Cell cell;
  cell.name = "harness";
  cell::Fixture fixture = test::PaperFixture(estimator);
  fixture.origin_mm = {Uniform(rng, -400, 400), Uniform(rng, -400, 400)};
  fixture.angle_deg = Uniform(rng, -180, 180);
  fixture.trip_window_mm = 8;
  fixture.max_line_residual_mm = 0.07;
  fixture.length_tolerance_mm = Uniform(rng, 0, 1) < 0.5 ? 0.1 : 20;
  fixture.squareness_deg = Uniform(rng, 0, 1) < 0.5 ? 0.2 : 10;
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const Eigen::Vector2d middle = ToBase(nominal, Eigen::Vector2d(95, 45));
  const OutsidePolicy policies[] = {OutsidePolicy::kError, OutsidePolicy::kClamp, OutsidePolicy::kNone};
  cell.regions.push_back(test::RegionOf(
      "board", test::RandomSmoothTable(rng, middle.x() - 60, middle.y() - 60, 120, 120,
                                       std::uniform_int_distribution<int>(2, 20)(rng), Uniform(rng, 0.01, 0.3)),
      Uniform(rng, -4, 1), policies[std::uniform_int_distribution<int>(0, 2)(rng)]));
  if (Uniform(rng, 0, 1) < 0.6) {
    const Eigen::Vector2d marker = ToBase(nominal, Eigen::Vector2d(2, 2));
    cell.regions.push_back(test::RegionOf(
        "marker1", test::RandomSmoothTable(rng, marker.x() - 20, marker.y() - 20, 40, 40, 6, 0.2)));
  }
  // A second board first, so the fixture under test is index 1 and the
  // runtime's fixture directory is exercised.
  cell::Fixture decoy = test::PaperFixture(cell::Estimator::kRigid);
  decoy.name = "Decoy";
  decoy.origin_mm = fixture.origin_mm + Eigen::Vector2d(300, 0);
  cell.fixtures.push_back(decoy);
  cell.fixtures.push_back(fixture);
  cell::LinuxCnc linuxcnc;
  linuxcnc.record_file = "harness.log";  // rs274 prints the LOG lines instead
  cell.linuxcnc = linuxcnc;
  return cell;
}

// The cycle records among rs274's canonical commands: LOG("line").
std::string LoggedText(const test::Rs274Result& run) {
  std::string text;
  for (const std::string& line : run.canon) {
    if (line.starts_with("LOG(\"") && line.ends_with("\")")) text += line.substr(5, line.size() - 7) + "\n";
  }
  return text;
}

// The harness's fixture in HarnessCell.
constexpr int kHarnessFixture = 1;

struct HarnessCase {
  std::vector<std::optional<Eigen::Vector2d>> trips;
  std::optional<Eigen::Affine3d> previous;
  std::vector<Eigen::Vector2d> fixture_points, base_points;
};

HarnessCase MakeHarnessCase(std::mt19937_64& rng, const cell::Cell& cell, const cell::Fixture& fixture,
                            Fault fault) {
  HarnessCase c;
  double shift = 0.6, turn_deg = 0.2;
  if (fault == Fault::kNominalShift) shift = 2.8;
  if (fault == Fault::kNominalRotation) turn_deg = 0.8;
  Eigen::Vector2d offset(Uniform(rng, -shift, shift), Uniform(rng, -shift, shift));
  if (fault == Fault::kNominalShift) offset = offset.normalized() * Uniform(rng, 2.2, 2.8);
  double turn = Uniform(rng, -turn_deg, turn_deg);
  if (fault == Fault::kNominalRotation) turn = (turn < 0 ? -1 : 1) * Uniform(rng, 0.6, 0.8);
  const Eigen::Affine3d truth =
      PlanarFix(fixture.origin_mm + offset, (fixture.angle_deg + turn) * kRadPerDeg,
                fixture.estimator == cell::Estimator::kRigidScale ? 1 + Uniform(rng, -2e-4, 2e-4) : 1);
  std::vector<double> sensor;
  std::vector<Eigen::Vector2d> robot;
  const double accuracy = Uniform(rng, 0, 1) < 0.5 ? 0.02 : 0.002;
  const std::size_t trip_count = ExpectedTrips(fixture).size();
  for (std::size_t k = 0; k < trip_count; ++k) {
    sensor.push_back(Uniform(rng, -accuracy, accuracy));
    robot.emplace_back(Uniform(rng, -0.003, 0.003), Uniform(rng, -0.003, 0.003));
  }
  std::vector<Eigen::Vector2d> trips = test::SimulateTrips(fixture, truth, sensor, robot);
  // Where a table covers a trip the robot really stands at t + Delta(t):
  // command t - Delta(t) (to first order) so the calibrated trip is on its edge.
  for (Eigen::Vector2d& t : trips) t -= DirectCalibrateInCell(cell.regions, t) - t;
  c.trips = test::Present(trips);
  const std::size_t k = std::uniform_int_distribution<std::size_t>(0, trip_count - 1)(rng);
  switch (fault) {
    case Fault::kMissingTrip: c.trips[k].reset(); break;
    case Fault::kTripWindow: *c.trips[k] += Eigen::Vector2d(Uniform(rng, 8.5, 10), Uniform(rng, -2, 2)); break;
    case Fault::kCoincidentTrips: c.trips[1] = c.trips[2]; break;  // T2, T3 on p1
    case Fault::kOutlier: *c.trips[k] += Eigen::Vector2d(Uniform(rng, -0.6, 0.6), Uniform(rng, -0.6, 0.6)); break;
    default: break;
  }
  if (fault == Fault::kCycleShift || fault == Fault::kCycleRotation || fault == Fault::kNoisyPrevious ||
      Uniform(rng, 0, 1) < 0.3) {
    Eigen::Vector2d moved(Uniform(rng, -0.3, 0.3), Uniform(rng, -0.3, 0.3));
    double turned = Uniform(rng, -0.1, 0.1);
    if (fault == Fault::kCycleShift) moved = Eigen::Vector2d(Uniform(rng, 2.2, 3), Uniform(rng, -1, 1));
    if (fault == Fault::kCycleRotation) turned = Uniform(rng, 0.6, 1.0) * (Uniform(rng, 0, 1) < 0.5 ? -1 : 1);
    c.previous = PlanarFix(FixOrigin(truth) + moved, FixAngleRad(truth) + turned * kRadPerDeg);
  }
  for (int i = 0; i < 4; ++i) c.fixture_points.emplace_back(Uniform(rng, 20, 170), Uniform(rng, -30, 120));
  const Eigen::Affine3d nominal = NominalFix(fixture);
  for (int i = 0; i < 2; ++i) {
    c.base_points.push_back(ToBase(nominal, Eigen::Vector2d(Uniform(rng, 20, 170), Uniform(rng, -30, 120))));
  }
  return c;
}

struct Agreement {
  double fix_mm = 0, check = 0, point_mm = 0, angle_deg = 0;
  int scans = 0, points = 0, refused_points = 0;
  std::map<std::string, int> verdicts;
  std::map<int, int> point_statuses;
};

// One rs274 run: `cases` scans of one random cell, each with its corrected
// points, compared with C++.
void RunHarness(std::mt19937_64& rng, cell::Estimator estimator, int cases, int first_fault, Agreement& agreement) {
  const cell::Cell cell = HarnessCell(rng, estimator);
  const cell::Fixture& fixture = cell.fixtures[kHarnessFixture];
  ASSERT_EQ(LinuxCncDataProblem(cell), std::nullopt);
  const Workspace ws("harness", cell);
  ws.Write("sub/smtcal_test_report.ngc", kReportSub);
  ws.Write("sub/smtcal_test_point.ngc", kPointSub);
  const PointCorrector corrector(cell.regions);

  struct Expected {
    ScanResult scan;
    std::vector<std::pair<int, CorrectedPoint>> points;  // index (fixture points 0.., base points 100..)
    std::vector<double> angles;
  };
  std::vector<Expected> expected;
  std::string program = ProgramStart() + "#37 = 1 (report failed checks, do not abort)\n";
  for (int i = 0; i < cases; ++i) {
    const auto fault = static_cast<Fault>((first_fault + i) % kFaultCount);
    const HarnessCase c = MakeHarnessCase(rng, cell, fixture, fault);
    ScanOptions options;
    options.estimator = fixture.estimator;
    options.regions = &cell.regions;
    options.previous = c.previous;
    Expected e{ScanFixture(fixture, c.trips, options), {}, {}};
    program += fmt::format("(case {})\n", i) + SetTrips(kHarnessFixture, c.trips) +
               SetPrevious(kHarnessFixture, c.previous);
    program += fmt::format("o<smtcal_estimate> call [{0}]\no<smtcal_test_report> call [{1}] [{0}]\n",
                           kHarnessFixture, i);
    // Points: those C++ corrects (an `error` refusal aborts the program; its
    // own test covers it).
    auto add = [&](int index, int k, const Eigen::Vector2d& xy, const CorrectedPoint& point) {
      if (point.region >= 0 && (point.solution.status == SolveStatus::kOutside ||
                                point.solution.status == SolveStatus::kNotConverged)) {
        ++agreement.refused_points;
        return;
      }
      e.points.emplace_back(index, point);
      program += fmt::format("o<smtcal_correct> call [{}] [{}] [{}]\no<smtcal_test_point> call [{}] [{}]\n", k,
                             Num(xy.x()), Num(xy.y()), i, index);
    };
    if (e.scan.fix) {
      for (std::size_t p = 0; p < c.fixture_points.size(); ++p) {
        add(static_cast<int>(p), kHarnessFixture, c.fixture_points[p], corrector.Correct(*e.scan.fix, c.fixture_points[p]));
      }
    }
    for (std::size_t p = 0; p < c.base_points.size(); ++p) {
      add(100 + static_cast<int>(p), -1, c.base_points[p], corrector.Invert(c.base_points[p]));
    }
    expected.push_back(std::move(e));
  }
  program += ProgramEnd();
  const test::Rs274Result run = ws.Run(program);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Printed printed = ParseMessages(run.messages);
  // Every scan's record, refused or not, read back as smtcal monitor reads it.
  SourceManager sources;
  Diagnostics diags(sources);
  RecordLog log;
  const std::string logged = LoggedText(run);
  ASSERT_TRUE(ReadRecordLog(sources.Add("harness.log", logged), log, diags)) << diags.RenderText() << logged;
  ASSERT_EQ(diags.warning_count(), 0u) << diags.RenderText();
  ASSERT_EQ(log.begins.size(), 1u);
  EXPECT_EQ(log.begins[0].begin.fixtures.size(), 2u);
  ASSERT_EQ(log.cycles.size(), static_cast<std::size_t>(cases)) << logged;

  for (int i = 0; i < cases; ++i) {
    SCOPED_TRACE(fmt::format("case {} (fault {})", i, (first_fault + i) % kFaultCount));
    const ScanResult& cpp = expected[static_cast<std::size_t>(i)].scan;
    {
      // The record: what C++ makes of the same trips, to the record's resolution.
      const CycleRecord want = RecordOfScan(kHarnessFixture, i + 1, std::nullopt, cpp);
      const CycleRecord& got = log.cycles[static_cast<std::size_t>(i)].record;
      EXPECT_EQ(got.fixture, want.fixture);
      EXPECT_EQ(got.cycle, want.cycle);
      EXPECT_EQ(got.status, want.status);
      EXPECT_EQ(got.trip, want.trip);
      EXPECT_FALSE(got.time_s);
      ASSERT_EQ(got.trips.size(), want.trips.size());
      for (std::size_t k = 0; k < want.trips.size(); ++k) {
        ASSERT_EQ(got.trips[k].has_value(), want.trips[k].has_value()) << "T" << k + 1;
        if (want.trips[k]) {
          EXPECT_LE((*got.trips[k] - *want.trips[k]).cwiseAbs().maxCoeff(), kRecordAgree);
        }
      }
      for (std::size_t c = 0; c < want.checks.size(); ++c) {
        ASSERT_EQ(got.checks[c].has_value(), want.checks[c].has_value()) << "check " << c + 1;
        if (want.checks[c]) {
          EXPECT_LE(std::abs(*got.checks[c] - *want.checks[c]), kRecordAgree)
              << "check " << c + 1 << ": recorded " << *got.checks[c] << ", C++ " << *want.checks[c];
        }
      }
      ASSERT_EQ(got.estimate.has_value(), want.estimate.has_value());
      for (std::size_t k = 0; k < 3 && want.estimate; ++k) {
        EXPECT_LE(((*got.estimate)[k] - (*want.estimate)[k]).cwiseAbs().maxCoeff(), kRecordAgree);
      }
    }
    ASSERT_EQ(printed.scans.count(i), 1u) << run.out;
    const Printed::Scan& s = printed.scans.at(i);
    const CheckResult* failure = cpp.FirstFailure();
    const int code = failure != nullptr ? static_cast<int>(failure->check) : 0;
    ASSERT_EQ(s.status, code) << (failure ? DescribeCheck(*failure, fixture) : "");
    ++agreement.verdicts[failure != nullptr ? std::string(ScanCheckName(failure->check)) : "ok"];
    ++agreement.scans;
    if (failure != nullptr) {
      EXPECT_EQ(s.trip, failure->trip);
    }
    for (const CheckResult& check : cpp.checks) {
      const auto c = static_cast<std::size_t>(check.check);
      ASSERT_EQ(s.evaluated[c], check.evaluated ? 1 : 0) << ScanCheckName(check.check);
      if (!check.evaluated) continue;
      const double difference = std::abs(s.value[c] - check.value);
      agreement.check = std::max(agreement.check, difference);
      EXPECT_LE(difference, kAgreeMm) << ScanCheckName(check.check) << " rs274 " << s.value[c] << " C++ "
                                      << check.value;
    }
    if (cpp.fix) {
      ASSERT_EQ(s.has_fix, 1);
      const Eigen::Matrix3d m = cpp.fix->linear();
      const double want[6] = {m(0, 0), m(1, 0), m(0, 1), m(1, 1), cpp.fix->translation().x(),
                              cpp.fix->translation().y()};
      for (std::size_t v = 0; v < 6; ++v) {
        // n and o over a 1000 mm lever, p in mm
        const double difference = std::abs(s.fix[v] - want[v]) * (v < 4 ? 1000 : 1);
        agreement.fix_mm = std::max(agreement.fix_mm, difference);
        EXPECT_LE(difference, kAgreeMm) << "FIX value " << v;
      }
    }
    for (const auto& [index, point] : expected[static_cast<std::size_t>(i)].points) {
      SCOPED_TRACE(fmt::format("point {}", index));
      ASSERT_EQ(printed.points.count({i, index}), 1u) << run.out;
      const std::array<double, 4>& p = printed.points.at({i, index});
      const int status = point.region < 0 ? 5 : static_cast<int>(point.solution.status);
      EXPECT_EQ(static_cast<int>(p[0]), status);
      ++agreement.point_statuses[status];
      ++agreement.points;
      const double dx = std::abs(p[1] - point.command.x()), dy = std::abs(p[2] - point.command.y());
      agreement.point_mm = std::max({agreement.point_mm, dx, dy});
      EXPECT_LE(std::max(dx, dy), kAgreeMm);
      const double angle = index >= 100 ? 0 : FixAngleRad(*cpp.fix) * kDegPerRad;
      agreement.angle_deg = std::max(agreement.angle_deg, std::abs(p[3] - angle));
      EXPECT_LE(std::abs(p[3] - angle), kAgreeMm);
    }
  }
}

// ------------------------------------------------------------------ rs274

// A replacement smtcal_probe_trips.ngc for fixture 0: the given trips, all
// tripped, every x moved by the program's #<_t_dx>.
std::string ReplacementProbe(const std::vector<Eigen::Vector2d>& trips) {
  std::string out = "; test replacement of the runtime's smtcal_probe_trips.ngc: known trips\n";
  out += "o<smtcal_probe_trips> sub\n";
  for (std::size_t i = 0; i < trips.size(); ++i) {
    out += fmt::format("#[#[#[#35 + #1] + {}] + {}] = [{} + #<_t_dx>]\n", L::kFxTripsAt, 2 * i, Num(trips[i].x()));
    out += fmt::format("#[#[#[#35 + #1] + {}] + {}] = {}\n", L::kFxTripsAt, 2 * i + 1, Num(trips[i].y()));
    out += fmt::format("#[#[#[#35 + #1] + {}] + {}] = 1\n", L::kFxTrippedAt, i);
  }
  return out + "o<smtcal_probe_trips> endsub\n";
}

TEST(LinuxCncRuntime, ExampleCellDataLoadsAndNominalTripsGiveTheNominalPose) {
  std::string diagnostics;
  const std::optional<cell::Cell> cell = LoadPaperCell(&diagnostics);
  ASSERT_TRUE(cell) << diagnostics;
  const Workspace ws("example", *cell, /*with_override_dir=*/true);
  const cell::Fixture& fixture = cell->fixtures[0];
  const Eigen::Affine3d nominal = NominalFix(fixture);
  ws.Write("first/smtcal_probe_trips.ngc", ReplacementProbe(CommandedTrips(fixture, cell->regions, nominal)));
  ws.Write("sub/smtcal_test_report.ngc", kReportSub);
  ws.Write("sub/smtcal_test_point.ngc", kPointSub);
  // A layer point on the board and a feeder position in the base frame.
  const Eigen::Vector2d board_point(40, 45), feeder(200, 20);
  const test::Rs274Result run = ws.Run(
      ProgramStart() + "#<_t_dx> = 0\no<smtcal_scan> call [0]\no<smtcal_test_report> call [0] [0]\n" +
      fmt::format("o<smtcal_correct> call [0] [{}] [{}]\no<smtcal_test_point> call [0] [0]\n", Num(board_point.x()),
                  Num(board_point.y())) +
      fmt::format("o<smtcal_correct> call [-1] [{}] [{}]\no<smtcal_test_point> call [0] [1]\n", Num(feeder.x()),
                  Num(feeder.y())) +
      ProgramEnd());
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  const Printed printed = ParseMessages(run.messages);
  ASSERT_EQ(printed.scans.count(0), 1u) << run.out;
  const Printed::Scan& s = printed.scans.at(0);
  EXPECT_EQ(s.status, 0);
  EXPECT_EQ(s.has_fix, 1);
  const double want[6] = {nominal.linear()(0, 0), nominal.linear()(1, 0), nominal.linear()(0, 1),
                          nominal.linear()(1, 1), nominal.translation().x(), nominal.translation().y()};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(s.fix[static_cast<std::size_t>(i)], want[i], kAgreeMm) << i;
  // The corrections through the example's error tables.
  const PointCorrector corrector(cell->regions);
  const CorrectedPoint on_board = corrector.Correct(nominal, board_point);
  const CorrectedPoint at_feeder = corrector.Invert(feeder);
  ASSERT_GE(on_board.region, 0);
  ASSERT_GE(at_feeder.region, 0);
  for (const auto& [index, expected] : {std::pair{0, on_board}, std::pair{1, at_feeder}}) {
    ASSERT_EQ(printed.points.count({0, index}), 1u) << run.out;
    const std::array<double, 4>& p = printed.points.at({0, index});
    EXPECT_EQ(static_cast<int>(p[0]), static_cast<int>(expected.solution.status));
    EXPECT_NEAR(p[1], expected.command.x(), kAgreeMm);
    EXPECT_NEAR(p[2], expected.command.y(), kAgreeMm);
    EXPECT_GT((expected.command - expected.required).norm(), 0.01) << "the tables correct it";
  }
  // No probe move: the replacement supplied the trips.
  for (const test::CanonMove& move : run.moves) EXPECT_NE(move.kind, "STRAIGHT_PROBE");
}

TEST(LinuxCncRuntime, SecondScanIsCheckedAgainstTheFirstAndAbortsBeforePlacing) {
  std::string diagnostics;
  const std::optional<cell::Cell> cell = LoadPaperCell(&diagnostics);
  ASSERT_TRUE(cell) << diagnostics;
  const Workspace ws("cycle", *cell, /*with_override_dir=*/true);
  const cell::Fixture& fixture = cell->fixtures[0];
  ws.Write("first/smtcal_probe_trips.ngc", ReplacementProbe(CommandedTrips(fixture, cell->regions, NominalFix(fixture))));
  // 1.5 mm and then -1 mm from nominal: each within max_shift_mm = 2 of
  // nominal, but 2.5 mm from each other (commanded: the trips are
  // direct-calibrated through the marker tables, whose slope makes the real
  // move 2.4992 mm).
  const test::Rs274Result run = ws.Run(ProgramStart() +
                                       "#<_t_dx> = 1.5\no<smtcal_scan> call [0]\nM64 P7\n"
                                       "#<_t_dx> = -1\no<smtcal_scan> call [0]\nM64 P8\n" +
                                       ProgramEnd());
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_NE(run.err.find("smtcal: marker scan of fixture Board failed check cycle_shift: the origin moved 2.4992 mm "
                         "since the last scan, limit max_shift_mm 2.0000"),
            std::string::npos)
      << run.err;
  const bool first_placed = std::count(run.canon.begin(), run.canon.end(), "SET_AUX_OUTPUT_BIT(7)") == 1;
  EXPECT_TRUE(first_placed) << "the first scan passed";
  for (const std::string& line : run.canon) EXPECT_NE(line, "SET_AUX_OUTPUT_BIT(8)");
}

TEST(LinuxCncRuntime, BadScanAbortsBeforeTheFirstPlacement) {
  std::string diagnostics;
  const std::optional<cell::Cell> cell = LoadPaperCell(&diagnostics);
  ASSERT_TRUE(cell) << diagnostics;
  const Workspace ws("badscan", *cell);
  // The real probe file: rs274's probe never trips.
  const test::Rs274Result run = ws.Run(ProgramStart() + "F600\no<smtcal_scan> call [0]\nM64 P8\n" + ProgramEnd());
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_NE(run.err.find("\nsmtcal: marker scan of fixture Board failed check missing_trip: 8 trips missing, the first "
                         "T1, limit 0\n"),
            std::string::npos)
      << "the message on a line of its own, no leading space: " << run.err;
  for (const std::string& line : run.canon) EXPECT_EQ(line.find("SET_AUX_OUTPUT_BIT"), std::string::npos) << line;
  // The scan: the first probe of each path toward its first leg's end at the
  // scan z, entering a marker (G38.3 prints no direction; its target is the
  // leg's end); after the miss the path is left.
  const cell::Fixture& fixture = cell->fixtures[0];
  const std::vector<std::vector<Eigen::Vector2d>> paths = ScanPathsInBase(fixture, NominalFix(fixture));
  std::vector<test::CanonMove> probes;
  for (const test::CanonMove& move : run.moves) {
    if (move.kind == "STRAIGHT_PROBE") probes.push_back(move);
  }
  ASSERT_EQ(probes.size(), paths.size()) << run.out;
  for (std::size_t p = 0; p < paths.size(); ++p) {
    EXPECT_NEAR(probes[p].xyzabc[0], paths[p][1].x(), 1e-4);
    EXPECT_NEAR(probes[p].xyzabc[1], paths[p][1].y(), 1e-4);
    EXPECT_NEAR(probes[p].xyzabc[2], fixture.scan_z_mm, 1e-4);
  }
  EXPECT_NE(std::find(run.canon.begin(), run.canon.end(),
                      fmt::format("SET_FEED_RATE({:.4f})", fixture.scan_speed_mm_s * 60)),
            run.canon.end())
      << "the search at scan_speed_mm_s: " << fixture.scan_speed_mm_s;
  EXPECT_NE(std::find(run.canon.begin(), run.canon.end(), "SET_FEED_RATE(600.0000)"), run.canon.end())
      << "the program's feed restored";
}

TEST(LinuxCncRuntime, ProbeMovesFollowThePathsWhenTheSensorTrips) {
  // rs274's probe never trips, so this checks the probe file's walk on a
  // copy whose probe moves are replaced by a simulated sensor: a G38.x
  // becomes a G1 to the expected trip and sets #5070, #5061, #5062. One
  // stage (the latch feed 0): the two-stage moves back over each edge go
  // toward where the search started, which this simulation cannot place.
  std::string diagnostics;
  std::optional<cell::Cell> cell = LoadPaperCell(&diagnostics);
  ASSERT_TRUE(cell) << diagnostics;
  cell->fixtures[0].latch_speed_mm_s = 0;
  const Workspace ws("walk", *cell, /*with_override_dir=*/true);
  const cell::Fixture& fixture = cell->fixtures[0];
  const std::vector<Eigen::Vector2d> trips = NominalTrips(fixture, NominalFix(fixture));
  std::string probe;
  for (const EmbeddedFile& file : LinuxCncRuntimeFiles()) {
    if (file.name == "smtcal_probe_trips.ngc") probe = file.text;
  }
  ASSERT_FALSE(probe.empty());
  // #5061.. are read-only: the copy reads the simulated trip from #<_t_hit_x/y>.
  std::string simulated;
  for (std::size_t k = 0; k < trips.size(); ++k) {
    simulated += fmt::format("o<smtcal_t_sim_LABEL> {}if [#<trip> EQ {}]\n#<_t_hx> = {}\n#<_t_hy> = {}\n",
                             k == 0 ? "" : "else", k, Num(trips[k].x()), Num(trips[k].y()));
  }
  simulated += "o<smtcal_t_sim_LABEL> endif\nG1 X#<_t_hx> Y#<_t_hy>\n";
  auto replace_all = [](std::string text, const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
      text.replace(at, from.size(), to);
    }
    return text;
  };
  probe = replace_all(probe, "G38.3 X#<x> Y#<y>\n",
                      "(DEBUG, enter %d#<trip>)\n" + replace_all(simulated, "LABEL", "enter"));
  probe = replace_all(probe, "G38.5 X#<x> Y#<y>\n",
                      "(DEBUG, leave %d#<trip>)\n" + replace_all(simulated, "LABEL", "leave"));
  probe = replace_all(probe, "= #5070\n", "= 1\n");
  probe = replace_all(probe, "= #5061\n", "= #<_t_hx>\n");
  probe = replace_all(probe, "= #5062\n", "= #<_t_hy>\n");
  ws.Write("first/smtcal_probe_trips.ngc", probe);
  ws.Write("sub/smtcal_test_report.ngc", kReportSub);
  const test::Rs274Result run =
      ws.Run(ProgramStart() + "o<smtcal_scan> call [0]\no<smtcal_test_report> call [0] [0]\n" + ProgramEnd());
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  // Enter, leave, enter, leave along each path.
  std::vector<std::string> directions;
  for (const std::string& message : run.messages) {
    if (message.starts_with(" enter") || message.starts_with(" leave")) directions.push_back(message);
  }
  EXPECT_EQ(directions, (std::vector<std::string>{" enter 0", " leave 1", " enter 2", " leave 3", " enter 4",
                                                   " leave 5", " enter 6", " leave 7"}));
  const Printed printed = ParseMessages(run.messages);
  ASSERT_EQ(printed.scans.count(0), 1u);
  EXPECT_EQ(printed.scans.at(0).status, 0);
  // Along each leg its trips, then the leg's end (at the scan feed: one stage).
  const std::vector<std::vector<Eigen::Vector2d>> paths = ScanPathsInBase(fixture, NominalFix(fixture));
  const std::vector<ExpectedTrip> expected = ExpectedTrips(fixture);
  std::vector<Eigen::Vector2d> want;
  for (std::size_t p = 0; p < paths.size(); ++p) {
    for (std::size_t leg = 0; leg + 1 < paths[p].size(); ++leg) {
      for (std::size_t k = 0; k < expected.size(); ++k) {
        if (expected[k].path == p && expected[k].leg == leg) want.push_back(trips[k]);
      }
      want.push_back(paths[p][leg + 1]);
    }
  }
  std::vector<Eigen::Vector2d> feeds;
  for (const test::CanonMove& move : run.moves) {
    if (move.kind == "STRAIGHT_FEED") feeds.emplace_back(move.xyzabc[0], move.xyzabc[1]);
  }
  ASSERT_EQ(feeds.size(), want.size()) << run.out;
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_LT((feeds[i] - want[i]).norm(), 1e-4) << "feed " << i;
}

// One scan with the runtime's abort (#37 = 0): the message for each fault
// the C++ implementation reports, with its value and limit as the runtime
// prints them (4 decimals).
TEST(LinuxCncRuntime, FailedChecksAbortWithTheCheckItsValueAndLimit) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  cell::Cell cell = HarnessCell(rng, cell::Estimator::kRigid);
  cell.regions.resize(1);  // no table over marker 1: the simulated trips fit their edges
  const cell::Fixture& fixture = cell.fixtures[kHarnessFixture];
  const Workspace ws("aborts", cell);
  std::map<std::string, int> seen;
  for (int attempt = 0; attempt < 60 && seen.size() < 7; ++attempt) {
    const auto fault = static_cast<Fault>(1 + attempt % (kFaultCount - 1));
    const HarnessCase c = MakeHarnessCase(rng, cell, fixture, fault);
    ScanOptions options;
    options.estimator = fixture.estimator;
    options.regions = &cell.regions;
    options.previous = c.previous;
    const ScanResult cpp = ScanFixture(fixture, c.trips, options);
    const CheckResult* failure = cpp.FirstFailure();
    if (failure == nullptr) continue;
    const std::string name(ScanCheckName(failure->check));
    if (seen.count(name) != 0) continue;
    seen[name] = 1;
    SCOPED_TRACE(name);
    const test::Rs274Result run =
        ws.Run(ProgramStart() + SetTrips(kHarnessFixture, c.trips) + SetPrevious(kHarnessFixture, c.previous) +
               fmt::format("o<smtcal_estimate> call [{}]\nM64 P8\n", kHarnessFixture) + ProgramEnd());
    EXPECT_EQ(run.exit_code, 1);
    const std::string head = fmt::format("smtcal: marker scan of fixture {} failed check {}: ", fixture.name, name);
    const std::size_t at = run.err.find(head);
    ASSERT_NE(at, std::string::npos) << run.err;
    const std::string message = run.err.substr(at, run.err.find('\n', at) - at);
    if (failure->check == ScanCheck::kMissingTrip) {
      EXPECT_NE(message.find(fmt::format("{} trips missing, the first T{}", failure->value, failure->trip + 1)),
                std::string::npos)
          << message;
    } else {
      EXPECT_NE(message.find(fmt::format("{:.4f}", failure->value)), std::string::npos) << message;
      EXPECT_NE(message.find(fmt::format("{:.4f}", failure->limit)), std::string::npos) << message;
    }
    if (failure->trip >= 0 && failure->check != ScanCheck::kMissingTrip) {
      EXPECT_NE(message.find(fmt::format("T{} ", failure->trip + 1)), std::string::npos) << message;
    }
    for (const std::string& line : run.canon) EXPECT_NE(line, "SET_AUX_OUTPUT_BIT(8)");
  }
  std::string names;
  for (const auto& [name, count] : seen) names += " " + name;
  EXPECT_GE(seen.size(), 6u) << names;
}

TEST(LinuxCncRuntime, CorrectRefusesUnscannedFixturesAndOutsidePoints) {
  std::string diagnostics;
  const std::optional<cell::Cell> cell = LoadPaperCell(&diagnostics);
  ASSERT_TRUE(cell) << diagnostics;
  const Workspace ws("refuse", *cell);
  const test::Rs274Result unscanned =
      ws.Run(ProgramStart() + "o<smtcal_correct> call [0] [40] [45]\nM64 P8\n" + ProgramEnd());
  EXPECT_EQ(unscanned.exit_code, 1);
  EXPECT_NE(unscanned.err.find("smtcal: fixture 0 has not been scanned"), std::string::npos) << unscanned.err;
  // A region whose bounds reach 3 mm beyond its table, policy `error`: a
  // point there needs a command the table does not cover.
  std::mt19937_64 rng(11);
  cell::Cell edge_cell;
  edge_cell.name = "edge";
  edge_cell.regions.push_back(
      test::RegionOf("edge", test::RandomSmoothTable(rng, 0, 0, 100, 100, 6, 0.2), -3, OutsidePolicy::kError));
  const Workspace edge_ws("refuse_edge", edge_cell);
  const PointCorrector corrector(edge_cell.regions);
  const Eigen::Vector2d refused(-2, 50);
  ASSERT_EQ(corrector.Invert(refused).solution.status, SolveStatus::kOutside);
  const test::Rs274Result outside =
      edge_ws.Run(ProgramStart() + fmt::format("o<smtcal_correct> call [-1] [{}] [{}]\nM64 P8\n", Num(refused.x()),
                                          Num(refused.y())) +
             ProgramEnd());
  EXPECT_EQ(outside.exit_code, 1);
  EXPECT_NE(outside.err.find("outside the table of region 0 whose outside policy is error"), std::string::npos)
      << outside.err;
  for (const std::string& line : outside.canon) EXPECT_NE(line, "SET_AUX_OUTPUT_BIT(8)");
}

// LinuxCNC prints a number below 1e-4 as 0 whatever its format: a scan
// that is almost perfect (the board 2.3e-5 deg and some 3e-5 mm off
// nominal, trips within 5e-5 mm, the previous pose as close) has check
// values that small, and its record must keep them, not write 0.
TEST(LinuxCncRuntime, CycleRecordKeepsValuesLinuxCncWouldPrintAsZero) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  cell::Cell cell = HarnessCell(rng, cell::Estimator::kRigid);
  cell.regions.clear();  // no table: the trips are where the board is
  const cell::Fixture& fixture = cell.fixtures[kHarnessFixture];
  const Workspace ws("small", cell);
  const Eigen::Affine3d truth = PlanarFix(fixture.origin_mm + Eigen::Vector2d(3e-5, -2e-5),
                                          (fixture.angle_deg + 2.3e-5) * kRadPerDeg);
  std::vector<double> sensor;
  std::vector<Eigen::Vector2d> robot;
  for (std::size_t k = 0; k < ExpectedTrips(fixture).size(); ++k) {
    sensor.push_back(Uniform(rng, -5e-5, 5e-5));
    robot.emplace_back(0, 0);
  }
  std::vector<Eigen::Vector2d> trips = test::SimulateTrips(fixture, truth, sensor, robot);
  for (Eigen::Vector2d& t : trips) t -= DirectCalibrateInCell(cell.regions, t) - t;
  const std::vector<std::optional<Eigen::Vector2d>> present = test::Present(trips);
  const Eigen::Affine3d previous =
      PlanarFix(FixOrigin(truth) + Eigen::Vector2d(4e-5, 1e-5), FixAngleRad(truth) + 1e-5 * kRadPerDeg);
  ScanOptions options;
  options.estimator = fixture.estimator;
  options.regions = &cell.regions;
  options.previous = previous;
  const ScanResult cpp = ScanFixture(fixture, present, options);
  ASSERT_EQ(cpp.FirstFailure(), nullptr);
  const test::Rs274Result run = ws.Run(ProgramStart() + SetTrips(kHarnessFixture, present) +
                                       SetPrevious(kHarnessFixture, previous) +
                                       fmt::format("o<smtcal_estimate> call [{}]\n", kHarnessFixture) + ProgramEnd());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  SourceManager sources;
  Diagnostics diags(sources);
  RecordLog log;
  const std::string logged = LoggedText(run);
  ASSERT_TRUE(ReadRecordLog(sources.Add("small.log", logged), log, diags)) << diags.RenderText() << logged;
  ASSERT_EQ(log.cycles.size(), 1u) << logged;
  const CycleRecord want = RecordOfScan(kHarnessFixture, 1, std::nullopt, cpp);
  const CycleRecord& got = log.cycles[0].record;
  int small = 0;  // check values LinuxCNC alone would print as 0
  for (std::size_t c = 0; c < want.checks.size(); ++c) {
    ASSERT_TRUE(want.checks[c].has_value()) << "check " << c + 1;
    ASSERT_TRUE(got.checks[c].has_value()) << "check " << c + 1;
    EXPECT_LE(std::abs(*got.checks[c] - *want.checks[c]), kRecordAgree)
        << "check " << c + 1 << ": recorded " << *got.checks[c] << ", C++ " << *want.checks[c] << "\n" << logged;
    if (std::abs(*want.checks[c]) > 1e-9 && std::abs(*want.checks[c]) < 1e-4) ++small;
  }
  // nominal_rotation, cycle_shift, cycle_rotation and the line residuals at least.
  EXPECT_GE(small, 4) << logged;
  for (std::size_t k = 0; k < want.trips.size(); ++k) {
    EXPECT_LE((*got.trips[k] - *want.trips[k]).cwiseAbs().maxCoeff(), kRecordAgree) << "T" << k + 1;
  }
  ASSERT_TRUE(got.estimate.has_value());
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_LE(((*got.estimate)[k] - (*want.estimate)[k]).cwiseAbs().maxCoeff(), kRecordAgree) << "S" << k + 1;
  }
}

TEST(LinuxCncRuntime, HarnessAgreesWithCppOnRandomScansChecksAndPoints) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  Agreement agreement;
  const cell::Estimator estimators[] = {cell::Estimator::kPaper, cell::Estimator::kRigid,
                                        cell::Estimator::kRigidScale};
  constexpr int kRunsPerEstimator = 4, kCasesPerRun = 30;
  for (cell::Estimator estimator : estimators) {
    for (int run = 0; run < kRunsPerEstimator; ++run) {
      SCOPED_TRACE(fmt::format("estimator {} run {}", static_cast<int>(estimator), run));
      RunHarness(rng, estimator, kCasesPerRun, run * 3, agreement);
      if (HasFatalFailure()) return;
    }
  }
  std::string verdicts, statuses;
  for (const auto& [name, count] : agreement.verdicts) verdicts += fmt::format(" {} {}", name, count);
  for (const auto& [status, count] : agreement.point_statuses) statuses += fmt::format(" {}:{}", status, count);
  std::printf(
      "rs274 vs C++ over %d scans and %d points (seed %llu): max |FIX difference| %.3g mm, check values %.3g, "
      "commands %.3g mm, angles %.3g deg; verdicts%s; point statuses%s; %d points refused by C++ not run\n",
      agreement.scans, agreement.points, static_cast<unsigned long long>(seed), agreement.fix_mm, agreement.check,
      agreement.point_mm, agreement.angle_deg, verdicts.c_str(), statuses.c_str(), agreement.refused_points);
  // Every verdict the faults aim at came up (the same in rs274 as in C++).
  for (const char* name : {"ok", "missing_trip", "trip_window", "degenerate", "line_residual", "nominal_shift",
                           "nominal_rotation", "cycle_shift", "cycle_rotation"}) {
    EXPECT_GT(agreement.verdicts[name], 0) << name;
  }
  EXPECT_GT(agreement.verdicts["length_l1"] + agreement.verdicts["length_l2"] + agreement.verdicts["squareness"], 0);
  for (int status : {0, 5}) EXPECT_GT(agreement.point_statuses[status], 0) << "point status " << status;
  EXPECT_GT(agreement.point_statuses[1] + agreement.point_statuses[2], 0) << "clamped or uncorrected points";
}

}  // namespace
}  // namespace smtcal
