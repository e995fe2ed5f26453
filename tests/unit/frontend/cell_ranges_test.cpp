// Every number of a cell file goes through the one check of
// base/number_range.h with a documented range: for every numeric value of
// the shipped example cell (every key the cell format has, nearly), NaN, an
// overflow and a value far out of range are refused at the value, naming the
// key, and the range the message gives is the one docs/cell.md states for
// that key. A key added with its range (frontend/cell_toml.cpp, one line:
// NumberIn(keys, "key", limits::kRange)) is covered once the example has it.
// Also: the reach x correlation grid of simulate's true field is bounded.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include "calibration/limits.h"
#include "calibration/truth_spec.h"
#include "frontend/cell_toml.h"
#include "frontend/truth_toml.h"
#include "tests/unit/test_support.h"

namespace fs = std::filesystem;

namespace smtcal {
namespace {

const fs::path kExample = fs::path(SMTCAL_SOURCE_DIR) / "examples" / "paper-cell";

// A number of the example cell: where it is written and under which key.
struct NumberAt {
  std::string key;   // the nearest key: "x_mm" for an interval's bound, "pick" for a point's coordinate
  std::string path;  // for failure messages: robot.x_mm[1]
  bool integer = false;
  toml::source_region where;
};

void Collect(const toml::node& node, const std::string& key, const std::string& path, std::vector<NumberAt>& out) {
  if (const toml::table* table = node.as_table()) {
    for (auto&& [k, child] : *table) Collect(child, std::string(k.str()), path + "." + std::string(k.str()), out);
  } else if (const toml::array* array = node.as_array()) {
    for (std::size_t i = 0; i < array->size(); ++i) Collect(*array->get(i), key, fmt::format("{}[{}]", path, i), out);
  } else if (node.is_number()) {
    out.push_back({key, path, node.is_integer(), node.source()});
  }
}

// A scratch folder with the example's tables, for variants of its cell file.
class CellRanges : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("smtcal_cell_ranges_{}", ::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (const fs::directory_entry& entry : fs::directory_iterator(kExample)) {
      if (entry.path().extension() == ".csv") fs::create_symlink(entry.path(), dir_ / entry.path().filename());
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  struct Loaded {
    bool ok = false;
    std::vector<Diagnostic> errors;
  };
  Loaded Load(const std::string& text) {
    const fs::path path = dir_ / "variant.cell.toml";
    std::ofstream(path, std::ios::binary) << text;
    SourceManager sources;
    Diagnostics diags(sources);
    Result<std::optional<cell::Cell>> loaded = cell::LoadCell(path.string(), sources, diags);
    Loaded result;
    result.ok = loaded && loaded.value().has_value();
    for (const Diagnostic& d : diags.all()) {
      if (d.severity == Severity::Error) result.errors.push_back(d);
    }
    return result;
  }

  fs::path dir_;
};

// The line of `text` (1-based) with its bytes from column `begin` to `end`
// (toml++'s 1-based columns; the example is ASCII) replaced.
std::string Replaced(const std::string& text, const toml::source_region& where, const std::string& with) {
  std::size_t line_start = 0;
  for (std::uint32_t line = 1; line < where.begin.line; ++line) line_start = text.find('\n', line_start) + 1;
  const std::size_t from = line_start + where.begin.column - 1;
  const std::size_t to = line_start + where.end.column - 1;
  return text.substr(0, from) + with + text.substr(to);
}

// The rows of docs/cell.md that name `key` in their first cell.
std::vector<std::string> DocRows(const std::string& doc, const std::string& key) {
  std::vector<std::string> rows;
  std::size_t start = 0;
  while (start < doc.size()) {
    std::size_t end = doc.find('\n', start);
    if (end == std::string::npos) end = doc.size();
    const std::string line = doc.substr(start, end - start);
    const std::size_t second_bar = line.find('|', 1);
    if (line.starts_with("| ") && second_bar != std::string::npos &&
        line.substr(0, second_bar).find("`" + key + "`") != std::string::npos) {
      rows.push_back(line);
    }
    start = end + 1;
  }
  return rows;
}

TEST_F(CellRanges, EveryNumberOfTheExampleIsCheckedAgainstTheRangeItsDocsState) {
  const std::string text = test::ReadFileText(kExample / "paper.cell.toml");
  const std::string doc = test::ReadFileText(fs::path(SMTCAL_SOURCE_DIR) / "docs" / "cell.md");
  // Positions and angles are stated once, in the conventions.
  const std::string conventions = doc.substr(0, doc.find("## Top level"));
  ASSERT_TRUE(Load(text).ok) << "the example loads";
  std::vector<NumberAt> numbers;
  Collect(toml::parse(text), "", "", numbers);
  ASSERT_GT(numbers.size(), 100u);
  for (const NumberAt& number : numbers) {
    // The slice replaced is the number as written.
    const std::string original = Replaced(text, number.where, "\x01");
    ASSERT_NE(original, text);
    for (const std::string& bad : {std::string("nan"), std::string("-inf"), std::string(number.integer ? "99999999999" : "1e308")}) {
      Loaded loaded = Load(Replaced(text, number.where, bad));
      ASSERT_FALSE(loaded.ok) << number.path << " = " << bad << " was accepted";
      bool at_value = false;
      for (const Diagnostic& d : loaded.errors) at_value = at_value || d.range.begin.line == number.where.begin.line;
      ASSERT_TRUE(at_value) << number.path << " = " << bad << ": no error on its line";
      const Diagnostic& first = loaded.errors.front();
      EXPECT_NE(first.message.find(number.key), std::string::npos) << number.path << ": " << first.message;
      if (first.kind != DiagKind::CellValueOutOfRange) continue;  // a float for a whole number: wrong type
      const std::size_t must = first.message.find("it must be ");
      ASSERT_NE(must, std::string::npos) << first.message;
      std::string range = first.message.substr(must + 11);
      if (range.ends_with(")")) range = range.substr(0, range.rfind(" ("));  // what a whole number counts
      bool documented = conventions.find(range) != std::string::npos;
      for (const std::string& row : DocRows(doc, number.key)) documented = documented || row.find(range) != std::string::npos;
      EXPECT_TRUE(documented) << number.path << ": docs/cell.md does not state \"" << range << "\" for `"
                              << number.key << "`";
    }
  }
}

// The two cells that made simulate run for hours, and the reach x
// correlation combination that passes each range but not their product.
TEST_F(CellRanges, NoCellThatLoadsMakesSimulatesTrueFieldExplode) {
  const std::string text = test::ReadFileText(kExample / "paper.cell.toml");
  auto replaced = [](std::string changed, const std::string& from, const std::string& to) {
    const std::size_t at = changed.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? changed : changed.replace(at, from.size(), to);
  };
  auto with = [&](const std::string& from, const std::string& to) { return replaced(text, from, to); };
  Loaded far = Load(with("x_mm = [0, 400]", "x_mm = [-1e17, 400]"));
  ASSERT_FALSE(far.ok);
  EXPECT_EQ(far.errors.front().kind, DiagKind::CellValueOutOfRange) << far.errors.front().message;
  Loaded fine = Load(with("uncalibrated_correlation_mm = 25", "uncalibrated_correlation_mm = 1e-300"));
  ASSERT_FALSE(fine.ok);
  EXPECT_EQ(fine.errors.front().kind, DiagKind::CellValueOutOfRange) << fine.errors.front().message;
  Loaded grid = Load(with("uncalibrated_correlation_mm = 25", "uncalibrated_correlation_mm = 0.5"));
  ASSERT_FALSE(grid.ok);
  EXPECT_EQ(grid.errors.front().kind, DiagKind::CellTrueFieldTooFine) << grid.errors.front().message;
  // The smallest correlation the message offers fits, and just below it does not.
  cell::Robot robot;
  robot.limits[0] = {0, 400};
  robot.limits[1] = {0, 300};
  const double least = MinTrueFieldCorrelationMm(robot);
  EXPECT_LE(TrueFieldSamples(robot, least), limits::kMaxTrueFieldSamples);
  EXPECT_GT(TrueFieldSamples(robot, least * 0.99), limits::kMaxTrueFieldSamples);
  EXPECT_TRUE(Load(with("uncalibrated_correlation_mm = 25", fmt::format("uncalibrated_correlation_mm = {}", least))).ok);
  // The default correlation (25 mm) on a reach of +-100 m.
  Loaded wide = Load(replaced(with("x_mm = [0, 400]\ny_mm = [0, 300]", "x_mm = [-100000, 100000]\ny_mm = [-100000, 100000]"),
                              "uncalibrated_correlation_mm = 25", "# the default"));
  ASSERT_FALSE(wide.ok);
  bool too_fine = false;
  for (const Diagnostic& d : wide.errors) too_fine = too_fine || d.kind == DiagKind::CellTrueFieldTooFine;
  EXPECT_TRUE(too_fine);
}

}  // namespace
}  // namespace smtcal
