// The lexical layer of the CAD list readers (frontend/cad/cad_text.h): numbers
// with units and decimal commas, sides, DNP marks, column names, globs and
// the three ways of splitting a row.
#include <gtest/gtest.h>

#include "frontend/cad/cad_text.h"
#include "ir/ir_text.h"

namespace smtcal::cad {
namespace {

Length Mm(std::string_view text, LengthUnit unit = LengthUnit::kMm, bool decimal_comma = false) {
  return ParseLength(text, unit, decimal_comma);
}

TEST(CadText, LengthsInEveryUnitAndSpelling) {
  EXPECT_EQ(Mm("12.5").mm, 12.5);
  EXPECT_EQ(Mm("12.5mm").mm, 12.5);
  EXPECT_EQ(Mm("12.5 MM").mm, 12.5);
  EXPECT_EQ(Mm("-3.2mm").mm, -3.2);
  EXPECT_EQ(Mm("+5").mm, 5.0);
  EXPECT_EQ(Mm("2.5e3").mm, 2500.0);
  EXPECT_EQ(Mm("1000mil").mm, 25.4);
  EXPECT_EQ(Mm("1000 mils").mm, 25.4);
  EXPECT_EQ(Mm("0.5in").mm, 12.7);
  EXPECT_EQ(Mm("0.5 inch").mm, 12.7);
  EXPECT_EQ(Mm("2\"").mm, 50.8);
  EXPECT_EQ(Mm("1000", LengthUnit::kMil).mm, 25.4);
  EXPECT_EQ(Mm("1", LengthUnit::kInch).mm, 25.4);
  // A suffix wins over the list's unit.
  EXPECT_EQ(Mm("10mm", LengthUnit::kMil).mm, 10.0);
}

TEST(CadText, ConvertedLengthsPrintAsTheirShortDecimal) {
  // 175 mil is 4.445 mm; 175 * 0.0254 in doubles is 4.4450000000000003.
  EXPECT_EQ(FormatRealLiteral(Mm("175", LengthUnit::kMil).mm), "4.445");
  EXPECT_EQ(FormatRealLiteral(Mm("482.473", LengthUnit::kMil).mm), "12.254814");
  EXPECT_EQ(FormatRealLiteral(Mm("0.5906", LengthUnit::kInch).mm), "15.00124");
  // Never a negative zero.
  EXPECT_EQ(FormatRealLiteral(Mm("-0.0000001").mm), "0.0");
}

TEST(CadText, DecimalCommaOnlyWhereFieldsAreNotCommaSeparated) {
  EXPECT_EQ(Mm("12,5", LengthUnit::kMm, true).mm, 12.5);
  EXPECT_EQ(Mm("12,5mm", LengthUnit::kMm, true).mm, 12.5);
  EXPECT_EQ(Mm("12,5", LengthUnit::kMm, false).status, Length::Status::kNotNumber);
  // Two commas or a comma beside a point is not a decimal comma.
  EXPECT_EQ(Mm("1,000,5", LengthUnit::kMm, true).status, Length::Status::kNotNumber);
  EXPECT_EQ(Mm("1.000,5", LengthUnit::kMm, true).status, Length::Status::kNotNumber);
}

TEST(CadText, BadLengths) {
  EXPECT_EQ(Mm("").status, Length::Status::kNotNumber);
  EXPECT_EQ(Mm("abc").status, Length::Status::kNotNumber);
  EXPECT_EQ(Mm("12.5.3").status, Length::Status::kNotNumber);
  EXPECT_EQ(Mm("nan").status, Length::Status::kNotNumber);
  EXPECT_EQ(Mm("inf").status, Length::Status::kNotNumber);
  EXPECT_EQ(Mm("++5").status, Length::Status::kNotNumber);
  Length cm = Mm("1.5cm");
  EXPECT_EQ(cm.status, Length::Status::kUnknownUnit);
  EXPECT_EQ(cm.suffix, "cm");
  EXPECT_EQ(Mm("1e9").status, Length::Status::kTooLarge);
  EXPECT_EQ(Mm("5000", LengthUnit::kInch).status, Length::Status::kTooLarge);
}

TEST(CadText, Angles) {
  EXPECT_EQ(ParseAngle("90", false), 90.0);
  EXPECT_EQ(ParseAngle("-45.5", false), -45.5);
  EXPECT_EQ(ParseAngle("270deg", false), 270.0);
  EXPECT_EQ(ParseAngle("12\xC2\xB0", false), 12.0);
  EXPECT_EQ(ParseAngle("22,5", true), 22.5);
  EXPECT_FALSE(ParseAngle("22,5", false));
  EXPECT_FALSE(ParseAngle("R90", false));
  EXPECT_FALSE(ParseAngle("", false));
}

TEST(CadText, SideSpellingsOfEveryTool) {
  for (std::string_view top : {"top", "Top", "TOP", "T", "t", "F.Cu", "f.cu", "TopLayer", "Top Layer", "front"}) {
    EXPECT_EQ(ParseSide(top), Side::kTop) << top;
  }
  for (std::string_view bottom : {"bottom", "Bottom", "B", "b", "B.Cu", "BottomLayer", "Bottom Layer", "bot", "back"}) {
    EXPECT_EQ(ParseSide(bottom), Side::kBottom) << bottom;
  }
  for (std::string_view neither : {"", "middle", "In1.Cu", "TB"}) EXPECT_FALSE(ParseSide(neither)) << neither;
}

TEST(CadText, DnpMarks) {
  for (std::string_view yes : {"yes", "Y", "1", "x", "DNP", "dnf", "DNI", "true", "excluded"}) {
    EXPECT_EQ(ParseDnp(yes), true) << yes;
  }
  for (std::string_view no : {"", "no", "N", "0", "false"}) EXPECT_EQ(ParseDnp(no), false) << no;
  EXPECT_FALSE(ParseDnp("maybe"));
}

TEST(CadText, ColumnNamesLoseCaseSeparatorsAndUnit) {
  ColumnName altium = NormaliseColumnName("Center-X(mil)");
  EXPECT_EQ(altium.base, "centerx");
  EXPECT_EQ(altium.unit, LengthUnit::kMil);
  ColumnName diptrace = NormaliseColumnName(" Center X (mm) ");
  EXPECT_EQ(diptrace.base, "centerx");
  EXPECT_EQ(diptrace.unit, LengthUnit::kMm);
  EXPECT_EQ(NormaliseColumnName("Mid X").base, "midx");
  EXPECT_EQ(NormaliseColumnName("Pos_X [in]").unit, LengthUnit::kInch);
  EXPECT_EQ(NormaliseColumnName("RefDes").base, "refdes");
  ColumnName cm = NormaliseColumnName("X (cm)");
  EXPECT_FALSE(cm.unit);
  EXPECT_EQ(cm.unit_text, "cm");
}

// Packages as CAD tools write them against a feeder's package pattern.
TEST(CadText, ChipSizesHoweverTheToolSpellsThem) {
  struct Case {
    const char* package;
    const char* size;
  };
  for (const Case& c : std::initializer_list<Case>{
           {"C_0805_2012Metric", "0805"},      // KiCad
           {"R_0402_1005Metric", "0402"},      // KiCad
           {"LED_0603_1608Metric", "0603"},    // KiCad
           {"C_0201_0603Metric", "0201"},      // KiCad: the metric 0603 is an 0201
           {"C0805", "0805"},                  // EasyEDA
           {"R0603", "0603"},                  // EasyEDA
           {"0805", "0805"},                   // Altium
           {"CAPC2012X135N", "0805"},          // IPC-7351, metric size after the family
           {"RESC1005X40X25NL05T05", "0402"},  // IPC-7351
           {"INDC3225X220N", "1210"},          // IPC-7351
           {"01005", "01005"},
           {"SOT-23", ""},
           {"SOIC-8_3.9x4.9mm_P1.27mm", ""},
           {"LED_WS2812B_PLCC4_5.0x5.0mm_P3.2mm", ""},
           {"FP-ERJ2R-IPC_B", ""},
           {"MOLEX-53261-0471_V", ""},
       }) {
    EXPECT_EQ(ChipSize(c.package), c.size) << c.package;
  }
  EXPECT_TRUE(PackageMatch("0805", "C_0805_2012Metric"));
  EXPECT_TRUE(PackageMatch("0805", "CAPC2012X135N"));
  EXPECT_TRUE(PackageMatch("2012Metric", "R0805"));
  EXPECT_TRUE(PackageMatch("2012metric", "0805"));
  EXPECT_FALSE(PackageMatch("0603", "C_0201_0603Metric"));
  EXPECT_FALSE(PackageMatch("0805", "C_0603_1608Metric"));
  EXPECT_FALSE(PackageMatch("0805", "SOT-23"));
  // Other patterns are globs in which '-', '_' and spaces do not count.
  EXPECT_TRUE(PackageMatch("SOT-23", "SOT23"));
  EXPECT_TRUE(PackageMatch("SOT-23", "sot_23"));
  EXPECT_FALSE(PackageMatch("SOT-23", "SOT-23-5"));
  EXPECT_TRUE(PackageMatch("C_0805*", "C0805"));
  EXPECT_TRUE(PackageMatch("SOIC-8*", "SOIC-8_3.9x4.9mm_P1.27mm"));
  EXPECT_FALSE(PackageMatch("SOIC-8*", "SOIC-14_3.9x8.7mm_P1.27mm"));
}

TEST(CadText, Globs) {
  EXPECT_TRUE(GlobMatch("R_0603*", "r_0603_1608Metric"));
  EXPECT_TRUE(GlobMatch("*", ""));
  EXPECT_TRUE(GlobMatch("*Fiducial*", "Fiducial_1mm"));
  EXPECT_TRUE(GlobMatch("C?", "C1"));
  EXPECT_TRUE(GlobMatch("C?", "C\xCE\xA9"));  // ? is one code point (Ω)
  EXPECT_TRUE(GlobMatch("*a*b*c", "xxaxxbxxc"));
  EXPECT_FALSE(GlobMatch("C?", "C12"));
  EXPECT_FALSE(GlobMatch("R_0603*", "C_0603"));
  EXPECT_FALSE(GlobMatch("", "x"));
  EXPECT_TRUE(GlobMatch("10k", "10K"));
}

class CadSplit : public testing::Test {
 protected:
  Lines Register(const std::string& text) {
    file_ = sources_.Add("t.csv", text);
    return Lines(sources_, file_);
  }
  SourceManager sources_;
  Diagnostics diags_{sources_};
  std::uint32_t file_ = 0;
};

TEST_F(CadSplit, DelimitedFollowsRfc4180) {
  Lines lines = Register("\xEF\xBB\xBF\"C1\",\"100n, 50V\",\"a \"\"b\"\"\", 12.5 ,\r\nnext\n");
  std::uint32_t number = 1;
  std::vector<Field> fields;
  ASSERT_TRUE(SplitDelimited(lines, number, ',', fields, diags_));
  ASSERT_EQ(fields.size(), 5u);
  EXPECT_EQ(fields[0].text, "C1");
  EXPECT_EQ(fields[1].text, "100n, 50V");
  EXPECT_EQ(fields[2].text, "a \"b\"");
  EXPECT_EQ(fields[3].text, "12.5");
  EXPECT_EQ(fields[4].text, "");
  // Columns count the file's bytes: the BOM is 3 of them.
  EXPECT_EQ(fields[0].range.begin.column, 4u);
  EXPECT_EQ(fields[0].range.length, 4u);
  EXPECT_EQ(fields[3].range.begin.column, 32u);
  EXPECT_EQ(number, 1u);
}

TEST_F(CadSplit, AQuotedFieldMayRunOverLineEnds) {
  Lines lines = Register("R1,\"10k\r\n1%\",R_0603\nR2,x,y\n");
  std::uint32_t number = 1;
  std::vector<Field> fields;
  ASSERT_TRUE(SplitDelimited(lines, number, ',', fields, diags_));
  ASSERT_EQ(fields.size(), 3u);
  EXPECT_EQ(fields[1].text, "10k\n1%");
  EXPECT_EQ(fields[2].text, "R_0603");
  EXPECT_EQ(number, 2u);  // the record ended on line 2
}

TEST_F(CadSplit, QuotingMistakesAreReported) {
  Lines lines = Register("a,\"b\nc\"x,d\ne,f\"g\n\"open\n");
  std::vector<Field> fields;
  std::uint32_t number = 1;
  EXPECT_FALSE(SplitDelimited(lines, number, ',', fields, diags_));  // "x after the closing quote
  number = 3;
  EXPECT_FALSE(SplitDelimited(lines, number, ',', fields, diags_));  // quote inside an unquoted field
  number = 4;
  EXPECT_FALSE(SplitDelimited(lines, number, ',', fields, diags_));  // never closed
  ASSERT_EQ(diags_.all().size(), 3u);
  EXPECT_EQ(diags_.all()[0].kind, DiagKind::CsvStrayQuote);
  EXPECT_EQ(diags_.all()[1].kind, DiagKind::CsvStrayQuote);
  EXPECT_EQ(diags_.all()[2].kind, DiagKind::CadUnclosedQuote);
}

TEST_F(CadSplit, SemicolonsAndTabs) {
  Lines lines = Register("C1;10,5;\"a;b\"\nC2\t1\t2\n");
  std::vector<Field> fields;
  std::uint32_t number = 1;
  ASSERT_TRUE(SplitDelimited(lines, number, ';', fields, diags_));
  ASSERT_EQ(fields.size(), 3u);
  EXPECT_EQ(fields[1].text, "10,5");
  EXPECT_EQ(fields[2].text, "a;b");
  number = 2;
  ASSERT_TRUE(SplitDelimited(lines, number, '\t', fields, diags_));
  EXPECT_EQ(fields.size(), 3u);
  EXPECT_EQ(GuessDelimiter("a;b;c,d"), ';');
  EXPECT_EQ(GuessDelimiter("a\tb\tc"), '\t');
  EXPECT_EQ(GuessDelimiter("\"a;b;c\",d"), ',');
  EXPECT_EQ(GuessDelimiter("a b c"), ',');
}

TEST_F(CadSplit, WhitespaceKeepsQuotedDescriptionsWhole) {
  Lines lines = Register("J1   53261   TopLayer  175.000  \"Male Header, 1 x 4\"  \"\"\n");
  std::vector<Field> fields;
  ASSERT_TRUE(SplitWhitespace(lines, 1, fields, diags_));
  ASSERT_EQ(fields.size(), 6u);
  EXPECT_EQ(fields[4].text, "Male Header, 1 x 4");
  EXPECT_EQ(fields[5].text, "");
  EXPECT_EQ(fields[3].start, 23u);
}

TEST_F(CadSplit, FixedWidthCutsAtCodePointColumns) {
  // The Ω is two bytes but one column of the report's padding.
  Lines lines = Register("R1   4.7k\xCE\xA9 1%  0603\n");
  std::vector<Field> fields;
  ASSERT_TRUE(SplitFixed(lines, 1, {0, 5, 15}, fields));
  ASSERT_EQ(fields.size(), 3u);
  EXPECT_EQ(fields[1].text, "4.7k\xCE\xA9 1%");
  EXPECT_EQ(fields[2].text, "0603");
  EXPECT_EQ(fields[2].range.begin.column, 17u);  // bytes
  // A cut inside a word means the row does not follow the header.
  EXPECT_FALSE(SplitFixed(lines, 1, {0, 7}, fields));
}

TEST_F(CadSplit, FillerLines) {
  Lines lines = Register("# comment\n\n   \n=====\n\"-----\"\nC1,2\n## End\n");
  for (std::uint32_t n : {1u, 2u, 3u, 4u, 5u, 7u}) EXPECT_TRUE(lines.IsFiller(n)) << n;
  EXPECT_FALSE(lines.IsFiller(6));
}

}  // namespace
}  // namespace smtcal::cad
