// The base layer's defences against hostile input and environments: staged
// outputs that are all-or-nothing, byte offsets to line and column, JSON
// that never throws on bad bytes or out-of-range numbers, the window on a
// long quoted line and the cap on warnings.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "base/diagnostics.h"
#include "base/field_text.h"
#include "base/json_text.h"
#include "base/source.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

TEST(StagedOutput, NothingReplacesTheFileUntilCommitAndADroppedStageLeavesNothing) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_staged_{}", ::getpid());
  fs::create_directories(dir);
  const std::string path = (dir / "out.txt").string();
  std::ofstream(path) << "old";
  {
    Result<StagedOutput> staged = StagedOutput::Stage(path, "new");
    ASSERT_TRUE(staged.ok()) << staged.error().message;
    EXPECT_EQ(test::ReadFileText(path), "old");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);  // and the temporary
  }
  EXPECT_EQ(test::ReadFileText(path), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  Result<StagedOutput> staged = StagedOutput::Stage(path, "new");
  ASSERT_TRUE(staged.ok());
  ASSERT_TRUE(staged.value().Commit().ok());
  EXPECT_EQ(test::ReadFileText(path), "new");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(SourceFile, LocationOfAByteOffset) {
  SourceManager sources;
  std::uint32_t id = sources.Add("f", "ab\ncde\n\nf");
  const SourceFile& file = sources.File(id);
  EXPECT_EQ(file.LocationOf(id, 0), (SourceLoc{id, 1, 1}));
  EXPECT_EQ(file.LocationOf(id, 2), (SourceLoc{id, 1, 3}));  // the newline
  EXPECT_EQ(file.LocationOf(id, 3), (SourceLoc{id, 2, 1}));
  EXPECT_EQ(file.LocationOf(id, 7), (SourceLoc{id, 3, 1}));
  EXPECT_EQ(file.LocationOf(id, 8), (SourceLoc{id, 4, 1}));
  EXPECT_EQ(file.LocationOf(id, 99), (SourceLoc{id, 4, 1}));  // past the end: the last byte
}

TEST(Json, ParseErrorsAndNumbersBeyondDoubleHaveAPlace) {
  JsonParse good = ParseJson("{\"a\": [1, 2.5]}");
  ASSERT_TRUE(good.value.has_value());
  EXPECT_EQ((*good.value)["a"][1].get<double>(), 2.5);

  JsonParse huge = ParseJson("{\n  \"a\": 1e400\n}");
  ASSERT_FALSE(huge.value.has_value());
  EXPECT_EQ(huge.error, "number overflow parsing '1e400'");
  EXPECT_EQ(huge.error_offset, 13u);  // the number's last byte, line 2

  JsonParse broken = ParseJson("[1,\n 2 3]");
  ASSERT_FALSE(broken.value.has_value());
  EXPECT_EQ(broken.error_offset, 7u);  // the '3'
  EXPECT_NE(broken.error.find("syntax error"), std::string::npos) << broken.error;
  EXPECT_EQ(broken.error.find("json.exception"), std::string::npos) << broken.error;

  EXPECT_FALSE(ParseJson("").value.has_value());
  EXPECT_FALSE(ParseJson(std::string(100000, '[')).value.has_value());  // deep: no recursion, no crash
}

TEST(Json, TextThatIsNotUtf8IsReplacedNotThrown) {
  nlohmann::ordered_json json = {{"file", "lay\xff.place"}};
  EXPECT_EQ(JsonText(json), "{\n  \"file\": \"lay\xef\xbf\xbd.place\"\n}\n");
  nlohmann::json plain = {{"file", std::string("\xc3")}};
  EXPECT_EQ(JsonText(plain), "{\n  \"file\": \"\xef\xbf\xbd\"\n}\n");
}

TEST(Json, NumbersAreWrittenWithTheirShortestDigits) {
  // nlohmann's Grisu2 writes 0.059409 as 0.059408999999999997.
  EXPECT_EQ(JsonText(nlohmann::json(RoundedToDecimals(0.0594090001, 6))), "0.059409\n");
  EXPECT_EQ(JsonText(nlohmann::ordered_json({{"a", 0.059409}})), "{\n  \"a\": 0.059409\n}\n");
  // Otherwise nlohmann's spelling: ".0" on integral values, plain from 1e-4
  // to below 1e15, an exponent of at least two digits beyond.
  const std::vector<std::pair<double, std::string>> cases = {
      {0.0, "0.0"},        {-0.0, "-0.0"},         {1.0, "1.0"},
      {-12.0, "-12.0"},    {179.9843, "179.9843"}, {0.0001, "0.0001"},
      {1e-05, "1e-05"},    {2.9e-05, "2.9e-05"},   {-4.1e-11, "-4.1e-11"},
      {1e14, "100000000000000.0"}, {1e15, "1e+15"}, {1.2345678901234568e+17, "1.2345678901234568e+17"},
      {1e300, "1e+300"},   {0.1 + 0.2, "0.30000000000000004"}};
  for (const auto& [value, text] : cases) {
    EXPECT_EQ(JsonText(nlohmann::json(value)), text + "\n") << text;
    EXPECT_EQ(nlohmann::json(value).dump(), text) << "nlohmann spells " << text << " so";
  }
  // Integers, and digits in strings and keys, as they are.
  EXPECT_EQ(JsonText(nlohmann::ordered_json({{"1.50", "x 1.50e3"}, {"n", 42}, {"m", -7}})),
            "{\n  \"1.50\": \"x 1.50e3\",\n  \"n\": 42,\n  \"m\": -7\n}\n");
  EXPECT_EQ(JsonText(nlohmann::json("a \"quoted\" 0.10")), "\"a \\\"quoted\\\" 0.10\"\n");
}

// The caret column of each rendered snippet: the display column of '^' in
// the second quoted line, counted in characters.
std::size_t CaretColumn(const std::string& rendered) {
  std::size_t caret_line = rendered.find('\n', rendered.find('\n') + 1) + 1;
  std::string marks = rendered.substr(caret_line, rendered.find('\n', caret_line) - caret_line);
  return marks.find('^');
}

TEST(Diagnostics, ALongLineIsQuotedAsAWindowWithTheCaretInPlace) {
  SourceManager sources;
  // 1000 bytes of 'a', then "é" (2 bytes) and the target "XYZ", then 5000 more.
  std::string line = std::string(1000, 'a') + "\xc3\xa9XYZ" + std::string(5000, 'b');
  std::uint32_t id = sources.Add("long.csv", line + "\n");
  Diagnostics diags(sources);
  diags.Report(DiagKind::SyntaxError, SourceRange(SourceLoc{id, 1, 1003}, 3), "here");
  std::string text = diags.RenderText();
  EXPECT_LT(text.size(), 800u) << text.size();
  // "  ..." + 118 'a' + "é" + "XYZ" (the window starts 120 bytes before the
  // caret): the caret under X, in characters.
  std::size_t first_line = text.find('\n') + 1;
  std::string quoted = text.substr(first_line, text.find('\n', first_line) - first_line);
  EXPECT_TRUE(quoted.starts_with("  ...aaa")) << quoted;
  EXPECT_TRUE(quoted.ends_with("bbb...")) << quoted;
  EXPECT_NE(quoted.find("\xc3\xa9XYZ"), std::string::npos);
  std::size_t x_in_characters = 2 + 3 + 118 + 1;  // indent, "...", the 'a's shown, "é"
  EXPECT_EQ(CaretColumn(text), x_in_characters) << text;
  EXPECT_NE(text.find("^~~"), std::string::npos);

  // A short line is quoted whole, without "...".
  std::uint32_t short_id = sources.Add("short.csv", "x,y,z\n");
  Diagnostics short_diags(sources);
  short_diags.Report(DiagKind::SyntaxError, SourceRange(SourceLoc{short_id, 1, 3}), "here");
  EXPECT_EQ(short_diags.RenderText(), "short.csv:1:3: error: here\n  x,y,z\n    ^\n");
}

TEST(Diagnostics, AMessageQuotingAHugeFieldIsCut) {
  SourceManager sources;
  Diagnostics diags(sources);
  diags.Report(DiagKind::SyntaxError, SourceRange(), std::string(5000, 'x') + "\xc3\xa9");
  ASSERT_EQ(diags.all().size(), 1u);
  EXPECT_EQ(diags.all()[0].message, std::string(1000, 'x') + "...");
  diags.Report(DiagKind::SyntaxError, SourceRange(), std::string(999, 'x') + "\xc3\xa9");  // cut before the é
  EXPECT_EQ(diags.all()[1].message, std::string(999, 'x') + "...");
}

TEST(Diagnostics, WarningsPastTheLimitAreCountedNotShown) {
  SourceManager sources;
  std::uint32_t id = sources.Add("w", "x\n");
  Diagnostics diags(sources, /*error_limit=*/50, /*warning_limit=*/3);
  for (int i = 0; i < 5; ++i) {
    Diagnostic* shown = diags.Report(DiagKind::TraceIncomplete, SourceRange(SourceLoc{id, 1, 1}), i);
    EXPECT_EQ(shown != nullptr, i < 3);
  }
  EXPECT_EQ(diags.warning_count(), 5u);
  ASSERT_EQ(diags.all().size(), 4u);
  EXPECT_EQ(diags.all().back().kind, DiagKind::TooManyWarnings);
  EXPECT_EQ(diags.all().back().message, "more than 3 warnings; the others are counted but not shown");
  EXPECT_FALSE(diags.has_errors());
}

}  // namespace
}  // namespace smtcal
