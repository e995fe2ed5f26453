// Every JSON output writes its numbers rounded to what they mean, never a
// double's noise (179.98430000000002): diff --json, simulate --json, verify
// --json, compile --report, table stats --json, cell check --json, fixture
// --json, each on the shipped example or a golden input. The finest
// resolution any of them documents is 1e-12 mm (compile's residuals); noise
// shows as 14 to 17 decimals. The 4 x 4 matrices of `fixture` keep every bit
// (--previous reads them back) and are not judged. That the text spells each
// number in its shortest form is JsonText's test (tests/unit/base).
#include <unistd.h>

#include <charconv>
#include <filesystem>
#include <functional>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/unit/json_walk.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = SMTCAL_SOURCE_DIR;
const fs::path kExample = kSource / "examples" / "paper-cell";
constexpr int kMaxDecimals = 12;

// The decimals of a number's shortest exact form ("2.9e-05" has 6), as
// smtcal writes it (base/json_text.h).
int Decimals(double value) {
  char buffer[64];
  const std::to_chars_result written =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::scientific);
  const std::string text(buffer, written.ptr);
  const std::size_t e = text.find('e');
  const std::size_t dot = text.find('.');
  const int digits = dot == std::string::npos || dot > e ? 0 : static_cast<int>(e - dot - 1);
  return std::max(digits - std::stoi(text.substr(e + 1)), 0);
}

void ExpectRounded(const std::string& what, const std::string& text) {
  SCOPED_TRACE(what);
  ASSERT_TRUE(nlohmann::json::accept(text)) << text;
  int numbers = 0;
  test::ForEachNumber(nlohmann::json::parse(text), "", [&](const std::string& key, const nlohmann::json& number) {
    if (key == "matrix") return;
    ++numbers;
    EXPECT_LE(Decimals(number.get<double>()), kMaxDecimals) << key << ": " << number.get<double>();
  });
  EXPECT_GT(numbers, 0) << "no numbers checked";
}

std::string Out(const std::string& args, const fs::path& dir = kExample) {
  test::SmtcalRun run = test::RunSmtcal(args, dir);
  EXPECT_LE(run.exit_code, 1) << run.command << "\n" << run.err;
  return run.out;
}

TEST(JsonNumbers, EveryJsonOutputIsRoundedToItsMeaning) {
  ExpectRounded("simulate --json", Out("simulate layers.place --cell paper.cell.toml --cycles 5 --json"));
  ExpectRounded("verify --json", Out("verify layers.place --cell paper.cell.toml --json"));
  ExpectRounded("table stats --json", Out("table stats --json placing-table.csv"));
  ExpectRounded("cell check --json", Out("cell check --json paper.cell.toml"));

  const fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_json_numbers_{}", ::getpid());
  fs::create_directories(dir);
  Out(fmt::format("compile layers.place --cell paper.cell.toml -o '{}' --report '{}'", (dir / "out.place").string(),
                  (dir / "report.json").string()));
  ExpectRounded("compile --report", test::ReadFileText(dir / "report.json"));
  fs::remove_all(dir);

  const fs::path diff = kSource / "tests" / "golden" / "diff";
  ExpectRounded("diff --json", Out("diff --json --exit-zero json.place new/json.place", diff));
  ExpectRounded("diff --json --cell",
                Out("diff --json --exit-zero --cell ../../../examples/paper-cell/paper.cell.toml frame_to_base.place "
                    "new/frame_to_base.place",
                    diff));

  const fs::path fixture = kSource / "tests" / "golden" / "fixture";
  ExpectRounded("fixture --json", Out("fixture --cell data/board.cell.toml --fixture Board --trips scan_json.csv "
                                      "--previous data/previous.json --json",
                                      fixture));
}

}  // namespace
}  // namespace smtcal
