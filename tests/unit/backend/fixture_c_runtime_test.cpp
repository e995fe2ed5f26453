// The C99 runtime against the C++ implementation: the same fault codes and
// tolerances, agreement within 1e-9 mm on thousands of random fixture poses,
// scans, tables and points, the emitted C data compiled with `cc` and run,
// and the runtime's promises checked on its object file (no heap, no
// writable globals, nothing from libm but sqrt and atan2).
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "backend/c/c_data.h"
#include "calibration/fixture_estimation.h"
#include "calibration/tolerances.h"
#include "runtime/c/smtcal_runtime.h"
#include "tests/unit/backend/c_object_symbols.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;
using test::Uniform;

constexpr double kAgreeMm = 1e-9;

TEST(FixtureCRuntime, FaultCodesAndTolerancesAreTheCppOnes) {
  for (ScanCheck check : kScanChecks) {
    const auto code = static_cast<smtcal_scan_status>(static_cast<int>(check));
    EXPECT_EQ(std::string(smtcal_scan_status_name(code)), std::string(ScanCheckName(check)));
  }
  EXPECT_EQ(SMTCAL_CHECK_COUNT, static_cast<int>(kScanChecks.size()));
  EXPECT_EQ(static_cast<int>(SolveStatus::kOk), SMTCAL_POINT_OK);
  EXPECT_EQ(static_cast<int>(SolveStatus::kClamped), SMTCAL_POINT_CLAMPED);
  EXPECT_EQ(static_cast<int>(SolveStatus::kUncorrected), SMTCAL_POINT_UNCORRECTED);
  EXPECT_EQ(static_cast<int>(SolveStatus::kOutside), SMTCAL_POINT_OUTSIDE);
  EXPECT_EQ(static_cast<int>(SolveStatus::kNotConverged), SMTCAL_POINT_NOT_CONVERGED);
  EXPECT_EQ(SMTCAL_MIN_TRIP_SEPARATION_MM, kMinTripSeparationMm);
  EXPECT_EQ(SMTCAL_MIN_LINE_CROSSING_SIN, kMinLineCrossingSin);
  EXPECT_EQ(SMTCAL_MIN_RELATIVE_DETERMINANT, kMinRelativeDeterminant);
  EXPECT_EQ(SMTCAL_RIGID_STEP_TOL_RAD, kRigidStepTolRad);
  EXPECT_EQ(SMTCAL_RIGID_MAX_ITERATIONS, kRigidMaxIterations);
  EXPECT_EQ(SMTCAL_INVERSE_RESIDUAL_TOL_MM, kInverseResidualTolMm);
  EXPECT_EQ(SMTCAL_INVERSE_POLISH_MM, kInversePolishMm);
  EXPECT_EQ(SMTCAL_TABLE_EDGE_TOL_MM, kTableEdgeTolMm);
}

smtcal_fix CFix(const Eigen::Affine3d& fix) {
  smtcal_fix c{};
  c.n[0] = fix.linear()(0, 0);
  c.n[1] = fix.linear()(1, 0);
  c.o[0] = fix.linear()(0, 1);
  c.o[1] = fix.linear()(1, 1);
  c.p[0] = fix.translation().x();
  c.p[1] = fix.translation().y();
  return c;
}

double FixDifference(const smtcal_fix& c, const Eigen::Affine3d& fix) {
  const smtcal_fix d = CFix(fix);
  double worst = 0;
  for (int k = 0; k < 2; ++k) {
    worst = std::max({worst, std::abs(c.n[k] - d.n[k]) * 1000, std::abs(c.o[k] - d.o[k]) * 1000,
                      std::abs(c.p[k] - d.p[k])});
  }
  return worst;  // mm over a 1000 mm lever
}

// One random case: a cell with the paper's board anywhere in the plane, a
// table over the board's middle (the points' region) and, in half the cases,
// one over marker 1 (its trips are direct-calibrated); a noisy scan, now and
// then with a fault; a previous FIX in half the cases.
struct RandomCase {
  cell::Cell cell;
  std::vector<std::optional<Eigen::Vector2d>> trips;
  std::optional<Eigen::Affine3d> previous;
  std::vector<Eigen::Vector2d> points;  // fixture frame
};

RandomCase MakeCase(std::mt19937_64& rng) {
  RandomCase c;
  const cell::Estimator estimators[] = {cell::Estimator::kPaper, cell::Estimator::kRigid,
                                        cell::Estimator::kRigidScale};
  cell::Fixture fixture = test::PaperFixture(estimators[std::uniform_int_distribution<int>(0, 2)(rng)]);
  fixture.origin_mm = {Uniform(rng, -400, 400), Uniform(rng, -400, 400)};
  fixture.angle_deg = Uniform(rng, -180, 180);
  // Limits loose enough that most scans pass, so poses are compared too.
  fixture.length_tolerance_mm = Uniform(rng, 0, 1) < 0.5 ? 0.1 : 20;
  fixture.squareness_deg = Uniform(rng, 0, 1) < 0.5 ? 0.2 : 10;
  const Eigen::Affine3d nominal = NominalFix(fixture);
  const Eigen::Affine3d truth =
      PlanarFix(fixture.origin_mm + Eigen::Vector2d(Uniform(rng, -0.6, 0.6), Uniform(rng, -0.6, 0.6)),
                (fixture.angle_deg + Uniform(rng, -0.2, 0.2)) * kRadPerDeg,
                fixture.estimator == cell::Estimator::kRigidScale ? 1 + Uniform(rng, -2e-4, 2e-4) : 1);
  std::vector<double> sensor;
  std::vector<Eigen::Vector2d> robot;
  const double accuracy = Uniform(rng, 0, 1) < 0.5 ? 0.05 : 0.002;
  for (int k = 0; k < 8; ++k) {
    sensor.push_back(Uniform(rng, -accuracy, accuracy));
    robot.emplace_back(Uniform(rng, -0.005, 0.005), Uniform(rng, -0.005, 0.005));
  }
  std::vector<Eigen::Vector2d> trips = test::SimulateTrips(fixture, truth, sensor, robot);
  c.trips = test::Present(trips);
  test::InjectTripFault(c.trips, rng, 0.05);
  if (Uniform(rng, 0, 1) < 0.5) {
    c.previous = PlanarFix(FixOrigin(truth) + Eigen::Vector2d(Uniform(rng, -1.5, 1.5), Uniform(rng, -1.5, 1.5)),
                           FixAngleRad(truth) + Uniform(rng, -0.6, 0.6) * kRadPerDeg);
  }
  // The points' region: a table over the middle of the board.
  const Eigen::Vector2d middle = ToBase(nominal, Eigen::Vector2d(95, 45));
  const OutsidePolicy policies[] = {OutsidePolicy::kError, OutsidePolicy::kClamp, OutsidePolicy::kNone};
  c.cell.regions.push_back(test::RegionOf(
      "board", test::RandomSmoothTable(rng, middle.x() - 60, middle.y() - 60, 120, 120,
                                       std::uniform_int_distribution<int>(2, 25)(rng), Uniform(rng, 0.01, 0.3)),
      Uniform(rng, -0.2, 1), policies[std::uniform_int_distribution<int>(0, 2)(rng)]));
  if (Uniform(rng, 0, 1) < 0.5) {
    const Eigen::Vector2d marker = ToBase(nominal, Eigen::Vector2d(2, 2));
    c.cell.regions.push_back(test::RegionOf(
        "marker1", test::RandomSmoothTable(rng, marker.x() - 20, marker.y() - 20, 40, 40, 6, 0.2)));
  }
  for (int i = 0; i < 12; ++i) c.points.emplace_back(Uniform(rng, 20, 170), Uniform(rng, -30, 120));
  c.cell.fixtures.push_back(fixture);
  return c;
}

TEST(FixtureCRuntime, AgreesWithCppOnRandomScansTablesAndPoints) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  std::map<std::string, int> outcomes;
  double worst_fix = 0, worst_point = 0;
  int points_compared = 0;
  for (int i = 0; i < 3000; ++i) {
    SCOPED_TRACE(fmt::format("case {}", i));
    const RandomCase c = MakeCase(rng);
    const cell::Fixture& fixture = c.cell.fixtures[0];
    ScanOptions options;
    options.estimator = fixture.estimator;
    options.regions = &c.cell.regions;
    options.previous = c.previous;
    const ScanResult cpp = ScanFixture(fixture, c.trips, options);

    const CRuntimeData data(c.cell);
    std::vector<double> xy;
    std::vector<unsigned char> tripped;
    for (const auto& trip : c.trips) {
      xy.push_back(trip ? trip->x() : 0);
      xy.push_back(trip ? trip->y() : 0);
      tripped.push_back(trip ? 1 : 0);
    }
    const smtcal_fix previous = c.previous ? CFix(*c.previous) : smtcal_fix{};
    smtcal_scan_result result;
    ASSERT_EQ(smtcal_check_fixture(&data.fixtures()[0]), SMTCAL_DATA_OK);
    const smtcal_scan_status status = smtcal_scan(&data.fixtures()[0], data.regions(), data.region_count(), xy.data(),
                                                  tripped.data(), c.previous ? &previous : nullptr, &result);
    const CheckResult* failure = cpp.FirstFailure();
    ASSERT_EQ(std::string(smtcal_scan_status_name(status)),
              failure != nullptr ? std::string(ScanCheckName(failure->check)) : "ok");
    ASSERT_EQ(result.has_fix, cpp.ok() ? 1 : 0);
    ++outcomes[smtcal_scan_status_name(status)];
    if (failure != nullptr) {
      ASSERT_EQ(result.trip, failure->trip);
    }
    for (const CheckResult& check : cpp.checks) {
      const int code = static_cast<int>(check.check);
      ASSERT_EQ(result.evaluated[code], check.evaluated ? 1 : 0) << ScanCheckName(check.check);
      if (check.evaluated) {
        ASSERT_NEAR(result.value[code], check.value, kAgreeMm) << ScanCheckName(check.check);
      }
    }
    if (cpp.estimate) {
      for (int s = 0; s < 3; ++s) {
        ASSERT_NEAR(result.s[s][0], cpp.estimate->s[static_cast<std::size_t>(s)].x(), kAgreeMm);
        ASSERT_NEAR(result.s[s][1], cpp.estimate->s[static_cast<std::size_t>(s)].y(), kAgreeMm);
      }
      for (std::size_t k = 0; k < 8; ++k) {
        ASSERT_NEAR(result.calibrated[k][0], cpp.calibrated[k].x(), kAgreeMm);
        ASSERT_NEAR(result.calibrated[k][1], cpp.calibrated[k].y(), kAgreeMm);
      }
      ASSERT_EQ(result.has_delta, cpp.delta ? 1 : 0);
      if (cpp.delta) {
        ASSERT_LT(FixDifference(result.delta, *cpp.delta), kAgreeMm);
      }
    }
    if (!cpp.ok()) continue;
    worst_fix = std::max(worst_fix, FixDifference(result.fix, *cpp.fix));
    ASSERT_LT(FixDifference(result.fix, *cpp.fix), kAgreeMm);
    // The corrected points, each from the same FIX (the C++ one) so the
    // comparison isolates the table lookup and the inverse.
    const PointCorrector corrector(c.cell.regions);
    for (const Eigen::Vector2d& point : c.points) {
      const CorrectedPoint expected = corrector.Correct(*cpp.fix, point);
      smtcal_corrected got;
      const double xy_point[2] = {point.x(), point.y()};
      const smtcal_fix fix = CFix(*cpp.fix);
      const smtcal_point_status point_status =
          smtcal_correct(&fix, data.regions(), data.region_count(), xy_point, &got);
      ASSERT_EQ(got.region, expected.region);
      ASSERT_EQ(static_cast<int>(point_status),
                expected.region < 0 ? SMTCAL_POINT_NO_REGION : static_cast<int>(expected.solution.status));
      ASSERT_NEAR(got.required[0], expected.required.x(), kAgreeMm);
      ASSERT_NEAR(got.required[1], expected.required.y(), kAgreeMm);
      ASSERT_NEAR(got.command[0], expected.command.x(), kAgreeMm);
      ASSERT_NEAR(got.command[1], expected.command.y(), kAgreeMm);
      ASSERT_EQ(got.iterations, expected.solution.iterations);
      worst_point = std::max(worst_point, (Eigen::Vector2d(got.command[0], got.command[1]) - expected.command).norm());
      ++points_compared;
      // ... and from the C runtime's own FIX.
      smtcal_corrected own;
      smtcal_correct(&result.fix, data.regions(), data.region_count(), xy_point, &own);
      ASSERT_NEAR(own.command[0], expected.command.x(), kAgreeMm);
      ASSERT_NEAR(own.command[1], expected.command.y(), kAgreeMm);
    }
  }
  std::string summary;
  for (const auto& [name, count] : outcomes) summary += fmt::format(" {} {}", name, count);
  RecordProperty("outcomes", summary);
  RecordProperty("worst_fix_mm", fmt::format("{:.3e}", worst_fix));
  RecordProperty("worst_point_mm", fmt::format("{:.3e}", worst_point));
  EXPECT_GT(outcomes["ok"], 1000) << summary;
  EXPECT_GT(points_compared, 10000);
  for (const char* fault : {"missing_trip", "trip_window", "length_l1", "line_residual", "cycle_shift"}) {
    EXPECT_GT(outcomes[fault], 0) << "no random case exercised " << fault << ":" << summary;
  }
}

TEST(FixtureCRuntime, RejectsBadArgumentsAndData) {
  cell::Cell cell;
  cell.fixtures.push_back(test::PaperFixture());
  const CRuntimeData data(cell);
  smtcal_scan_result result;
  const double trips[16] = {};
  EXPECT_EQ(smtcal_scan(nullptr, nullptr, 0, trips, nullptr, nullptr, &result), SMTCAL_SCAN_BAD_ARGUMENT);
  EXPECT_EQ(result.has_fix, 0);
  EXPECT_EQ(smtcal_scan(&data.fixtures()[0], nullptr, 0, nullptr, nullptr, nullptr, &result), SMTCAL_SCAN_BAD_ARGUMENT);
  smtcal_fixture broken = data.fixtures()[0];
  broken.trip_edge[3] = 7;
  EXPECT_EQ(smtcal_check_fixture(&broken), SMTCAL_DATA_FIXTURE);
  broken = data.fixtures()[0];
  broken.trip_count = SMTCAL_MAX_TRIPS + 1;
  EXPECT_EQ(smtcal_check_fixture(&broken), SMTCAL_DATA_FIXTURE);
  const smtcal_program program{"p", nullptr, 0, data.fixtures().data(), 1, nullptr, 0};
  EXPECT_EQ(smtcal_check_program(&program), SMTCAL_DATA_OK);
  const smtcal_point bad_point{"x", 3, 0, 0, 0, 0};
  const smtcal_program bad{"p", nullptr, 0, data.fixtures().data(), 1, &bad_point, 1};
  EXPECT_EQ(smtcal_check_program(&bad), SMTCAL_DATA_POINT);
  smtcal_corrected out;
  EXPECT_EQ(smtcal_program_point(&program, nullptr, 0, &out), SMTCAL_POINT_BAD_ARGUMENT);
}

// --- the emitted C, compiled with cc ------------------------------------------

struct Command {
  int exit_code = -1;
  std::string out;
};

Command RunShell(const std::string& command, const fs::path& dir) {
  const std::string full = fmt::format("cd '{}' && {} >out.txt 2>&1", dir.string(), command);
  const int status = std::system(full.c_str());
  std::ifstream in(dir / "out.txt");
  std::stringstream text;
  text << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text.str()};
}

bool HaveCc() { return std::system("command -v cc >/dev/null 2>&1") == 0; }

fs::path ScratchDir(std::string_view name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_{}_{}", name, ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

const std::string kStrictC = "cc -std=c99 -Wall -Wextra -Werror -pedantic";

TEST(FixtureCRuntime, EmittedDataCompilesWithTheRuntimeAndAgrees) {
  if (!HaveCc()) GTEST_SKIP() << "no C compiler (cc) on PATH";
  std::mt19937_64 rng(test::FixtureSeed());
  cell::Cell cell;
  cell.name = "paper-cell";
  cell.fixtures.push_back(test::PaperFixture(cell::Estimator::kRigid));
  cell.fixtures.push_back(test::PaperFixture(cell::Estimator::kPaper));
  cell.fixtures[1].name = "Tray \"B\"?\?/";  // a name that needs escaping
  cell.fixtures[1].origin_mm = {20, 200};
  cell.regions.push_back(test::RegionOf("layer1", test::RandomSmoothTable(rng, 150, 60, 50, 50, 11, 0.15)));
  cell.regions.push_back(test::RegionOf("layer2", test::RandomSmoothTable(rng, 205, 60, 50, 50, 6, 0.1), 0.5,
                                        OutsidePolicy::kClamp));
  std::vector<CRuntimePoint> points;
  for (int i = 0; i < 40; ++i) {
    points.push_back(CRuntimePoint{fmt::format("C{}", i), i % 5 == 4 ? "tray \"b\"?\?/" : "Board",
                                   Eigen::Vector2d(Uniform(rng, 10, 125), Uniform(rng, 20, 70)), -3, 90,
                                   SourceLoc{1, static_cast<std::uint32_t>(10 + i), 3}});
  }
  points.push_back(CRuntimePoint{"Feed", "", Eigen::Vector2d(160, 70), -12, 0, SourceLoc{}});
  const std::string source = EmitCRuntimeData(cell, points, "Layer A");
  EXPECT_EQ(source, EmitCRuntimeData(cell, points, "Layer A")) << "deterministic";
  EXPECT_NE(source.find("const smtcal_program smtcal_program_Layer_A"), std::string::npos);

  // The board this cycle and its scan.
  const Eigen::Affine3d truth = PlanarFix(Eigen::Vector2d(138.21, 39.87), 0.07 * kRadPerDeg);
  const std::vector<Eigen::Vector2d> trips = test::SimulateTrips(cell.fixtures[0], truth);
  std::string trip_list;
  for (const Eigen::Vector2d& t : trips) trip_list += fmt::format("{}, {}, ", t.x(), t.y());
  const fs::path dir = ScratchDir("c_runtime");
  std::ofstream(dir / "data.c") << source;
  std::ofstream(dir / "main.c") << fmt::format(R"(#include <stdio.h>
#include "smtcal_runtime.h"
extern const smtcal_program smtcal_program_Layer_A;
int main(void) {{
  const smtcal_program *program = &smtcal_program_Layer_A;
  const double trips[16] = {{{}}};
  smtcal_scan_result scan;
  smtcal_corrected out;
  int i;
  if (smtcal_check_program(program) != SMTCAL_DATA_OK) return 2;
  if (smtcal_scan(&program->fixtures[0], program->regions, program->region_count, trips, NULL, NULL, &scan) !=
      SMTCAL_SCAN_OK) return 3;
  printf("fix %.17g %.17g %.17g %.17g %.17g %.17g\n", scan.fix.n[0], scan.fix.n[1], scan.fix.o[0], scan.fix.o[1],
         scan.fix.p[0], scan.fix.p[1]);
  for (i = 0; i < program->point_count; ++i) {{
    if (program->points[i].fixture > 0) continue;
    smtcal_program_point(program, &scan.fix, i, &out);
    printf("%s %d %s %.17g %.17g %.17g %.17g\n", program->points[i].name, out.region,
           smtcal_point_status_name(out.status), out.command[0], out.command[1], out.z, out.u_deg);
  }}
  printf("%s\n", program->fixtures[1].name);
  return 0;
}}
)",
                                               trip_list);
  const std::string runtime = fs::path(SMTCAL_SOURCE_DIR) / "runtime" / "c";
  const Command built = RunShell(
      fmt::format("{} -I'{}' '{}/smtcal_runtime.c' data.c main.c -lm -o program", kStrictC, runtime, runtime), dir);
  ASSERT_EQ(built.exit_code, 0) << built.out;
  const Command ran = RunShell("./program", dir);
  ASSERT_EQ(ran.exit_code, 0) << ran.out;

  // The same cycle in C++.
  ScanOptions options;
  options.estimator = cell.fixtures[0].estimator;
  options.regions = &cell.regions;
  const ScanResult scan = ScanFixture(cell.fixtures[0], test::Present(trips), options);
  ASSERT_TRUE(scan.ok());
  const PointCorrector corrector(cell.regions);
  std::istringstream lines(ran.out);
  std::string word;
  double n0, n1, o0, o1, p0, p1;
  lines >> word >> n0 >> n1 >> o0 >> o1 >> p0 >> p1;
  ASSERT_EQ(word, "fix");
  EXPECT_NEAR(p0, scan.fix->translation().x(), kAgreeMm);
  EXPECT_NEAR(p1, scan.fix->translation().y(), kAgreeMm);
  EXPECT_NEAR(n0, scan.fix->linear()(0, 0), 1e-12);
  EXPECT_NEAR(o0, scan.fix->linear()(0, 1), 1e-12);
  int compared = 0;
  for (const CRuntimePoint& point : points) {
    if (point.fixture.rfind("tray", 0) == 0) continue;
    std::string name, status;
    int region;
    double x, y, z, u;
    lines >> name >> region >> status >> x >> y >> z >> u;
    ASSERT_EQ(name, point.name);
    const CorrectedPoint expected =
        point.fixture.empty() ? corrector.Invert(point.fix_mm) : corrector.Correct(*scan.fix, point.fix_mm);
    EXPECT_EQ(region, expected.region) << name;
    EXPECT_NEAR(x, expected.command.x(), kAgreeMm) << name;
    EXPECT_NEAR(y, expected.command.y(), kAgreeMm) << name;
    EXPECT_EQ(z, point.z_mm);
    EXPECT_NEAR(u, point.u_deg + (point.fixture.empty() ? 0 : FixAngleRad(*scan.fix) * kDegPerRad), 1e-9);
    ++compared;
  }
  EXPECT_EQ(compared, 33);
  std::string rest;
  std::getline(lines >> std::ws, rest);
  EXPECT_EQ(rest, "Tray \"B\"?\?/") << "the escaped name reads back";
  fs::remove_all(dir);
}

// The object file shows what the runtime links against and what it stores.
TEST(FixtureCRuntime, ObjectHasNoHeapNoWritableGlobalsAndOnlySqrtAtan2FromLibm) {
  if (!HaveCc() || std::system("command -v nm >/dev/null 2>&1") != 0) GTEST_SKIP() << "needs cc and nm";
  const fs::path dir = ScratchDir("c_runtime_nm");
  const std::string runtime = fs::path(SMTCAL_SOURCE_DIR) / "runtime" / "c";
  // Compiler-generated block copies (memset/memcpy) are fine; nothing else
  // may be undefined.
  const std::set<std::string> allowed = {"sqrt", "atan2", "memset", "memcpy", "memmove"};
  for (const char* level : {"-O0", "-O2", "-O3"}) {
    SCOPED_TRACE(level);
    const Command built =
        RunShell(fmt::format("{} {} -c '{}/smtcal_runtime.c' -o runtime.o", kStrictC, level, runtime), dir);
    ASSERT_EQ(built.exit_code, 0) << built.out;
    const Command symbols = RunShell("nm -P runtime.o", dir);
    ASSERT_EQ(symbols.exit_code, 0) << symbols.out;
    const int defined_functions = test::ExpectOnlyAllowedCallsAndNoWritableGlobals(symbols.out, allowed, "the runtime");
    EXPECT_GE(defined_functions, 10);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace smtcal
