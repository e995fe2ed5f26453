// From CAD rows to a .place program (frontend/cad/cad_to_program.h, frontend/
// feeders_toml.h): the generated program passes the IR verifier, parses back
// to itself in canonical form and is clean under every check pass; the
// KiCad CSV and the JLCPCB CPL of one real board import to the same
// placements; feeders match as documented; angles are normalised; and every
// row ends as a placement or a diagnostic.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "backend/place/place_printer.h"
#include "frontend/cad/cad_reader.h"
#include "frontend/cad/cad_to_program.h"
#include "frontend/cell_toml.h"
#include "frontend/feeders_toml.h"
#include "frontend/parse.h"
#include "ir/verifier.h"
#include "passes/pass.h"
#include "passes/pass_manager.h"
#include "tests/unit/parse_text.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

namespace fs = std::filesystem;

const fs::path kData = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "import-data";
const fs::path kSamples = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "import-samples";

std::uint64_t BaseSeed() {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : 20240521;
}

struct Imported {
  std::optional<ir::Program> program;
  std::string text;         // PrintPlace of the program ("" when none)
  std::string diagnostics;  // rendered
  std::vector<DiagKind> kinds;
  ImportSummary summary;
};

// Runs the import the way `smtcal import` does, on a list given as text.
Imported Import(const std::string& list, ImportOptions options = {}, const fs::path& feeders = kData / "feeders.toml",
                cad::ReadOptions read = {}, const std::string& list_name = "list.csv",
                const fs::path& cell_file = kData / "cell.toml") {
  SourceManager sources;
  Diagnostics diags(sources);
  Imported out;
  Result<std::optional<cell::Cell>> cell = cell::LoadCell(cell_file.string(), sources, diags);
  EXPECT_TRUE(cell.ok() && cell.value()) << diags.RenderText();
  if (!cell.ok() || !cell.value()) return out;
  // The fixture's pocket, as `smtcal import` takes it from the cell.
  if (const auto& pocket = cell.value()->fixtures.front().pocket_mm; pocket && !options.pocket) {
    options.pocket = std::array<double, 4>{(*pocket)[0].lo, (*pocket)[1].lo, (*pocket)[0].hi, (*pocket)[1].hi};
  }
  cad::FeedersFile file;
  if (!feeders.empty()) {
    Result<std::optional<cad::FeedersFile>> loaded = cad::LoadFeeders(feeders.string(), sources, diags);
    EXPECT_TRUE(loaded.ok() && loaded.value()) << diags.RenderText();
    file = std::move(*loaded.value());
  }
  std::optional<cad::FeederTable> table = cad::FeederTable::Build(cell.value()->feeders, std::move(file), diags);
  EXPECT_TRUE(table) << diags.RenderText();
  std::uint32_t id = sources.Add(list_name, list);
  std::unique_ptr<cad::ListReader> reader = cad::OpenList(id, read, diags);
  if (reader && table) {
    if (options.fixture.empty()) options.fixture = "Board";
    if (options.program_name.empty()) options.program_name = "T";
    CadImporter importer(*table, options, id, diags);
    cad::Row row;
    while (reader->Next(row)) importer.Add(row);
    out.program = importer.Finish(*reader);
    out.summary = importer.summary();
    if (out.program) {
      EXPECT_TRUE(VerifyProgram(*out.program).empty()) << "the importer built an IR the verifier rejects";
      out.text = PrintPlace(*out.program);
    }
  }
  out.diagnostics = diags.RenderText();
  for (const Diagnostic& d : diags.all()) out.kinds.push_back(d.kind);
  return out;
}

// The program text parses without errors, prints back to itself, and the
// check passes find nothing (not even a warning).
void ExpectCleanAndCanonical(const std::string& text) {
  SourceManager sources;
  std::uint32_t file = sources.Add("imported.place", text);
  Diagnostics diags(sources);
  ir::Program program = ParseProgram(file, diags);
  ASSERT_EQ(diags.all().size(), 0u) << diags.RenderText() << text;
  EXPECT_EQ(PrintPlace(program), text) << "not canonical";
  std::vector<std::string> checks;
  for (const PassInfo& info : PassRegistry()) checks.push_back(info.name);
  ASSERT_TRUE(RunPasses(program, diags, checks, /*verify_each=*/true).ok());
  EXPECT_EQ(diags.all().size(), 0u) << diags.RenderText() << text;
}

const std::string kHeader = "Ref,Val,Package,PosX,PosY,Rot,Side\n";
const std::string kBoard = kHeader +
                           "C1,100n,C_0603_1608Metric,10.16,5.08,90,top\n"
                           "C2,10uF,C_0805_2012Metric,15,5,0,top\n"
                           "R1,10k,R_0603_1608Metric,20,7.5,180,top\n"
                           "Q1,BC847,SOT-23,25.4,12.7,270,top\n"
                           "U1,NE555,SOIC-8,30,20,45,top\n"
                           "D1,WS2812B,LED_WS2812B_PLCC4,35,-5,-90,top\n"
                           "J1,Conn,JST_PH,0.03,23.99,180,top\n";

TEST(CadImport, GeneratedProgramIsCleanAndCanonical) {
  Imported r = Import(kBoard);
  ASSERT_TRUE(r.program) << r.diagnostics;
  EXPECT_EQ(r.diagnostics, "");
  ExpectCleanAndCanonical(r.text);
  EXPECT_EQ(r.summary.parts_placed, 7u);
  EXPECT_EQ(r.summary.feeders_used, 7u);
}

TEST(CadImport, PanelsBottomSidesAndPalletsAreCleanToo) {
  ImportOptions options;
  options.columns = 3;
  options.rows = 2;
  options.pitch_x_mm = 40;
  options.pitch_y_mm = 30;
  options.rotation_deg = -90;
  options.origin_x_mm = 12.5;
  options.angles = AngleRange::kPositive;
  options.side = cad::Side::kBottom;
  std::string bottom = kBoard;
  for (std::size_t at; (at = bottom.find(",top")) != std::string::npos;) bottom.replace(at, 4, ",bottom");
  Imported r = Import(bottom, options);
  ASSERT_TRUE(r.program) << r.diagnostics;
  ExpectCleanAndCanonical(r.text);
  EXPECT_NE(r.text.find("Local Pcb6 = XY(42.5, -80.0, 0.0, -90.0) In Board"), std::string::npos) << r.text;
  EXPECT_NE(r.text.find("Point Pcb1_C1 = XY(-10.16, 5.08, 0.0, 90.0) In Pcb1"), std::string::npos);
  // R1 at 180 on the bottom: 180 - 180 = 0; Q1 at 270: 180 - 270 = -90 -> 270.
  EXPECT_NE(r.text.find("Point Pcb1_R1 = XY(-20.0, 7.5, 0.0, 0.0) In Pcb1"), std::string::npos);
  EXPECT_NE(r.text.find("Point Pcb1_Q1 = XY(-25.4, 12.7, 0.0, 270.0) In Pcb1"), std::string::npos);
  EXPECT_NE(r.text.find("Pick Pallet(1, 6)  ' pocket 6 of 8"), std::string::npos);  // the 6th SOIC from the tray
  EXPECT_EQ(r.summary.boards, 6u);
}

TEST(CadImport, AnglesAreNormalisedAndOffsetsAdded) {
  std::string list = kHeader +
                     "C1,1,C_0603,0,0,270,top\n"
                     "C2,1,C_0603,0,0,-180,top\n"
                     "C3,1,C_0603,0,0,360,top\n"
                     "C4,1,C_0603,0,0,-450.5,top\n"
                     "C5,10uF,C_0805,0,0,315,top\n"   // + 90 from the [[map]]
                     "D1,WS2812B,LED,0,0,45,top\n";  // - 90 from the Leds feeder
  Imported r = Import(list);
  ASSERT_TRUE(r.program) << r.diagnostics;
  for (std::string_view expected : {"C1 = XY(0.0, 0.0, 0.0, -90.0)", "C2 = XY(0.0, 0.0, 0.0, 180.0)",
                                    "C3 = XY(0.0, 0.0, 0.0, 0.0)", "C4 = XY(0.0, 0.0, 0.0, -90.5)",
                                    "C5 = XY(0.0, 0.0, 0.0, 45.0)", "D1 = XY(0.0, 0.0, 0.0, -45.0)"}) {
    EXPECT_NE(r.text.find(expected), std::string::npos) << expected << "\n" << r.text;
  }
  ImportOptions positive;
  positive.angles = AngleRange::kPositive;
  r = Import(list, positive);
  for (std::string_view expected : {"C1 = XY(0.0, 0.0, 0.0, 270.0)", "C2 = XY(0.0, 0.0, 0.0, 180.0)",
                                    "C3 = XY(0.0, 0.0, 0.0, 0.0)", "C4 = XY(0.0, 0.0, 0.0, 269.5)"}) {
    EXPECT_NE(r.text.find(expected), std::string::npos) << expected << "\n" << r.text;
  }
}

TEST(CadImport, KicadCsvAndJlcpcbCplOfTheSameBoardGiveTheSamePlacements) {
  auto read = [](const std::string& name) { return test::ReadFileText(kSamples / name); };
  Imported kicad = Import(read("opulo-inc__lumenpnp__ringLight-top_pos.csv"), {}, kData / "samples-feeders.toml");
  Imported jlc = Import(read("opulo-inc__lumenpnp__ringLight_cpl_jlc.csv"), {}, kData / "samples-feeders.toml");
  ASSERT_TRUE(kicad.program) << kicad.diagnostics;
  ASSERT_TRUE(jlc.program) << jlc.diagnostics;
  // The placements: every statement but comments, each without its comment
  // (the CPL has no values or packages to show there).
  auto placements = [](const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
      std::size_t comment = line.find('\'');
      if (comment != std::string::npos) line.erase(comment);
      while (!line.empty() && line.back() == ' ') line.pop_back();
      if (!line.empty()) lines.push_back(line);
    }
    return lines;
  };
  std::vector<std::string> a = placements(kicad.text), b = placements(jlc.text);
  EXPECT_EQ(a, b);
  EXPECT_EQ(std::count_if(a.begin(), a.end(), [](const std::string& l) { return l.find("    Place ") == 0; }), 9);
  ExpectCleanAndCanonical(kicad.text);
  ExpectCleanAndCanonical(jlc.text);
}

// The lists KiCad 6 wrote itself (tests/golden/import-kicad, made by
// import-data/generate_kicad_lists.py with pcbnew) against KiCad's own pad
// positions (import-data/kicad-truth.csv): with the default options every
// part is placed so that its library pads land on KiCad's pads once the
// board is turned over about its y axis (bottom) or as they are (top).
TEST(CadImport, KicadListsPlaceEveryPadWhereKicadPutIt) {
  const fs::path kicad = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "import-kicad";
  struct TruthPad {
    std::string ref, side;
    double library_x, library_y, board_x, board_y;
  };
  std::vector<TruthPad> truth;
  {
    std::istringstream in(test::ReadFileText(kData / "kicad-truth.csv"));
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::vector<std::string> f;
      std::istringstream fields(line);
      for (std::string item; std::getline(fields, item, ',');) f.push_back(item);
      ASSERT_EQ(f.size(), 7u) << line;
      truth.push_back({f[0], f[1], std::stod(f[3]), std::stod(f[4]), std::stod(f[5]), std::stod(f[6])});
    }
  }
  ASSERT_GT(truth.size(), 30u);
  struct Case {
    std::string file;
    std::string side;
    double origin_x, origin_y;  // the list's origin in the truth's frame (the auxiliary origin is 0, 0)
    double tolerance_mm;        // what the list's decimals allow
  };
  const std::vector<Case> cases = {
      {"kicad6_bottom.pos", "bottom", 0, 0, 1e-4},      {"kicad6_csv_bottom.csv", "bottom", 0, 0, 1e-4},
      {"kicad6_bottom_inch.pos", "bottom", 0, 0, 2e-3}, {"kicad6_top.pos", "top", 0, 0, 1e-4},
      {"kicad6_all_page.pos", "bottom", -90, 140, 1e-4}, {"kicad8_bottom.pos", "bottom", 0, 0, 1e-4},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    ImportOptions options;
    options.side = c.side == "top" ? cad::Side::kTop : cad::Side::kBottom;
    Imported r = Import(test::ReadFileText(kicad / c.file), options, kData / "kicad-feeders.toml", {}, c.file);
    ASSERT_TRUE(r.program) << r.diagnostics;
    std::map<std::string, std::array<double, 4>> placed;
    for (const ir::StmtPtr& stmt : r.program->items) {
      if (const auto* point = std::get_if<ir::PointDecl>(&stmt->node); point != nullptr && point->frame == "Pcb") {
        placed[point->name] = point->coords.values;
      }
    }
    std::size_t pads = 0;
    for (const TruthPad& pad : truth) {
      if (pad.side != c.side) continue;
      ASSERT_TRUE(placed.count(pad.ref)) << pad.ref << " is not placed";
      const auto& [x, y, z, u] = placed[pad.ref];
      const double angle = u * std::numbers::pi / 180.0;
      const double at_x = x + std::cos(angle) * pad.library_x - std::sin(angle) * pad.library_y;
      const double at_y = y + std::sin(angle) * pad.library_x + std::cos(angle) * pad.library_y;
      // KiCad's pad, in the list's frame, and seen from below for the bottom.
      double want_x = pad.board_x - c.origin_x, want_y = pad.board_y - c.origin_y;
      if (c.side == "bottom") want_x = -want_x;
      EXPECT_NEAR(at_x, want_x, c.tolerance_mm) << pad.ref << " pad";
      EXPECT_NEAR(at_y, want_y, c.tolerance_mm) << pad.ref << " pad";
      ++pads;
    }
    EXPECT_GT(pads, 8u);
  }
}

// KiCad's StickHub demo board (both sides populated), exported by KiCad 6
// with its drill/place file origin on the lower left corner of the board's
// outline (import-data/generate_kicad_demo_lists.py), against where KiCad
// has every footprint (import-data/stickhub-truth.csv). Imported without
// --origin onto a fixture with a pocket, the top and the bottom land in the
// same pocket: the board's outline fills the pocket's corner either side
// up, and every part is where it is on the board lying there (the bottom
// turned over about the board's own y edge).
TEST(CadImport, BothSidesOfAKicadBoardUseTheSamePocket) {
  const fs::path kicad = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "import-kicad";
  std::istringstream in(test::ReadFileText(kData / "stickhub-truth.csv"));
  std::string line;
  std::getline(in, line);  // "# outline,W,H"
  ASSERT_EQ(line.rfind("# outline,", 0), 0u) << line;
  const double width = std::stod(line.substr(10)), height = std::stod(line.substr(line.rfind(',') + 1));
  std::getline(in, line);  // header
  struct Footprint {
    std::string side;
    double x, y;
  };
  std::map<std::string, Footprint> truth;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::istringstream fields(line);
    for (std::string item; std::getline(fields, item, ',');) f.push_back(item);
    ASSERT_EQ(f.size(), 4u) << line;
    truth[f[0]] = {f[1], std::stod(f[2]), std::stod(f[3])};
  }
  const double pocket_x = 100, pocket_y = 20;  // pocket-cell.toml's pocket, lower left corner
  for (const std::string side : {"top", "bottom"}) {
    SCOPED_TRACE(side);
    ImportOptions options;
    options.side = side == "top" ? cad::Side::kTop : cad::Side::kBottom;
    options.origin_given = false;
    options.board = std::array<double, 4>{0, 0, width, height};
    options.skip_unmapped = true;
    const std::string file = "stickhub_" + side + ".pos";
    Imported r = Import(test::ReadFileText(kicad / file), options, kData / "stickhub-feeders.toml", {}, file,
                        kData / "pocket-cell.toml");
    ASSERT_TRUE(r.program) << r.diagnostics;
    EXPECT_EQ(std::count(r.kinds.begin(), r.kinds.end(), DiagKind::ImportOutlineFromParts), 0) << r.diagnostics;
    std::array<double, 4> origin{};
    std::map<std::string, std::array<double, 4>> placed;
    for (const ir::StmtPtr& stmt : r.program->items) {
      if (const auto* local = std::get_if<ir::LocalDecl>(&stmt->node)) origin = local->origin.values;
      if (const auto* point = std::get_if<ir::PointDecl>(&stmt->node); point != nullptr && point->frame == "Pcb") {
        placed[point->name] = point->coords.values;
      }
    }
    ASSERT_EQ(origin[3], 0.0);
    // The outline as placed: the top view's corners, turned over for the bottom.
    const double sign = side == "top" ? 1 : -1;
    const double corner_x = origin[0] + std::min(0.0, sign * width), corner_y = origin[1];
    EXPECT_NEAR(corner_x, pocket_x, 1e-9);
    EXPECT_NEAR(corner_y, pocket_y, 1e-9);
    std::size_t checked = 0;
    for (const auto& [ref, at] : placed) {
      ASSERT_TRUE(truth.count(ref)) << ref;
      const Footprint& fp = truth[ref];
      EXPECT_EQ(fp.side, side) << ref;
      // Where the part is on the board lying in the pocket.
      const double want_x = pocket_x + (side == "top" ? fp.x : width - fp.x), want_y = pocket_y + fp.y;
      EXPECT_NEAR(origin[0] + at[0], want_x, 1e-4) << ref;
      EXPECT_NEAR(origin[1] + at[1], want_y, 1e-4) << ref;
      ++checked;
    }
    EXPECT_EQ(checked, side == "top" ? 35u : 50u);  // every part of the side (stickhub_*.err: 35 and 50 placed)
  }
}

// A part outside the outline --board gives is an error at its row; without
// --board the parts' bounding box stands for the board, with a warning.
TEST(CadImport, PartsOffTheBoardAndTheOutlineFromTheParts) {
  const fs::path kicad = fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "import-kicad";
  ImportOptions options;
  options.side = cad::Side::kBottom;
  options.origin_given = false;
  options.skip_unmapped = true;
  options.board = std::array<double, 4>{0, 0, 16.6, 20};  // the board is 40.1 mm high
  Imported off = Import(test::ReadFileText(kicad / "stickhub_bottom.pos"), options, kData / "stickhub-feeders.toml", {},
                        "stickhub_bottom.pos", kData / "pocket-cell.toml");
  EXPECT_FALSE(off.program);
  EXPECT_GT(std::count(off.kinds.begin(), off.kinds.end(), DiagKind::ImportPartOffBoard), 5) << off.diagnostics;
  options.board.reset();
  Imported box = Import(test::ReadFileText(kicad / "stickhub_bottom.pos"), options, kData / "stickhub-feeders.toml", {},
                        "stickhub_bottom.pos", kData / "pocket-cell.toml");
  ASSERT_TRUE(box.program) << box.diagnostics;
  EXPECT_EQ(std::count(box.kinds.begin(), box.kinds.end(), DiagKind::ImportOutlineFromParts), 1) << box.diagnostics;
}

TEST(CadImport, FeederMatching) {
  SourceManager sources;
  Diagnostics diags(sources);
  std::uint32_t file = sources.Add("f.toml", R"(
[[feeder]]
name = "Generic0603"
pick = [0, 0, 0, 0]
package = "*0603*"
[[feeder]]
name = "Cap100n"
pick = [1, 0, 0, 0]
package = "C_0603*"
value = "100n"
[[feeder]]
name = "Anything"
pick = [2, 0, 0, 0]
[[feeder]]
name = "Bank"
pick = [3, 0, 0, 0]
package = ["SOT-23", "SOD-123"]
pallet = { last = [4, 0, 0, 0], back = [3, 0, 0, 0], columns = 2, rows = 1 }
[[map]]
feeder = "Anything"
designator = "J*"
[[map]]
feeder = "Bank"
value = "special"
lane = 2
rotation_offset_deg = 45
)");
  (void)file;
  cad::FeedersFile feeders_file;
  {
    // Load through the public door: write the text to a temporary file.
    fs::path path = fs::temp_directory_path() / fmt::format("smtcal_feeders_{}.toml", ::getpid());
    std::ofstream(path) << sources.File(file).text;
    Result<std::optional<cad::FeedersFile>> loaded = cad::LoadFeeders(path.string(), sources, diags);
    fs::remove(path);
    ASSERT_TRUE(loaded.ok() && loaded.value()) << diags.RenderText();
    feeders_file = std::move(*loaded.value());
  }
  std::optional<cad::FeederTable> table = cad::FeederTable::Build({}, std::move(feeders_file), diags);
  ASSERT_TRUE(table) << diags.RenderText();
  EXPECT_TRUE(table->matches_designators());
  auto find = [&](std::string designator, std::string value, std::string package) -> std::string {
    cad::Row row;
    row.designator = designator;
    row.value = value;
    row.package = package;
    std::optional<cad::FeederMatch> match = table->Find(row);
    if (!match) return "-";
    std::string text = table->feeders()[match->feeder].name;
    if (match->lane) text += fmt::format(":{}", *match->lane);
    if (match->rotation_offset_deg != 0) text += fmt::format("@{}", match->rotation_offset_deg);
    return text;
  };
  EXPECT_EQ(find("C1", "100n", "C_0603_1608Metric"), "Cap100n");      // package and value beat package alone
  EXPECT_EQ(find("C2", "10n", "C_0603_1608Metric"), "Generic0603");   // the value does not match Cap100n
  EXPECT_EQ(find("R1", "10k", "r_0603"), "Generic0603");              // globs ignore case
  EXPECT_EQ(find("L1", "1u", "L_1210"), "-");                         // a feeder without package/value is not "any"
  EXPECT_EQ(find("J1", "Conn", "L_1210"), "Anything");                // ... but a [[map]] reaches it
  EXPECT_EQ(find("J2", "100n", "C_0603"), "Anything");                // a [[map]] wins over the packages
  EXPECT_EQ(find("D1", "1N4148", "SOD-123"), "Bank:2");               // bank lanes: one package per pick point
  EXPECT_EQ(find("Q1", "BC847", "SOT-23"), "Bank:1");
  EXPECT_EQ(find("Q2", "special", "SOT-23"), "Bank:2@45");            // the rule's lane and offset
}

TEST(CadImport, NamesAreValidAndNeverKeywords) {
  EXPECT_EQ(MakeIdentifier("R1"), "R1");
  EXPECT_EQ(MakeIdentifier("R-1.2"), "R_1_2");
  EXPECT_EQ(MakeIdentifier("1R"), "_1R");
  EXPECT_EQ(MakeIdentifier("C\xCE\xA9" "2"), "C_2");
  EXPECT_EQ(MakeIdentifier(""), "_");
  EXPECT_EQ(MakeIdentifier("ringLight-top_pos"), "ringLight_top_pos");
  // Every keyword, in any case, becomes a name the parser takes.
  for (std::string keyword : {"And", "call", "CYCLE", "Else", "ElseIf", "EndCycle", "EndIf", "Exit", "Fend",
                              "Fixture", "For", "Function", "Go", "If", "In", "Integer", "Jump", "LimZ", "Local",
                              "Mod", "Move", "Next", "Not", "Off", "On", "Or", "Pallet", "Pick", "Place", "Point",
                              "Program", "Real", "Scan", "Step", "Sw", "Taught", "Then", "To", "Units", "Vacuum",
                              "Wait", "Xor", "XY"}) {
    std::string name = MakeIdentifier(keyword);
    EXPECT_NE(name, keyword);
    test::ParsedText parsed = test::ParseText(fmt::format("Program T\nUnits mm\nPoint {} = XY(0, 0, 0, 0)\n", name));
    EXPECT_TRUE(parsed.ok()) << keyword << ": " << parsed.diagnostics;
    // ... and the keyword itself would not parse as a name.
    EXPECT_FALSE(test::ParseText(fmt::format("Program T\nUnits mm\nPoint {} = XY(0, 0, 0, 0)\n", keyword)).ok())
        << keyword;
  }
}

// Every row of a random list ends as a placement, a skipped row the summary
// names (its group warned once), or an error at its line.
TEST(CadImportProperty, EveryRowIsPlacedOrReported) {
  const std::vector<std::string> packages = {"C_0603_1608Metric", "R_0603_1608Metric", "SOIC-8", "L_1210",
                                             "Fiducial_1mm"};
  const std::vector<std::string> values = {"100n", "10k", "DNP", "NE555", "10uH"};
  for (int k = 0; k < 40; ++k) {
    const std::uint64_t seed = BaseSeed() + 7000 + static_cast<std::uint64_t>(k);
    SCOPED_TRACE(fmt::format("seed {}", seed));
    std::mt19937_64 rng(seed);
    std::string list = kHeader;
    int rows = std::uniform_int_distribution<int>(1, 40)(rng);
    for (int i = 0; i < rows; ++i) {
      auto pick = [&](const std::vector<std::string>& from) {
        return from[std::uniform_int_distribution<std::size_t>(0, from.size() - 1)(rng)];
      };
      bool broken = std::uniform_int_distribution<int>(0, 9)(rng) == 0;
      list += fmt::format("X{},{},{},{},{},{},{}\n", i, pick(values), pick(packages), broken ? "oops" : "1.5",
                          i, std::uniform_int_distribution<int>(-400, 400)(rng),
                          std::uniform_int_distribution<int>(0, 3)(rng) == 0 ? "bottom" : "top");
    }
    ImportOptions options;
    options.side = cad::Side::kTop;
    options.skip_unmapped = true;
    // Keep the tray from running out: SOIC parts beyond 8 are an error of
    // their own, counted below like any other.
    Imported r = Import(list, options, kData / "feeders.toml");
    std::size_t skipped = 0;
    for (std::size_t n : r.summary.skipped) skipped += n;
    // Skipped rows give one warning per group (reason and rule), at its
    // first row, and the summary's groups name every skipped row once; a
    // bad number is an error of its own row.
    std::size_t skip_warnings = 0, bad_numbers = 0;
    for (DiagKind kind : r.kinds) {
      if (kind == DiagKind::ImportSkippedSide || kind == DiagKind::ImportSkippedDnp ||
          kind == DiagKind::ImportExcluded || kind == DiagKind::ImportSkippedUnmapped) {
        ++skip_warnings;
      }
      bad_numbers += kind == DiagKind::CadBadNumber;
    }
    std::size_t named = 0;
    std::set<std::string> names;
    for (const SkipGroup& group : r.summary.skip_groups) {
      named += group.names.size();
      names.insert(group.names.begin(), group.names.end());
    }
    EXPECT_EQ(r.summary.rows_read, static_cast<std::size_t>(rows));
    EXPECT_EQ(skip_warnings, r.summary.skip_groups.size()) << r.diagnostics;
    EXPECT_EQ(named, skipped) << r.diagnostics;
    EXPECT_EQ(names.size(), skipped) << "a row named twice\n" << r.diagnostics;
    EXPECT_EQ(bad_numbers, r.summary.rows_with_errors) << r.diagnostics;
    if (r.program) {
      EXPECT_EQ(r.summary.parts_placed + skipped + r.summary.rows_with_errors, static_cast<std::size_t>(rows));
      EXPECT_EQ(static_cast<std::size_t>(std::count(r.text.begin(), r.text.end(), '\n')) > 0, true);
    } else {
      EXPECT_TRUE(r.summary.failed);
    }
  }
}

}  // namespace
}  // namespace smtcal

namespace smtcal {
namespace {

// The command line: usage errors exit 2 before any file is read, a file
// that cannot be read exits 3, and nothing is written on errors.
TEST(CadImportCli, UsageAndIoErrors) {
  const std::string data = (kData).string();
  const std::string cell = "--cell '" + data + "/cell.toml'";
  const std::string board = "'" + data + "/board.csv'";
  test::SmtcalRun run = test::RunSmtcal("import " + board + " " + cell + " -o - --format csv");
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("--format csv needs --columns"), std::string::npos) << run.err;
  run = test::RunSmtcal("import " + board + " " + cell + " -o - --columns designator=Ref,x=PosX,y=PosY");
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("--columns is for --format csv"), std::string::npos) << run.err;
  run = test::RunSmtcal("import " + board + " " + cell + " -o - --format csv --columns designator=Ref,x=PosX");
  EXPECT_EQ(run.exit_code, 2) << run.err;
  run = test::RunSmtcal("import " + board + " " + cell + " -o - --origin 5");
  EXPECT_EQ(run.exit_code, 2) << run.err;
  run = test::RunSmtcal("import " + board + " " + cell + " -o - --panel 0x2");
  EXPECT_EQ(run.exit_code, 2) << run.err;
  run = test::RunSmtcal("import " + board + " " + cell + " -o - --rotation 400");
  EXPECT_EQ(run.exit_code, 2) << run.err;
  run = test::RunSmtcal("import /nonexistent/list.csv " + cell + " -o -");
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find("cannot open '/nonexistent/list.csv'"), std::string::npos) << run.err;
  run = test::RunSmtcal("import " + board + " " + cell + " --feeders /nonexistent/f.toml -o -");
  EXPECT_EQ(run.exit_code, 3) << run.err;

  // Success writes the file atomically; an error leaves an existing output alone.
  fs::path out = fs::temp_directory_path() / fmt::format("smtcal_import_{}.place", ::getpid());
  run = test::RunSmtcal("import " + board + " " + cell + " -o '" + out.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::string written = test::ReadFileText(out);
  EXPECT_NE(written.find("Program smtcal_import_"), std::string::npos) << written;
  run = test::RunSmtcal("import " + board + " " + cell + " --fixture Nope -o '" + out.string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(test::ReadFileText(out), written);
  // The same inputs give the same bytes.
  run = test::RunSmtcal("import " + board + " " + cell + " -o -");
  std::string again = test::RunSmtcal("import " + board + " " + cell + " -o -").out;
  EXPECT_EQ(run.out, again);
  fs::remove(out);
}

}  // namespace
}  // namespace smtcal
