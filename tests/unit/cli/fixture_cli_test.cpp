// `smtcal fixture` as a user runs it: one run's --json is the next run's
// --previous, an unknown fixture is a usage error, and the output is
// byte-identical from run to run. (Every fault and diagnostic has a golden
// case in tests/golden/fixture/.)
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

const fs::path kSuite = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "fixture";

std::string Args(const std::string& trips, const std::string& extra = "") {
  return "fixture --cell data/board.cell.toml --fixture board --trips " + trips + " " + extra;
}

TEST(FixtureCli, JsonOfOneScanIsThePreviousOfTheNext) {
  const test::SmtcalRun first = test::RunSmtcal(Args("scan.csv", "--json"), kSuite);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const fs::path previous = fs::temp_directory_path() / ("smtcal_fixture_previous_" + std::to_string(::getpid()));
  std::ofstream(previous) << first.out;
  const test::SmtcalRun second =
      test::RunSmtcal(Args("scan_no_z_any_order.csv", "--json --previous '" + previous.string() + "'"), kSuite);
  fs::remove(previous);
  ASSERT_EQ(second.exit_code, 0) << second.err;
  const nlohmann::json json = nlohmann::json::parse(second.out);
  ASSERT_FALSE(json["delta"].is_null());
  EXPECT_TRUE(json["ok"].get<bool>());
  for (const auto& check : json["checks"]) EXPECT_TRUE(check["evaluated"].get<bool>()) << check["name"];
  // The same board twice: the delta is (almost) the identity.
  EXPECT_LT(json["delta"]["shift_mm"].get<double>(), 1e-3);
  EXPECT_EQ(json["delta"]["matrix"][2][2].get<double>(), 1.0);
}

TEST(FixtureCli, OutputIsDeterministic) {
  const test::SmtcalRun a = test::RunSmtcal(Args("scan.csv", "--json"), kSuite);
  const test::SmtcalRun b = test::RunSmtcal(Args("scan.csv", "--json"), kSuite);
  EXPECT_EQ(a.out, b.out);
  EXPECT_EQ(a.exit_code, 0);
}

TEST(FixtureCli, UnknownFixtureIsAUsageError) {
  const test::SmtcalRun run =
      test::RunSmtcal("fixture --cell data/board.cell.toml --fixture Tray --trips scan.csv", kSuite);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("has no fixture 'Tray'; its fixtures: Board"), std::string::npos) << run.err;
}

TEST(FixtureCli, MissingFilesAreIoErrors) {
  EXPECT_EQ(test::RunSmtcal(Args("no-such-trips.csv"), kSuite).exit_code, 3);
  EXPECT_EQ(test::RunSmtcal(Args("scan.csv", "--previous no-such.json"), kSuite).exit_code, 3);
}

TEST(FixtureCli, TripsFromStdin) {
  const std::string trips = test::ReadFileText(kSuite / "scan.csv");
  const test::SmtcalRun run = test::RunSmtcal(Args("-"), kSuite, trips);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("result: ok"), std::string::npos);
}

}  // namespace
}  // namespace smtcal
