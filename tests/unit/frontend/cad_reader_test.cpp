// The CAD list readers (frontend/cad/cad_reader.h): content detection, each
// family's rows and their source ranges, streaming, and a property test that
// writes random rows in the quirks real files have (quoting, CRLF, BOM,
// decimal commas, units) and reads them back. The seed is printed on
// failure; SMTCAL_TEST_SEED varies it.
#include <cstdlib>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "frontend/cad/cad_reader.h"
#include "frontend/cad/cad_table.h"
#include "frontend/cad/cad_bottom.h"
#include "frontend/cad/cad_encoding.h"
#include "frontend/cad/cad_text.h"

namespace smtcal::cad {
namespace {

std::uint64_t BaseSeed() {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : 20240521;
}

struct ReadResult {
  std::optional<Format> format;  // nullopt when the list could not be opened
  std::vector<Row> rows;
  std::string diagnostics;
  std::size_t rows_read = 0;
  std::size_t rows_with_errors = 0;
  LengthUnit unit = LengthUnit::kMm;
};

ReadResult Read(const std::string& text, ReadOptions options = {}, const std::string& name = "list.csv") {
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add(name, text);
  ReadResult result;
  std::unique_ptr<ListReader> reader = OpenList(file, options, diags);
  if (reader) {
    result.format = reader->format();
    Row row;
    while (reader->Next(row)) result.rows.push_back(row);
    result.rows_read = reader->rows_read();
    result.rows_with_errors = reader->rows_with_errors();
    result.unit = reader->unit();
  }
  result.diagnostics = diags.RenderText();
  return result;
}

std::optional<Format> Detect(const std::string& text) {
  SourceManager sources;
  std::uint32_t file = sources.Add("list", text);
  return DetectFormat(Lines(sources, file), sources);
}

// Lists as their tools write them: UTF-16 by its byte order mark or its zero
// bytes, Windows-1252 when the bytes are not UTF-8, UTF-8 kept as it is.
TEST(CadEncoding, Utf16AndWindows1252AreDecodedAndOtherBytesRefused) {
  const std::string utf8 = "Designator\tMid X\n\xC2\xB5" "F\n";  // "µF"
  DecodedText kept = DecodeListText(utf8);
  EXPECT_TRUE(kept.ok);
  EXPECT_EQ(kept.encoding, TextEncoding::kUtf8);
  EXPECT_EQ(kept.text, "");  // use the bytes as they are
  std::string le = "\xFF\xFE", be = "\xFE\xFF", le_bare, be_bare;
  for (unsigned char c : std::string("Designator\tMid X\n\xB5" "F\n")) {  // every code point below 256
    le += {static_cast<char>(c), '\0'};
    be += {'\0', static_cast<char>(c)};
  }
  le_bare = le.substr(2);
  be_bare = be.substr(2);
  for (const auto& [bytes, encoding] : std::initializer_list<std::pair<std::string, TextEncoding>>{
           {le, TextEncoding::kUtf16Le}, {be, TextEncoding::kUtf16Be}, {le_bare, TextEncoding::kUtf16Le},
           {be_bare, TextEncoding::kUtf16Be}}) {
    DecodedText decoded = DecodeListText(bytes);
    EXPECT_TRUE(decoded.ok) << EncodingName(encoding);
    EXPECT_EQ(decoded.encoding, encoding);
    EXPECT_EQ(decoded.text, utf8);
  }
  DecodedText windows = DecodeListText("C1 1\xB5" "F \xB1" "10%\n");
  EXPECT_TRUE(windows.ok);
  EXPECT_EQ(windows.encoding, TextEncoding::kWindows1252);
  EXPECT_EQ(windows.text, "C1 1\xC2\xB5" "F \xC2\xB1" "10%\n");
  DecodedText undefined = DecodeListText("C1 1\xB5" "F\nU1 \x81\n");
  EXPECT_FALSE(undefined.ok);
  EXPECT_EQ(undefined.bad_offset, 10u);
  EXPECT_NE(undefined.why.find("0x81"), std::string::npos);
  DecodedText cut = DecodeListText(le.substr(0, le.size() - 1));
  EXPECT_FALSE(cut.ok);
}

// The version line of KiCad's .pos, which decides its bottom-side x.
TEST(CadKicad, VersionFromThePrintedByLine) {
  struct Case {
    const char* line;
    int major;
  };
  for (const Case& c : std::initializer_list<Case>{{"### Printed by Pcbnew version 6.0.11+dfsg-1", 6},
                                                   {"### Printed by Pcbnew version kicad (5.1.9)-1", 5},
                                                   {"### Printed by Pcbnew version kicad 4.0.5", 4},
                                                   {"### Printed by KiCad version 8.0.3", 8},
                                                   {"### Printed by KiCad version 10.0.0-rc1", 10},
                                                   {"### Printed by Pcbnew version pcbnew (2014-01-24 BZR 4632)-product", 0}}) {
    SourceManager sources;
    Diagnostics diags(sources);
    std::string text = fmt::format("### Module positions - created on x ###\n{}\n## Unit = mm, Angle = deg.\n"
                                   "# Ref Val Package PosX PosY Rot Side\nC1 1 C0603 1 2 0 bottom\n## End\n",
                                   c.line);
    std::unique_ptr<ListReader> reader = OpenList(sources.Add("list.pos", text), {}, diags);
    ASSERT_TRUE(reader) << diags.RenderText();
    EXPECT_EQ(reader->tool_version().major, c.major) << c.line;
    EXPECT_EQ(reader->tool_version().range.begin.line, c.major > 0 ? 2u : 0u);
  }
}

TEST(CadDetect, EveryFormatByContent) {
  EXPECT_EQ(Detect("### Module positions - created on x ###\n## Unit = mm, Angle = deg.\n"), Format::kKicadPos);
  EXPECT_EQ(Detect("### Footprint positions - created on x ###\n"), Format::kKicadPos);
  EXPECT_EQ(Detect("## Unit = inches, Angle = deg.\n# Ref Val\n"), Format::kKicadPos);
  EXPECT_EQ(Detect("# Ref     Val       Package  PosX  PosY  Rot  Side\nC1 1 2 3 4 5 top\n"), Format::kKicadPos);
  EXPECT_EQ(Detect("Ref,Val,Package,PosX,PosY,Rot,Side\n"), Format::kKicadCsv);
  EXPECT_EQ(Detect("\xEF\xBB\xBF" "Designator,Mid X,Mid Y,Layer,Rotation\r\n"), Format::kJlcpcb);
  EXPECT_EQ(Detect("Designator,Comment,Footprint,Mid X,Mid Y,Layer,Rotation\n"), Format::kJlcpcb);
  EXPECT_EQ(Detect("Designator,Val,Package,Mid X,Mid Y,Rotation,Layer\n"), Format::kJlcpcb);
  EXPECT_EQ(Detect("Altium Designer Pick and Place Locations\nC:\\x.txt\n"), Format::kAltium);
  EXPECT_EQ(Detect("\"Altium Designer Pick and Place Locations\"\n"), Format::kAltium);
  EXPECT_EQ(Detect("Date: 1\nUnits used: mm\n"), Format::kAltium);
  EXPECT_EQ(Detect("Designator Footprint Mid X Mid Y Ref X Ref Y Pad X Pad Y TB Rotation Comment\n"), Format::kAltium);
  EXPECT_EQ(Detect("Designator\tFootprint\tMid X\tMid Y\tRef X\tRef Y\tPad X\tPad Y\tLayer\tRotation\tComment\n"),
            Format::kEasyEda);
  EXPECT_EQ(Detect("RefDes,Name,Value,X (mm),Y (mm),Rotate,Side\n"), Format::kDipTrace);
  EXPECT_EQ(Detect("RefDes,Name,Value,Center X (mm),Center Y (mm),Rotation,Side\n"), Format::kDipTrace);
  EXPECT_EQ(Detect("C1 10.16 5.08 90 100n C0603\n"), Format::kEagle);
  EXPECT_EQ(Detect("\n\nU1 1 2 0 C0603\n"), Format::kEagle);
  EXPECT_FALSE(Detect("Bill of materials\n"));
  EXPECT_FALSE(Detect("x,y\n1,2\n"));
  EXPECT_FALSE(Detect(""));
}

TEST(CadReader, KicadPosRowsAndRanges) {
  ReadResult r = Read(
      "### Footprint positions - created on x ###\n"
      "## Unit = mm, Angle = deg.\n"
      "# Ref     Val       Package   PosX       PosY       Rot  Side\n"
      "C1        4.7k\xCE\xA9    C_0603    10.1600    -5.0800   90.0000  bottom\n"
      "## End\n");
  ASSERT_EQ(r.format, Format::kKicadPos) << r.diagnostics;
  ASSERT_EQ(r.rows.size(), 1u) << r.diagnostics;
  const Row& row = r.rows[0];
  EXPECT_EQ(row.line, 4u);
  EXPECT_EQ(row.designator, "C1");
  EXPECT_EQ(row.value, "4.7k\xCE\xA9");
  EXPECT_EQ(row.package, "C_0603");
  EXPECT_EQ(row.x_mm, 10.16);
  EXPECT_EQ(row.y_mm, -5.08);
  EXPECT_EQ(row.rotation_deg, 90.0);
  EXPECT_EQ(row.side, Side::kBottom);
  EXPECT_TRUE(row.side_given);
  EXPECT_EQ(row.x_range.begin.column, 31u);  // bytes: the Î© is two
  EXPECT_EQ(row.x_range.length, 7u);
  EXPECT_EQ(row.value_range.begin.column, 11u);
  EXPECT_EQ(r.rows_read, 1u);
}

TEST(CadReader, KicadInchHeader) {
  ReadResult r = Read("### Module positions ###\n## Unit = inches, Angle = deg.\n# Ref Val Package PosX PosY Rot Side\n"
                      "R1 10k R0603 1.0000 -0.5000 0 top\n");
  ASSERT_EQ(r.rows.size(), 1u) << r.diagnostics;
  EXPECT_EQ(r.unit, LengthUnit::kInch);
  EXPECT_EQ(r.rows[0].x_mm, 25.4);
  EXPECT_EQ(r.rows[0].y_mm, -12.7);
}

TEST(CadReader, AltiumTextFallsBackToTheHeadersColumns) {
  // "10k 1%" has a space: the row has one word more than the header.
  ReadResult r = Read(
      "Altium Designer Pick and Place Locations\nUnits used: mil\n\n"
      "Designator Comment  Layer    Footprint Center-X(mil) Center-Y(mil) Rotation Description\n"
      "R1         10k 1%   TopLayer R0603     1000.000      -500.000      90       \"Resistor, 1%\"\n"
      "R2         4k7      BottomLayer R0603  100           100           0        \"\"\n");
  ASSERT_EQ(r.format, Format::kAltium);
  ASSERT_EQ(r.rows.size(), 2u) << r.diagnostics;
  EXPECT_EQ(r.rows[0].value, "10k 1%");
  EXPECT_EQ(r.rows[0].package, "R0603");
  EXPECT_EQ(r.rows[0].x_mm, 25.4);
  EXPECT_EQ(r.rows[0].y_mm, -12.7);
  EXPECT_EQ(r.rows[1].side, Side::kBottom);
  EXPECT_EQ(r.unit, LengthUnit::kMil);
}

TEST(CadReader, OldAltiumPrefersMidOverRefAndPad) {
  ReadResult r = Read(
      "Designator Footprint Mid X   Mid Y   Ref X   Ref Y   Pad X   Pad Y   TB Rotation Comment\n"
      "C1         0805      1000mil 500mil  900mil  400mil  800mil  300mil  B  270.00   100n\n");
  ASSERT_EQ(r.rows.size(), 1u) << r.diagnostics;
  EXPECT_EQ(r.rows[0].x_mm, 25.4);
  EXPECT_EQ(r.rows[0].y_mm, 12.7);
  EXPECT_EQ(r.rows[0].side, Side::kBottom);
  EXPECT_EQ(r.rows[0].value, "100n");
}

TEST(CadReader, EagleTakesItsSideFromTheOptions) {
  ReadOptions options;
  options.side_without_column = Side::kBottom;
  ReadResult r = Read("C1 10.16 5.08 90 100 nF C0603\nQ1 1 2 180 SOT23\n", options, "board.mnb");
  ASSERT_EQ(r.rows.size(), 2u) << r.diagnostics;
  EXPECT_EQ(r.rows[0].value, "100 nF");
  EXPECT_EQ(r.rows[0].package, "C0603");
  EXPECT_EQ(r.rows[1].value, "");
  EXPECT_EQ(r.rows[1].side, Side::kBottom);
  EXPECT_FALSE(r.rows[1].side_given);
}

TEST(CadReader, GenericByNameAndByNumber) {
  ReadOptions options;
  options.format = Format::kGenericCsv;
  ASSERT_FALSE(ParseColumnMapping("designator=Part,x=PX,y=PY,rotation=A", options.mapping));
  ReadResult r = Read("Part;PX;PY;A\nC1;1,5;2,5;90\n", options);
  ASSERT_EQ(r.rows.size(), 1u) << r.diagnostics;
  EXPECT_EQ(r.rows[0].x_mm, 1.5);
  EXPECT_EQ(r.rows[0].y_mm, 2.5);

  ReadOptions numbers;
  numbers.format = Format::kGenericCsv;
  numbers.units = LengthUnit::kMil;
  ASSERT_FALSE(ParseColumnMapping("designator=2,x=3,y=4", numbers.mapping));
  r = Read("1,C1,1000,500\n2,C2,0,0\n", numbers);
  ASSERT_EQ(r.rows.size(), 2u) << r.diagnostics;
  EXPECT_EQ(r.rows[0].designator, "C1");
  EXPECT_EQ(r.rows[0].x_mm, 25.4);
  EXPECT_EQ(r.rows[0].rotation_deg, 0.0);  // no rotation column: 0
}

TEST(CadReader, ColumnMappingMistakes) {
  ColumnMapping mapping;
  EXPECT_TRUE(ParseColumnMapping("designator=Ref,x=X", mapping));          // y missing
  EXPECT_TRUE(ParseColumnMapping("designator=Ref,x=X,y=Y,angle=A", mapping));  // unknown key
  EXPECT_TRUE(ParseColumnMapping("designator=1,x=X,y=Y", mapping));          // names and numbers
  EXPECT_TRUE(ParseColumnMapping("designator=0,x=1,y=2", mapping));          // numbers start at 1
  EXPECT_TRUE(ParseColumnMapping("designator=99999,x=1,y=2", mapping));      // too large
  EXPECT_TRUE(ParseColumnMapping("designator", mapping));
  ColumnMapping good;
  EXPECT_FALSE(ParseColumnMapping("designator=Ref,x=X,y=Y,side=Layer,dnp=Fitted", good));
  EXPECT_EQ(good.columns[static_cast<int>(Column::kDnp)], "Fitted");
}

TEST(CadReader, ARowWithAMistakeIsReportedAndTheOthersAreRead) {
  ReadResult r = Read("Ref,Val,Package,PosX,PosY,Rot,Side\n"
                      "C1,1,A,1,2,0,top\n"
                      "C2,1,A,x,2,0,top\n"
                      "C3,1,A,1,2\n"
                      "C4,1,A,1,2,0,top,,\n");  // trailing empty fields are fine
  EXPECT_EQ(r.rows.size(), 2u);
  EXPECT_EQ(r.rows_read, 4u);
  EXPECT_EQ(r.rows_with_errors, 2u);
  EXPECT_NE(r.diagnostics.find("list.csv:3:"), std::string::npos);
  EXPECT_NE(r.diagnostics.find("list.csv:4:"), std::string::npos);
}

// ------------------------------------------------------------------ property

std::string RandomText(std::mt19937_64& rng, bool wild) {
  static const std::vector<std::string> pieces = {"R", "C", "10", "k", "_", "0603", "-", ".", "u", "F"};
  static const std::vector<std::string> wild_pieces = {",", "\"", " ", ";", "\xCE\xA9", "\xC2\xB5", "\n"};
  std::string text;
  int n = std::uniform_int_distribution<int>(1, 6)(rng);
  for (int i = 0; i < n; ++i) {
    bool use_wild = wild && std::uniform_int_distribution<int>(0, 3)(rng) == 0;
    const auto& set = use_wild ? wild_pieces : pieces;
    text += set[std::uniform_int_distribution<std::size_t>(0, set.size() - 1)(rng)];
  }
  // Fields are trimmed and a lone line end would end the record in blank-
  // separated lists: keep the ends solid.
  return "X" + text + "Y";
}

std::string Quote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

TEST(CadReaderProperty, RandomRowsSurviveEveryQuirk) {
  for (int k = 0; k < 200; ++k) {
    const std::uint64_t seed = BaseSeed() + static_cast<std::uint64_t>(k);
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937_64 rng(seed);
    const bool semicolon = k % 2 == 1;  // then decimal commas
    const bool crlf = k % 3 == 0;
    const bool bom = k % 5 == 0;
    const LengthUnit unit = static_cast<LengthUnit>(k % 3);
    const char sep = semicolon ? ';' : ',';
    std::string text = bom ? "\xEF\xBB\xBF" : "";
    text += fmt::format("Designator{0}Val{0}Package{0}Mid X{0}Mid Y{0}Rotation{0}Layer", sep);
    text += crlf ? "\r\n" : "\n";
    struct Expected {
      std::string designator, value, package;
      double x, y, rotation;
      Side side;
    };
    std::vector<Expected> expected;
    int rows = std::uniform_int_distribution<int>(1, 30)(rng);
    for (int i = 0; i < rows; ++i) {
      Expected e;
      e.designator = fmt::format("U{}", i + 1);
      e.value = RandomText(rng, true);
      e.package = RandomText(rng, true);
      // Values on a 0.001 grid of the unit, written with 3 decimals.
      long x = std::uniform_int_distribution<long>(-500000, 500000)(rng);
      long y = std::uniform_int_distribution<long>(-500000, 500000)(rng);
      e.x = ParseLength(fmt::format("{}.{:03}", x / 1000, std::abs(x % 1000)), unit, false).mm;
      std::string xs = fmt::format("{}{}.{:03}", x < 0 && x > -1000 ? "-" : "", x / 1000, std::abs(x % 1000));
      std::string ys = fmt::format("{}{}.{:03}", y < 0 && y > -1000 ? "-" : "", y / 1000, std::abs(y % 1000));
      e.x = ParseLength(xs, unit, false).mm;
      e.y = ParseLength(ys, unit, false).mm;
      e.rotation = std::uniform_int_distribution<int>(0, 359)(rng);
      e.side = std::uniform_int_distribution<int>(0, 1)(rng) == 0 ? Side::kTop : Side::kBottom;
      std::string suffix = std::uniform_int_distribution<int>(0, 2)(rng) == 0 ? std::string(UnitName(unit)) : "";
      if (semicolon) {
        std::replace(xs.begin(), xs.end(), '.', ',');
        std::replace(ys.begin(), ys.end(), '.', ',');
      }
      bool quote_numbers = std::uniform_int_distribution<int>(0, 1)(rng) == 0;
      auto number = [&](const std::string& s) { return quote_numbers ? Quote(s + suffix) : s + suffix; };
      text += fmt::format("{1}{0}{2}{0}{3}{0}{4}{0}{5}{0}{6}{0}{7}", sep, Quote(e.designator), Quote(e.value),
                          Quote(e.package), number(xs), number(ys), static_cast<int>(e.rotation),
                          e.side == Side::kTop ? "top" : "B");
      text += crlf ? "\r\n" : "\n";
      expected.push_back(e);
    }
    ReadOptions options;
    options.units = unit;
    ReadResult r = Read(text, options);
    ASSERT_EQ(r.format, Format::kJlcpcb) << r.diagnostics;
    ASSERT_EQ(r.rows.size(), expected.size()) << r.diagnostics << text;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      std::string value = expected[i].value, package = expected[i].package;
      // A line end inside quotes comes back as '\n' (CRLF included).
      EXPECT_EQ(r.rows[i].designator, expected[i].designator);
      EXPECT_EQ(r.rows[i].value, value);
      EXPECT_EQ(r.rows[i].package, package);
      EXPECT_EQ(r.rows[i].x_mm, expected[i].x);
      EXPECT_EQ(r.rows[i].y_mm, expected[i].y);
      EXPECT_EQ(r.rows[i].rotation_deg, expected[i].rotation);
      EXPECT_EQ(r.rows[i].side, expected[i].side);
    }
  }
}


// How the bottom side's x is read (cad_bottom.h): by KiCad's version where
// the .pos names one up to 6, else by the list's own numbers, else seen
// from the top; every other tool from the top.
TEST(CadBottom, KicadVersionThenTheNumbersThenTopView) {
  auto decide = [](const std::string& text, const std::vector<SidedX>& parts, const std::string& name = "list.pos") {
    SourceManager sources;
    Diagnostics diags(sources);
    std::unique_ptr<ListReader> reader = OpenList(sources.Add(name, text), {}, diags);
    EXPECT_TRUE(reader) << diags.RenderText();
    return reader ? DecideBottomPositions(*reader, parts).positions : BottomPositions::kTopView;
  };
  const std::string kicad6 = "### Module positions - created on x ###\n### Printed by Pcbnew version 6.0.11\n"
                             "## Unit = mm, Angle = deg.\n# Ref Val Package PosX PosY Rot Side\n";
  const std::string kicad8 = "### Footprint positions - created on x ###\n### Printed by KiCad version 8.0.3\n"
                             "## Unit = mm, Angle = deg.\n# Ref Val Package PosX PosY Rot Side\n";
  const std::string csv = "Ref,Val,Package,PosX,PosY,Rot,Side\n";
  const std::string jlc = "Designator,Mid X,Mid Y,Layer,Rotation\n";
  const std::vector<SidedX> mixed = {{5, Side::kBottom}, {-5, Side::kBottom}};
  const std::vector<SidedX> negative = {{-5, Side::kBottom}, {-7, Side::kBottom}, {3, Side::kTop}};
  const std::vector<SidedX> top_negative = {{-5, Side::kBottom}, {-3, Side::kTop}};
  EXPECT_EQ(decide(kicad6, mixed), BottomPositions::kNegatedX);  // KiCad 6 always negated
  EXPECT_EQ(decide(kicad8, mixed), BottomPositions::kTopView);
  EXPECT_EQ(decide(kicad8, negative), BottomPositions::kNegatedX);  // "negative X" was asked for
  EXPECT_EQ(decide(csv, negative, "list.csv"), BottomPositions::kNegatedX);
  EXPECT_EQ(decide(csv, top_negative, "list.csv"), BottomPositions::kTopView);  // the numbers do not tell
  EXPECT_EQ(decide(csv, mixed, "list.csv"), BottomPositions::kTopView);
  EXPECT_EQ(decide(jlc, negative, "list.csv"), BottomPositions::kTopView);  // not KiCad
}

}  // namespace
}  // namespace smtcal::cad
