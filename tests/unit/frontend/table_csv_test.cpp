// The CSV reader of error tables, raw measurements and point lists: the
// dialect (quotes, CRLF, BOM, comments, blank lines, columns in any order),
// locale-independent numbers, and a seeded mutation fuzz that must never crash
// (run it under ASan/UBSan too).
#include <clocale>
#include <cstdlib>
#include <random>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "calibration/error_table_check.h"
#include "calibration/inverse_calibration.h"
#include "frontend/table_csv.h"

namespace smtcal {
namespace {

const char* kTable =
    "# a small table\n"
    "axis,x_mm,y_mm,error_mm,stddev_mm,n\n"
    "x,0,0,-0.050,0.002,20\n"
    "x,10,0,-0.060,0.002,20\n"
    "x,0,10,-0.054,0.002,20\n"
    "x,10,10,-0.064,0.002,20\n"
    "y,0.004,-0.003,0.010,,\n"
    "y,10.004,-0.003,0.013,,\n"
    "y,0.004,9.997,0.012,,\n"
    "y,10.004,9.997,0.015,,\n";

struct Read {
  SourceManager sources;
  Diagnostics diags{sources};
  std::uint32_t file = 0;
  explicit Read(std::string text, std::string name = "t.csv") {
    file = sources.Add(std::move(name), std::move(text));
  }
};

TEST(TableCsv, SplitsQuotedFieldsCrlfBomCommentsAndBlankLines) {
  Read r("\xEF\xBB\xBF" "a, \"b,c\" ,\"say \"\"hi\"\"\"\r\n"
         "\r\n"
         "   # comment\r\n"
         "1,,  2  \r\n");
  std::vector<CsvRecord> records = SplitCsv(r.file, r.diags);
  ASSERT_FALSE(r.diags.has_errors()) << r.diags.RenderText();
  ASSERT_EQ(records.size(), 2u);
  ASSERT_EQ(records[0].fields.size(), 3u);
  EXPECT_EQ(records[0].fields[0].text, "a");
  EXPECT_EQ(records[0].fields[1].text, "b,c");
  EXPECT_EQ(records[0].fields[2].text, "say \"hi\"");
  EXPECT_EQ(records[0].line, 1u);
  EXPECT_EQ(records[0].fields[0].range.begin.column, 4u);  // after the 3-byte BOM
  EXPECT_EQ(records[1].line, 4u);
  ASSERT_EQ(records[1].fields.size(), 3u);
  EXPECT_EQ(records[1].fields[1].text, "");
  EXPECT_EQ(records[1].fields[2].text, "2");
  EXPECT_EQ(records[1].fields[2].range.begin.column, 6u);
}

TEST(TableCsv, ReadsATableWithColumnsInAnyOrder) {
  Read plain(kTable);
  std::optional<ErrorTable> a = ReadErrorTable(plain.file, plain.diags);
  ASSERT_TRUE(a.has_value()) << plain.diags.RenderText();
  Read shuffled("\xEF\xBB\xBF" "N,Error_mm,y_mm,AXIS,x_mm,stddev_mm\r\n"
                "20,-0.064,10,x,10,0.002\r\n"
                "20,-0.050,0,x,0,0.002\r\n"
                ",0.015,9.997,y,10.004,\r\n"
                "20,-0.054,10,x,0,0.002\r\n"
                ",0.010,-0.003,\"y\",0.004,\r\n"
                "20,-0.060,0,x,+10,0.002\r\n"
                ",0.012,9.997,Y,0.004,\r\n"
                ",1.3e-2,-0.003,y,10.004,\r\n");
  std::optional<ErrorTable> b = ReadErrorTable(shuffled.file, shuffled.diags);
  ASSERT_TRUE(b.has_value()) << shuffled.diags.RenderText();
  for (TableAxis axis : kTableAxes) {
    EXPECT_EQ((*a)[axis].xs, (*b)[axis].xs);
    EXPECT_EQ((*a)[axis].ys, (*b)[axis].ys);
    EXPECT_EQ((*a)[axis].error_mm, (*b)[axis].error_mm);
    EXPECT_EQ((*a)[axis].count, (*b)[axis].count);
  }
  EXPECT_EQ((*a)[TableAxis::X].count, std::vector<int>(4, 20));
  EXPECT_EQ((*a)[TableAxis::X].stddev_mm, std::vector<std::optional<double>>(4, 0.002));
  EXPECT_TRUE((*a)[TableAxis::Y].stddev_mm.empty()) << "no y node has a stddev";
  // Each node knows where its value was written, for diagnostics.
  EXPECT_EQ((*a)[TableAxis::X].Origin(1, 1).begin.line, 6u);
  EXPECT_EQ((*a)[TableAxis::X].Origin(1, 1).begin.column, 9u);
}

TEST(TableCsv, NumbersIgnoreTheLocale) {
  // A locale with a decimal comma must not change how "1.5" reads.
  if (std::setlocale(LC_ALL, "de_DE.UTF-8") == nullptr && std::setlocale(LC_ALL, "fr_FR.UTF-8") == nullptr) {
    GTEST_SKIP() << "no decimal-comma locale installed";
  }
  Read r("1.5,-2.25e1\n");
  std::optional<std::vector<PointRow>> points = ReadPoints(r.file, r.diags);
  std::setlocale(LC_ALL, "C");
  ASSERT_TRUE(points.has_value()) << r.diags.RenderText();
  EXPECT_EQ((*points)[0].point, Eigen::Vector2d(1.5, -22.5));
}

TEST(TableCsv, PointsWithAndWithoutHeader) {
  Read bare("1,2\n# comment\n3.5,-4\n");
  std::optional<std::vector<PointRow>> a = ReadPoints(bare.file, bare.diags);
  ASSERT_TRUE(a.has_value()) << bare.diags.RenderText();
  ASSERT_EQ(a->size(), 2u);
  EXPECT_EQ((*a)[1].point, Eigen::Vector2d(3.5, -4));
  EXPECT_EQ((*a)[1].range.begin.line, 3u);
  EXPECT_EQ((*a)[1].range.length, 6u);
  Read named("y_mm,x_mm\n2,1\n");
  std::optional<std::vector<PointRow>> b = ReadPoints(named.file, named.diags);
  ASSERT_TRUE(b.has_value()) << named.diags.RenderText();
  EXPECT_EQ((*b)[0].point, Eigen::Vector2d(1, 2));
}

TEST(TableCsv, RejectsWhatIsNotANumber) {
  for (const char* bad : {"1.5.2", "0x10", "1,5", "--1", "+-1", "1e", "abc", "1 2", "\"\"", "."}) {
    SCOPED_TRACE(bad);
    Read r(fmt::format("x_mm,y_mm\n{},2\n", bad));
    EXPECT_FALSE(ReadPoints(r.file, r.diags).has_value());
    ASSERT_TRUE(r.diags.has_errors());
  }
  for (const char* not_finite : {"nan", "inf", "-Infinity", "1e400"}) {
    SCOPED_TRACE(not_finite);
    Read r(fmt::format("{},2\n", not_finite));
    EXPECT_FALSE(ReadPoints(r.file, r.diags).has_value());
    ASSERT_EQ(r.diags.all().size(), 1u);
    EXPECT_EQ(r.diags.all()[0].kind, DiagKind::CsvNonFinite);
  }
  for (const char* fine : {"+1.5", "1e-3", ".5", "5.", "-0", "1E+2"}) {
    SCOPED_TRACE(fine);
    Read r(fmt::format("{},2\n", fine));
    EXPECT_TRUE(ReadPoints(r.file, r.diags).has_value()) << r.diags.RenderText();
  }
}

// Lengths far beyond a robot cell (|v| > kMaxLengthMm) are refused where they
// are read: in double arithmetic they would break the fold check (an inf - inf
// slope is NaN, and a NaN determinant passed it) and the inverse solver's
// 1e-9 mm guarantee (a constant 1e308 error left a residual of 2.5 mm).
TEST(TableCsv, RejectsLengthsFarBeyondARobotCell) {
  const char* tables[] = {
      // a fold of +-1e308 at the nodes
      "axis,x_mm,y_mm,error_mm\nx,0,0,1e308\nx,5,0,-1e308\nx,0,5,-1e308\nx,5,5,1e308\n"
      "y,0,0,0\ny,5,0,0\ny,0,5,0\ny,5,5,0\n",
      // a constant error of 1e308 mm
      "axis,x_mm,y_mm,error_mm\nx,0,0,1e308\nx,5,0,1e308\nx,0,5,1e308\nx,5,5,1e308\n"
      "y,0,0,0\ny,5,0,0\ny,0,5,0\ny,5,5,0\n",
      // grid lines at +-1e308 mm
      "axis,x_mm,y_mm,error_mm\nx,-1e308,0,0\nx,1e308,0,0\nx,-1e308,5,0\nx,1e308,5,0\n"
      "y,-1e308,0,0\ny,1e308,0,0\ny,-1e308,5,0\ny,1e308,5,0\n"};
  for (const char* text : tables) {
    SCOPED_TRACE(text);
    Read r(text);
    std::optional<ErrorTable> table = ReadErrorTable(r.file, r.diags);
    EXPECT_FALSE(table && ValidateErrorTable(*table, r.diags, TableWarnings::kSkip));
    ASSERT_FALSE(r.diags.all().empty());
    EXPECT_EQ(r.diags.all()[0].kind, DiagKind::CsvLengthTooLarge);
  }
  Read points("1e300,5\n");
  EXPECT_FALSE(ReadPoints(points.file, points.diags).has_value());
  Read raw("axis,x_mm,y_mm,set,repetition,error_mm\nx,0,0,1,1,-2e5\n");
  EXPECT_FALSE(ReadRawMeasurements(raw.file, raw.diags).has_value());
  Read fine(fmt::format("{},-{}\n", kMaxLengthMm, kMaxLengthMm));
  EXPECT_TRUE(ReadPoints(fine.file, fine.diags).has_value()) << fine.diags.RenderText();
}

TEST(TableCsv, RawMeasurements) {
  Read r("axis,x_mm,y_mm,set,repetition,error_mm\n"
         "x,0,0,1,1,-0.050\n"
         "y,0.004,-0.003,2,10,0.011\n");
  std::optional<std::vector<RawMeasurement>> raw = ReadRawMeasurements(r.file, r.diags);
  ASSERT_TRUE(raw.has_value()) << r.diags.RenderText();
  ASSERT_EQ(raw->size(), 2u);
  EXPECT_EQ((*raw)[1].axis, TableAxis::Y);
  EXPECT_EQ((*raw)[1].set, 2);
  EXPECT_EQ((*raw)[1].repetition, 10);
  EXPECT_EQ((*raw)[1].error_mm, 0.011);
  EXPECT_EQ((*raw)[1].error_field.begin.line, 3u);
}

// The text with control bytes escaped, to reproduce a failing round.
std::string Escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    auto byte = static_cast<unsigned char>(c);
    out += byte < 0x20 || byte >= 0x7f ? fmt::format("\\x{:02x}", byte) : std::string(1, c);
  }
  return out;
}

// Mutations of a valid table: bytes flipped, inserted, deleted, lines
// duplicated. Whatever comes out, the reader reports errors or returns a
// table, never both, never crashes; a table that validates can be solved.
TEST(TableCsv, FuzzedTablesNeverCrash) {
  const char* env = std::getenv("SMTCAL_TEST_SEED");
  const std::uint64_t seed = env != nullptr ? std::strtoull(env, nullptr, 10) : 20240521;
  SCOPED_TRACE(fmt::format("seed {}", seed));
  std::mt19937_64 rng(seed);
  const std::string alphabet = std::string("0123456789.,-+e\"\r\n #xyXY\t") + '\0' + "\x7f\xff";
  int tables = 0;
  for (int round = 0; round < 3000; ++round) {
    std::string text = kTable;
    int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      std::size_t at = rng() % (text.size() + 1);
      switch (rng() % 4) {
        case 0: if (at < text.size()) text[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: text.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
        case 2: if (at < text.size()) text.erase(at, 1 + rng() % 8); break;
        case 3: text.insert(at, text.substr(at, rng() % 40)); break;
      }
    }
    SCOPED_TRACE(fmt::format("round {}", round));
    Read r(text);
    std::optional<ErrorTable> table = ReadErrorTable(r.file, r.diags);
    ASSERT_NE(table.has_value(), r.diags.has_errors()) << Escaped(text) << "\n" << r.diags.RenderText();
    (void)r.diags.RenderText();
    (void)r.diags.RenderJson();
    Read raw(text), points(text);
    const bool raw_read = ReadRawMeasurements(raw.file, raw.diags).has_value();
    const bool points_read = ReadPoints(points.file, points.diags).has_value();
    ASSERT_NE(raw_read, raw.diags.has_errors()) << Escaped(text);
    ASSERT_NE(points_read, points.diags.has_errors()) << Escaped(text);
    if (!table || !ValidateErrorTable(*table, r.diags, TableWarnings::kReport)) continue;
    ++tables;
    InverseSolver solver(*table);
    const Rect& d = solver.map().domain();
    Solution s = solver.Solve({0.5 * (d.x0 + d.x1), 0.5 * (d.y0 + d.y1)}, OutsidePolicy::kClamp);
    EXPECT_LE(s.residual_mm, kInverseResidualTolMm);
  }
  EXPECT_GT(tables, 10) << "some mutations should still be valid tables";
}

}  // namespace
}  // namespace smtcal
