// The cycle record (docs/monitor.md) written and read back: the C runtime's
// smtcal_record_format (directly, and through smtcal's C++ records) read by
// frontend/record_log exactly, on thousands of random scans, failed ones
// included; the formatter's object file keeps the runtime's promises.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "backend/c/c_data.h"
#include "backend/c/record_text.h"
#include "calibration/cycle_record.h"
#include "calibration/fixture_estimation.h"
#include "frontend/record_log.h"
#include "runtime/c/smtcal_record.h"
#include "tests/unit/backend/c_object_symbols.h"
#include "tests/unit/calibration/fixture_test_cell.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;
using test::Uniform;

// A random scan of the paper board (sometimes a missing or moved trip) and
// what the C++ scan makes of it.
struct Case {
  cell::Cell cell;
  std::vector<std::optional<Eigen::Vector2d>> trips;
  std::optional<Eigen::Affine3d> previous;
};

Case MakeCase(std::mt19937_64& rng) {
  Case c;
  const cell::Estimator estimators[] = {cell::Estimator::kPaper, cell::Estimator::kRigid, cell::Estimator::kRigidScale};
  cell::Fixture fixture = test::PaperFixture(estimators[std::uniform_int_distribution<int>(0, 2)(rng)]);
  const Eigen::Affine3d truth = PlanarFix(fixture.origin_mm + Eigen::Vector2d(Uniform(rng, -0.5, 0.5), Uniform(rng, -0.5, 0.5)),
                                          Uniform(rng, -0.2, 0.2) * kRadPerDeg);
  std::vector<double> sensor;
  std::vector<Eigen::Vector2d> robot;
  for (int k = 0; k < 8; ++k) {
    sensor.push_back(Uniform(rng, -0.05, 0.05));
    robot.emplace_back(Uniform(rng, -0.005, 0.005), Uniform(rng, -0.005, 0.005));
  }
  c.trips = test::Present(test::SimulateTrips(fixture, truth, sensor, robot));
  test::InjectTripFault(c.trips, rng, 0.1);
  // A previous scan half the time; one in five of those farther than
  // max_shift_mm (2 mm) from this one, so cycle_shift refuses some scans.
  if (Uniform(rng, 0, 1) < 0.5) {
    const Eigen::Vector2d moved = Uniform(rng, 0, 1) < 0.2 ? Eigen::Vector2d(2.5, 0) : Eigen::Vector2d(0.1, -0.2);
    c.previous = PlanarFix(FixOrigin(truth) + moved, FixAngleRad(truth));
  }
  c.cell.name = "paper cell";  // a name the record writes as paper_cell
  c.cell.fixtures.push_back(fixture);
  return c;
}

RecordLog Read(const std::string& text, SourceManager& sources, Diagnostics& diags) {
  RecordLog log;
  ReadRecordLog(sources.Add("records.log", text), log, diags);
  return log;
}

// Bitwise: the text holds the 17 significant digits that read back.
void ExpectSame(const CycleRecord& got, const CycleRecord& want) {
  EXPECT_EQ(got.fixture, want.fixture);
  EXPECT_EQ(got.cycle, want.cycle);
  EXPECT_EQ(got.time_s, want.time_s);
  EXPECT_EQ(got.status, want.status);
  EXPECT_EQ(got.trip, want.trip);
  ASSERT_EQ(got.trips.size(), want.trips.size());
  for (std::size_t k = 0; k < want.trips.size(); ++k) {
    ASSERT_EQ(got.trips[k].has_value(), want.trips[k].has_value()) << "T" << k + 1;
    if (want.trips[k]) {
      EXPECT_EQ(got.trips[k]->x(), want.trips[k]->x());
      EXPECT_EQ(got.trips[k]->y(), want.trips[k]->y());
    }
  }
  for (std::size_t c = 0; c < want.checks.size(); ++c) EXPECT_EQ(got.checks[c], want.checks[c]) << "check " << c + 1;
  ASSERT_EQ(got.estimate.has_value(), want.estimate.has_value());
  if (want.estimate) {
    for (std::size_t s = 0; s < 3; ++s) EXPECT_EQ((*got.estimate)[s], (*want.estimate)[s]);
  }
}

TEST(CycleRecord, ReadsBackExactlyWhatTheCRuntimeWrites) {
  const std::uint64_t seed = test::FixtureSeed();
  SCOPED_TRACE(fmt::format("seed {} (SMTCAL_TEST_SEED)", seed));
  std::mt19937_64 rng(seed);
  std::set<int> statuses;
  for (int i = 0; i < 1000; ++i) {
    SCOPED_TRACE(fmt::format("case {}", i));
    const Case c = MakeCase(rng);
    const cell::Fixture& fixture = c.cell.fixtures[0];
    ScanOptions options;
    options.estimator = fixture.estimator;
    options.previous = c.previous;
    const ScanResult scan = ScanFixture(fixture, c.trips, options);
    const std::optional<double> time = i % 3 == 0 ? std::nullopt : std::optional<double>(Uniform(rng, 0, 1e5));
    const CycleRecord want = RecordOfScan(0, i + 1, time, scan);
    statuses.insert(want.status);

    RecordBegin begin;
    begin.cell = c.cell.name;
    begin.fixtures = {{fixture.name, 8}};
    begin.clock = time ? "smtcal-clock.out" : "none";
    begin.segment = i;
    const std::string text = RecordBeginText(begin) + CycleRecordText(want, -1);
    SourceManager sources;
    Diagnostics diags(sources);
    const RecordLog log = Read(text, sources, diags);
    ASSERT_FALSE(diags.has_errors()) << diags.RenderText() << text;
    ASSERT_EQ(diags.warning_count(), 0u) << diags.RenderText();
    ASSERT_EQ(log.begins.size(), 1u);
    EXPECT_EQ(log.begins[0].begin.cell, "paper_cell");
    EXPECT_EQ(log.begins[0].begin.clock, begin.clock);
    EXPECT_EQ(log.begins[0].begin.segment, i);
    ASSERT_EQ(log.cycles.size(), 1u) << text;
    ExpectSame(log.cycles[0].record, want);

    // The C runtime itself, from the same trips: the same text.
    const CRuntimeData data(c.cell);
    std::vector<double> xy;
    std::vector<unsigned char> tripped;
    for (const auto& trip : c.trips) {
      xy.push_back(trip ? trip->x() : 0);
      xy.push_back(trip ? trip->y() : 0);
      tripped.push_back(trip ? 1 : 0);
    }
    smtcal_fix previous{};
    if (c.previous) {
      previous = {{c.previous->linear()(0, 0), c.previous->linear()(1, 0)},
                  {c.previous->linear()(0, 1), c.previous->linear()(1, 1)},
                  {c.previous->translation().x(), c.previous->translation().y()}};
    }
    smtcal_scan_result result;
    smtcal_scan(&data.fixtures()[0], nullptr, 0, xy.data(), tripped.data(), c.previous ? &previous : nullptr, &result);
    smtcal_record record;
    const double time_value = time.value_or(0);
    ASSERT_EQ(smtcal_record_scan(&data.fixtures()[0], 0, i + 1, time ? &time_value : nullptr, xy.data(),
                                 tripped.data(), &result, &record),
              result.status);
    char buffer[SMTCAL_RECORD_TEXT_SIZE];
    const int length = smtcal_record_format(&record, -1, buffer, sizeof buffer);
    ASSERT_GT(length, 0);
    ASSERT_LT(length, static_cast<int>(sizeof buffer));
    SourceManager c_sources;
    Diagnostics c_diags(c_sources);
    const RecordLog c_log = Read(RecordBeginText(begin) + buffer, c_sources, c_diags);
    ASSERT_FALSE(c_diags.has_errors()) << c_diags.RenderText() << buffer;
    ASSERT_EQ(c_log.cycles.size(), 1u);
    const CycleRecord& got = c_log.cycles[0].record;
    EXPECT_EQ(got.status, want.status);
    EXPECT_EQ(got.trip, want.trip);
    for (std::size_t k = 0; k < 8; ++k) {
      ASSERT_EQ(got.trips[k].has_value(), want.trips[k].has_value());
      if (want.trips[k]) {
        EXPECT_EQ(*got.trips[k], *want.trips[k]) << "the trips as given";
      }
    }
    for (std::size_t k = 0; k < 11; ++k) {
      ASSERT_EQ(got.checks[k].has_value(), want.checks[k].has_value());
      if (want.checks[k]) {
        EXPECT_NEAR(*got.checks[k], *want.checks[k], 1e-9);
      }
    }
  }
  for (int status : {0, 1, 2, 4, 7, 10}) {
    EXPECT_TRUE(statuses.count(status)) << "no random case gave status " << status;
  }
}

TEST(CycleRecord, SixDecimalsReadBackAsTheirDigits) {
  std::mt19937_64 rng(test::FixtureSeed());
  const Case c = MakeCase(rng);
  ScanOptions options;
  options.estimator = cell::Estimator::kRigid;
  const ScanResult scan = ScanFixture(c.cell.fixtures[0], c.trips, options);
  const CycleRecord want = RecordOfScan(0, 7, 1234.5, scan);
  RecordBegin begin;
  begin.cell = "paper-cell";
  begin.fixtures = {{"Board", 8}};
  const std::string text = RecordBeginText(begin) + CycleRecordText(want, 6);
  SourceManager sources;
  Diagnostics diags(sources);
  const RecordLog log = Read(text, sources, diags);
  ASSERT_FALSE(diags.has_errors()) << diags.RenderText();
  ASSERT_EQ(log.cycles.size(), 1u);
  const CycleRecord& got = log.cycles[0].record;
  for (std::size_t k = 0; k < 8; ++k) {
    if (!want.trips[k]) continue;
    EXPECT_EQ(got.trips[k]->x(), std::stod(fmt::format("{:.6f}", want.trips[k]->x())));
    EXPECT_NEAR(got.trips[k]->y(), want.trips[k]->y(), 5e-7);
  }
  EXPECT_EQ(got.time_s, 1234.5);
}

TEST(CycleRecord, FormatterRefusesBadArgumentsAndMeasuresLikeSnprintf) {
  smtcal_record record{};
  record.trip_count = 8;
  char small[16];
  EXPECT_EQ(smtcal_record_format(nullptr, -1, small, sizeof small), -1);
  EXPECT_EQ(smtcal_record_format(&record, 18, small, sizeof small), -1);
  EXPECT_EQ(smtcal_record_format(&record, -1, nullptr, 4), -1);
  const int length = smtcal_record_format(&record, 6, nullptr, 0);
  ASSERT_GT(length, 16);
  EXPECT_EQ(smtcal_record_format(&record, 6, small, sizeof small), length) << "the whole length, like snprintf";
  EXPECT_EQ(std::string(small).size(), sizeof small - 1) << "cut and terminated";
  record.trip_count = 0;
  EXPECT_EQ(smtcal_record_format(&record, 6, small, sizeof small), -1);
}

// --- the formatter's object file ----------------------------------------------

struct Command {
  int exit_code = -1;
  std::string out;
};

Command RunShell(const std::string& command, const fs::path& dir) {
  const int status = std::system(fmt::format("cd '{}' && {} >out.txt 2>&1", dir.string(), command).c_str());
  std::ifstream in(dir / "out.txt");
  std::stringstream text;
  text << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text.str()};
}

TEST(CycleRecord, ObjectIsStrictC99WithNoHeapAndNoWritableGlobals) {
  if (std::system("command -v cc >/dev/null 2>&1 && command -v nm >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "needs cc and nm";
  }
  const fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_record_nm_{}", ::getpid());
  fs::create_directories(dir);
  const std::string runtime = fs::path(SMTCAL_SOURCE_DIR) / "runtime" / "c";
  // Text comes from vsnprintf; compiler-generated block copies are fine.
  const std::set<std::string> allowed = {"vsnprintf", "memset", "memcpy", "memmove", "__stack_chk_fail"};
  for (const char* level : {"-O0", "-O2"}) {
    SCOPED_TRACE(level);
    const Command built = RunShell(
        fmt::format("cc -std=c99 -Wall -Wextra -Werror -pedantic {} -c '{}/smtcal_record.c' -o record.o", level, runtime),
        dir);
    ASSERT_EQ(built.exit_code, 0) << built.out;
    const Command symbols = RunShell("nm -P record.o", dir);
    ASSERT_EQ(symbols.exit_code, 0) << symbols.out;
    test::ExpectOnlyAllowedCallsAndNoWritableGlobals(symbols.out, allowed, "the record");
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace smtcal
