// Tests of `smtcal diff`: the statement alignment (backend/diff/program_diff.h
// Align), the diff of two parsed programs (matching by name and position,
// displacements in each frame), and the command's exit codes and SVG. The
// review text and JSON are golden tests (tests/golden/diff/).
//
// The alignment property test prints its seed; set SMTCAL_TEST_SEED to vary it.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "backend/diff/diff_report.h"
#include "backend/diff/program_diff.h"
#include "frontend/parse.h"
#include "passes/pass_manager.h"
#include "tests/unit/json_walk.h"
#include "tests/unit/test_support.h"

namespace smtcal::diff {
namespace {

// ------------------------------------------------------------------ Align

std::size_t Matches(const std::vector<Aligned>& alignment) {
  std::size_t n = 0;
  for (const Aligned& a : alignment) n += a.old_index != Aligned::npos && a.new_index != Aligned::npos;
  return n;
}

// Every index of both sides exactly once, in increasing order, and matched
// elements have equal signatures.
void ExpectValid(const std::vector<Aligned>& alignment, const std::vector<std::string>& a,
                 const std::vector<std::string>& b) {
  std::size_t next_a = 0, next_b = 0;
  for (const Aligned& pair : alignment) {
    if (pair.old_index != Aligned::npos) { ASSERT_EQ(pair.old_index, next_a++); }
    if (pair.new_index != Aligned::npos) { ASSERT_EQ(pair.new_index, next_b++); }
    if (pair.old_index != Aligned::npos && pair.new_index != Aligned::npos) {
      ASSERT_EQ(a[pair.old_index], b[pair.new_index]);
    }
  }
  EXPECT_EQ(next_a, a.size());
  EXPECT_EQ(next_b, b.size());
}

std::size_t LcsLength(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  std::vector<std::vector<std::size_t>> l(a.size() + 1, std::vector<std::size_t>(b.size() + 1, 0));
  for (std::size_t i = a.size(); i-- > 0;) {
    for (std::size_t j = b.size(); j-- > 0;) {
      l[i][j] = a[i] == b[j] ? l[i + 1][j + 1] + 1 : std::max(l[i + 1][j], l[i][j + 1]);
    }
  }
  return l[0][0];
}

TEST(DiffAlign, InsertedPickDoesNotShiftTheOthers) {
  // Old: Pick a, Place R1, Pick b, Place R2. New inserts "Pick c, Place R9"
  // after R1. All Picks share a signature; only their positions tell them apart.
  std::vector<std::string> a = {"pick xy", "place r1", "pick xy", "place r2"};
  std::vector<std::string> b = {"pick xy", "place r1", "pick xy", "place r9", "pick xy", "place r2"};
  std::vector<double> old_x = {160, 0, 170, 0};
  std::vector<double> new_x = {160, 0, 190, 0, 170.002, 0};
  auto similarity = [&](std::size_t i, std::size_t j) {
    return old_x[i] == new_x[j] ? 1.0 : 0.9 / (1 + std::fabs(old_x[i] - new_x[j]));
  };
  std::vector<Aligned> alignment = Align(a, b, similarity);
  ExpectValid(alignment, a, b);
  ASSERT_EQ(Matches(alignment), 4u);
  // Pick b (old 2) goes with the Pick 2 µm away (new 4), not the one inserted.
  bool found = false;
  for (const Aligned& pair : alignment) {
    if (pair.old_index == 2) {
      EXPECT_EQ(pair.new_index, 4u);
      found = true;
    }
    if (pair.new_index == 2) { EXPECT_EQ(pair.old_index, Aligned::npos); }
    if (pair.new_index == 3) { EXPECT_EQ(pair.old_index, Aligned::npos); }
  }
  EXPECT_TRUE(found);
}

TEST(DiffAlign, IdenticalSequencesMatchOneToOne) {
  std::vector<std::string> a = {"x", "y", "x", "z"};
  std::vector<Aligned> alignment = Align(a, a, [](std::size_t, std::size_t) { return 1.0; });
  ASSERT_EQ(alignment.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(alignment[i].old_index, i);
    EXPECT_EQ(alignment[i].new_index, i);
  }
}

TEST(DiffAlign, EmptySides) {
  std::vector<std::string> none, some = {"a", "b"};
  auto one = [](std::size_t, std::size_t) { return 1.0; };
  EXPECT_TRUE(Align(none, none, one).empty());
  std::vector<Aligned> added = Align(none, some, one);
  ASSERT_EQ(added.size(), 2u);
  EXPECT_EQ(added[0].old_index, Aligned::npos);
  std::vector<Aligned> removed = Align(some, none, one);
  ASSERT_EQ(removed.size(), 2u);
  EXPECT_EQ(removed[1].new_index, Aligned::npos);
}

// Beyond kDiffMaxAlignCells the middle goes to Myers' algorithm: still a
// longest common subsequence.
TEST(DiffAlign, LargeMiddleUsesMyersAndStaysOptimal) {
  std::vector<std::string> a, b;
  for (int i = 0; i < 3000; ++i) a.push_back(fmt::format("s{}", i % 7));
  b = a;
  b.erase(b.begin() + 1000);                        // a removal
  b.insert(b.begin() + 2000, "new statement");      // an addition
  b[1] = "changed";                                 // a change near the start (defeats the prefix)
  b[b.size() - 2] = "changed too";                  // and near the end (defeats the suffix)
  std::vector<Aligned> alignment = Align(a, b, [](std::size_t, std::size_t) { return 0.75; });
  ExpectValid(alignment, a, b);
  EXPECT_EQ(Matches(alignment), a.size() - 3);
}

// Beyond kDiffMaxEditDistance edits Myers gives up: the rest is removed, then added.
TEST(DiffAlign, TooManyEditsReportEverythingRemovedThenAdded) {
  std::vector<std::string> a, b;
  for (int i = 0; i < 2500; ++i) {
    a.push_back(fmt::format("old {}", i));
    b.push_back(fmt::format("new {}", i));
  }
  std::vector<Aligned> alignment = Align(a, b, [](std::size_t, std::size_t) { return 1.0; });
  ExpectValid(alignment, a, b);
  ASSERT_EQ(alignment.size(), 5000u);
  EXPECT_EQ(alignment[2499].new_index, Aligned::npos);
  EXPECT_EQ(alignment[2500].old_index, Aligned::npos);
}

// The fallback does not slide a run of Picks from one feeder past an inserted
// pair: places far apart are not alike, so the insertion stays where it is.
TEST(DiffAlign, LargeMiddleKeepsAnInsertionInPlace) {
  std::vector<std::string> a, b;
  std::vector<double> ax, bx;
  for (int i = 0; i < 2000; ++i) {
    if (i == 1000) {
      b.insert(b.end(), {"pick xy", "place xy"});
      bx.insert(bx.end(), {200, 170});
    }
    a.insert(a.end(), {"pick xy", "place xy"});
    b.insert(b.end(), {"pick xy", "place xy"});
    ax.insert(ax.end(), {200, 150 + 0.5 * (i % 100)});
    bx.insert(bx.end(), {200.001, 150.001 + 0.5 * (i % 100)});  // every target moved 1 µm: no identical prefix
  }
  auto similarity = [&](std::size_t i, std::size_t j) { return 0.9 / (1 + std::fabs(ax[i] - bx[j]) / 0.25); };
  std::vector<Aligned> alignment = Align(a, b, similarity);
  ExpectValid(alignment, a, b);
  EXPECT_EQ(Matches(alignment), a.size());
  for (const Aligned& pair : alignment) {
    if (pair.old_index != Aligned::npos && pair.new_index != Aligned::npos) {
      EXPECT_LT(std::fabs(ax[pair.old_index] - bx[pair.new_index]), 0.01) << pair.old_index << " " << pair.new_index;
    }
  }
}

TEST(DiffAlign, RandomSequencesGiveALongestCommonSubsequence) {
  const char* text = std::getenv("SMTCAL_TEST_SEED");
  const std::uint64_t seed = text != nullptr ? std::strtoull(text, nullptr, 10) : 20261121;
  std::mt19937_64 rng(seed);
  for (int round = 0; round < 200; ++round) {
    std::vector<std::string> a, b;
    int n = static_cast<int>(rng() % 30), m = static_cast<int>(rng() % 30);
    for (int i = 0; i < n; ++i) a.push_back(std::string(1, static_cast<char>('a' + rng() % 4)));
    for (int j = 0; j < m; ++j) b.push_back(std::string(1, static_cast<char>('a' + rng() % 4)));
    std::vector<double> sims;
    for (int k = 0; k < n * m; ++k) sims.push_back(static_cast<double>(rng() % 3) / 2);
    auto similarity = [&](std::size_t i, std::size_t j) { return sims[i * static_cast<std::size_t>(m) + j]; };
    std::vector<Aligned> alignment = Align(a, b, similarity);
    SCOPED_TRACE(fmt::format("seed {} round {}", seed, round));
    ExpectValid(alignment, a, b);
    EXPECT_EQ(Matches(alignment), LcsLength(a, b));
  }
}

// ------------------------------------------------------------------ DiffPrograms

// Two program texts through the parser and the checks, then the diff.
struct DiffRun {
  SourceManager sources;
  std::unique_ptr<Diagnostics> diags;
  ir::Program old_program, new_program;
  ProgramDiff diff;
};

std::unique_ptr<DiffRun> RunDiff(const std::string& old_text, const std::string& new_text,
                                 double threshold_um = 10) {
  auto run = std::make_unique<DiffRun>();
  std::uint32_t a = run->sources.Add("old.place", old_text);
  std::uint32_t b = run->sources.Add("new.place", new_text);
  run->diags = std::make_unique<Diagnostics>(run->sources);
  run->old_program = ParseProgram(a, *run->diags);
  run->new_program = ParseProgram(b, *run->diags);
  std::vector<const PassInfo*> checks;
  for (const PassInfo& info : PassRegistry()) checks.push_back(&info);
  RunPasses(run->old_program, *run->diags, checks, false);
  RunPasses(run->new_program, *run->diags, checks, false);
  EXPECT_FALSE(run->diags->has_errors()) << run->diags->RenderText();
  DiffOptions options;
  options.threshold_um = threshold_um;
  run->diff = DiffPrograms(run->old_program, run->new_program, options, *run->diags);
  return run;
}

const char* kProgram = R"(Program T
Units mm
Fixture Board
Vacuum 8
Local Layer = XY(10.0, 20.0, 0.0, 0.0) In Board
Local Tray = XY(300.0, 150.0, 0.0, 90.0)
Point Feed = XY(160.0, 10.0, -12.0, 0.0)
Point R1 = XY(5.0, 7.0, -3.0, 0.0) In Layer
Point S1 = XY(1.0, 2.0, -4.0, 0.0) In Tray

Function Main
  Cycle Board
    Pick Feed
    Place R1
  EndCycle
  Jump S1
Fend
)";

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

const Change* Find(const ProgramDiff& diff, const std::string& what) {
  for (const Change& c : diff.changes) {
    if (c.what == what) return &c;
  }
  return nullptr;
}

TEST(DiffPrograms, CommentsCaseAndLayoutAreNoChange) {
  std::string reformatted = Replace(kProgram, "    Place R1\n", "    PLACE r1   ' the resistor\n");
  reformatted = Replace(reformatted, "Point Feed = XY(160.0, 10.0, -12.0, 0.0)", "point FEED = XY(160, 10, -12, 0)");
  auto run = RunDiff(kProgram, reformatted);
  EXPECT_TRUE(run->diff.changes.empty()) << FormatDiffText(run->diff);
  EXPECT_TRUE(run->diff.summary.gate_passes());
  EXPECT_EQ(run->diff.summary.targets_compared, 6u);  // Feed, R1, S1 and three motions
}

TEST(DiffPrograms, MovedPointInItsFrameAndInTheRoot) {
  auto run = RunDiff(kProgram, Replace(kProgram, "XY(5.0, 7.0, -3.0, 0.0) In Layer", "XY(5.003, 6.996, -3.0, 0.0) In Layer"));
  const Change* point = Find(run->diff, "point R1");
  ASSERT_NE(point, nullptr);
  EXPECT_EQ(point->kind, ChangeKind::kMoved);
  ASSERT_EQ(point->moves.size(), 2u);  // in Layer, in Board
  EXPECT_EQ(point->moves[0].frame, "Layer");
  EXPECT_EQ(point->moves[1].frame, "Board");
  EXPECT_NEAR(point->moves[0].dx_um, 3, 1e-6);
  EXPECT_NEAR(point->moves[0].dy_um, -4, 1e-6);
  EXPECT_NEAR(point->moves[0].d_um, 5, 1e-6);
  EXPECT_NEAR(point->moves[0].direction_deg, std::atan2(-4.0, 3.0) * 180 / M_PI, 1e-9);
  EXPECT_FALSE(point->beyond_threshold);
  // The Place that uses it moved with it.
  const Change* place = Find(run->diff, "Place R1");
  ASSERT_NE(place, nullptr);
  EXPECT_EQ(place->function, "Main");
  EXPECT_NEAR(place->gate_um, 5, 1e-6);
  EXPECT_TRUE(run->diff.summary.gate_passes());
  EXPECT_EQ(run->diff.summary.targets_moved, 2u);
}

TEST(DiffPrograms, RotatedLocalTurnsTheMoveIntoTheBaseFrame) {
  // S1 moves +10 µm along Tray's x axis; Tray is turned 90°, so in the robot
  // base frame it moves +10 µm along y.
  auto run = RunDiff(kProgram, Replace(kProgram, "XY(1.0, 2.0, -4.0, 0.0) In Tray", "XY(1.01, 2.0, -4.0, 0.0) In Tray"), 5);
  const Change* point = Find(run->diff, "point S1");
  ASSERT_NE(point, nullptr);
  ASSERT_EQ(point->moves.size(), 2u);
  EXPECT_EQ(point->moves[1].frame, "robot base");
  EXPECT_NEAR(point->moves[1].dx_um, 0, 1e-6);
  EXPECT_NEAR(point->moves[1].dy_um, 10, 1e-6);
  EXPECT_TRUE(point->beyond_threshold);
  EXPECT_FALSE(run->diff.summary.gate_passes());
}

TEST(DiffPrograms, MovedFrameMovesItsPointsButNotTheirCoordinates) {
  auto run = RunDiff(kProgram, Replace(kProgram, "Local Layer = XY(10.0, 20.0,", "Local Layer = XY(10.0, 20.05,"));
  const Change* point = Find(run->diff, "point R1");
  ASSERT_NE(point, nullptr);
  EXPECT_NEAR(point->moves[0].d_um, 0, 1e-9);   // in Layer: unchanged
  EXPECT_NEAR(point->moves[1].dy_um, 50, 1e-6);  // in Board: 50 µm
  EXPECT_TRUE(point->beyond_threshold);
}

TEST(DiffPrograms, InsertedPickPlacePairIsAdded) {
  std::string more = Replace(kProgram, "    Place R1\n", "    Place R1\n    Pick Feed\n    Place R1 + Y(2.0)\n");
  auto run = RunDiff(kProgram, more);
  EXPECT_EQ(run->diff.summary.added, 2u);
  EXPECT_EQ(run->diff.summary.removed, 0u);
  EXPECT_EQ(run->diff.summary.targets_moved, 0u) << FormatDiffText(run->diff);
  EXPECT_FALSE(run->diff.summary.gate_passes());
  ASSERT_EQ(run->diff.changes.size(), 2u);
  EXPECT_EQ(run->diff.changes[0].new_side.loc.line, 15u);
  EXPECT_EQ(run->diff.changes[1].what, "Place R1 + Y(2.0)");
}

TEST(DiffPrograms, ChangedNonCoordinateIsChangedNotMoved) {
  auto run = RunDiff(kProgram, Replace(kProgram, "    Place R1\n", "    Place R1 LimZ -1.0\n"));
  ASSERT_EQ(run->diff.changes.size(), 1u);
  EXPECT_EQ(run->diff.changes[0].kind, ChangeKind::kChanged);
  EXPECT_EQ(run->diff.changes[0].old_side.text, "Place R1");
  EXPECT_EQ(run->diff.summary.changed, 1u);
}

TEST(DiffPrograms, DifferentRunTimeOffsetsCannotBeCompared) {
  std::string with_var = Replace(kProgram, "Function Main\n", "Real dx\n\nFunction Main\n");
  auto run = RunDiff(Replace(with_var, "    Place R1\n", "    Place R1 + X(dx)\n"),
                     Replace(with_var, "    Place R1\n", "    Place R1 + X(2 * dx)\n"));
  const Change* place = Find(run->diff, "Place R1 + X(2 * dx)");
  ASSERT_NE(place, nullptr);
  EXPECT_EQ(place->kind, ChangeKind::kChanged);
  EXPECT_TRUE(place->moves.empty());
  EXPECT_EQ(run->diff.summary.not_comparable, 1u);
}

TEST(DiffPrograms, OutputIsDeterministic) {
  std::string moved = Replace(kProgram, "XY(160.0, 10.0,", "XY(160.02, 10.01,");
  auto first = RunDiff(kProgram, moved);
  auto second = RunDiff(kProgram, moved);
  EXPECT_EQ(FormatDiffText(first->diff), FormatDiffText(second->diff));
  EXPECT_EQ(FormatDiffJson(first->diff), FormatDiffJson(second->diff));
  std::string svg = PlotDiffSvg(first->diff);
  EXPECT_EQ(svg, PlotDiffSvg(second->diff));
  EXPECT_EQ(svg.rfind("<svg ", 0), 0u);
  EXPECT_NE(svg.find("times enlarged"), std::string::npos);
}

// ------------------------------------------------------------------ JSON and SVG

// The decimals a JSON number is written with ("2.9e-05" has 6).
int Decimals(const nlohmann::json& number) {
  const std::string text = number.dump();
  const std::size_t e = text.find_first_of("eE");
  const std::string mantissa = text.substr(0, e);
  const std::size_t dot = mantissa.find('.');
  int decimals = dot == std::string::npos ? 0 : static_cast<int>(mantissa.size() - dot - 1);
  if (e != std::string::npos) decimals -= std::stoi(text.substr(e + 1));
  return std::max(decimals, 0);
}

TEST(DiffJson, NumbersCarryTheirDecimalsOnly) {
  // R1 moves 1 mm back along x and 0.274 µm up: toward 179.9843° (as
  // 1799843 * 1e-4 the double is 179.98430000000002).
  auto run = RunDiff(kProgram, Replace(kProgram, "XY(5.0, 7.0, -3.0, 0.0) In Layer",
                                       "XY(4.0, 7.000274, -3.0, 0.05) In Layer"));
  const nlohmann::json json = nlohmann::json::parse(FormatDiffJson(run->diff));
  int numbers = 0;
  test::ForEachNumber(json, "", [&](const std::string& key, const nlohmann::json& number) {
    ++numbers;
    EXPECT_LE(Decimals(number), key == "du_deg" ? 7 : 4) << key << " " << number.dump();
  });
  EXPECT_GT(numbers, 10);
  EXPECT_NE(FormatDiffJson(run->diff).find("\"direction_deg\": 179.9843\n"), std::string::npos)
      << FormatDiffJson(run->diff);
}

// R1's Place depends on a run-time offset: compared, but not drawn.
std::unique_ptr<DiffRun> RunTimeOffsetDiff() {
  std::string with_var = Replace(kProgram, "Function Main\n", "Real dx\n\nFunction Main\n");
  with_var = Replace(with_var, "    Place R1\n", "    Place R1 + X(dx)\n");
  return RunDiff(with_var, Replace(with_var, "XY(160.0, 10.0,", "XY(160.02, 10.01,"));
}

TEST(DiffSvg, CountsAgreeWithTheTextAndJson) {
  auto run = RunTimeOffsetDiff();
  const std::size_t compared = nlohmann::json::parse(FormatDiffJson(run->diff))["summary"]["targets_compared"];
  ASSERT_EQ(compared, 6u);  // Feed, R1, S1, Pick, Place, Jump
  EXPECT_NE(FormatDiffText(run->diff).find("6 targets compared"), std::string::npos);
  const std::string svg = PlotDiffSvg(run->diff);
  EXPECT_NE(svg.find(">6 targets compared (as in the text report): 4 in the robot base frame, 1 in the fixture "
                     "Board's frame, 1 not drawn</text>"),
            std::string::npos)
      << svg;
  // Each panel's count is of the same targets, and they add up.
  const std::regex panel_count(R"(>(\d+) of the (\d+) compared targets)");
  std::size_t drawn = 0, panels = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), panel_count); it != std::sregex_iterator(); ++it) {
    EXPECT_EQ(std::stoul((*it)[2]), compared);
    drawn += std::stoul((*it)[1]);
    ++panels;
  }
  EXPECT_EQ(panels, 2u);
  EXPECT_EQ(drawn + 1, compared);
}

TEST(DiffSvg, PanelsNameTheirFrameAndTickInMillimetres) {
  auto run = RunTimeOffsetDiff();
  const std::string svg = PlotDiffSvg(run->diff);
  EXPECT_NE(svg.find(">robot base frame, mm</text>"), std::string::npos) << svg;
  EXPECT_NE(svg.find(">fixture Board's frame, mm</text>"), std::string::npos);
  std::size_t x_labels = 0, y_labels = 0;
  for (std::size_t at = svg.find(">x (mm)</text>"); at != std::string::npos; at = svg.find(">x (mm)</text>", at + 1)) {
    ++x_labels;
  }
  for (std::size_t at = svg.find(">y (mm)</text>"); at != std::string::npos; at = svg.find(">y (mm)</text>", at + 1)) {
    ++y_labels;
  }
  EXPECT_EQ(x_labels, 2u);
  EXPECT_EQ(y_labels, 2u);
  // Round ticks: in the base panel (Feed at x 160, S1 at 298) every 25 mm.
  for (const char* tick : {">150</text>", ">175</text>", ">275</text>", ">300</text>"}) {
    EXPECT_NE(svg.find(tick), std::string::npos) << tick << "\n" << svg;
  }
}

// Eight neighbouring targets 1 mm apart all move; the labels of the five
// largest must stay inside the frame and off each other.
TEST(DiffSvg, LabelsStayInsideTheFrameAndApart) {
  std::string points, moved, uses;
  for (int k = 0; k < 8; ++k) {
    points += fmt::format("Point P{} = XY({}.0, 10.0, -3.0, 0.0)\n", k, 100 + k);
    moved += fmt::format("Point P{} = XY({}, {}, -3.0, 0.0)\n", k, 100 + k + 0.01 + 0.002 * k, 10.0 + 0.01);
    uses += fmt::format("  Jump P{}\n", k);
  }
  const std::string head = "Program L\nUnits mm\nPoint Far = XY(300.0, 200.0, -3.0, 0.0)\n";
  const std::string tail = "\nFunction Main\n" + uses + "  Jump Far\nFend\n";
  auto run = RunDiff(head + points + tail, head + moved + tail);
  const std::string svg = PlotDiffSvg(run->diff);
  const std::regex frame_re(
      R"re(<rect x="([\d.]+)" y="([\d.]+)" width="([\d.]+)" height="([\d.]+)" fill="none" stroke="#999"/>)re");
  std::smatch frame;
  ASSERT_TRUE(std::regex_search(svg, frame, frame_re)) << svg;
  const double fx = std::stod(frame[1]), fy = std::stod(frame[2]);
  const double fw = std::stod(frame[3]), fh = std::stod(frame[4]);
  // The label boxes as the plot estimates them: 0.56 em per character, the
  // anchor at the start, middle or end.
  struct Box {
    double x0, y0, x1, y1;
  };
  std::vector<Box> boxes;
  const std::regex label_re(
      R"re(<text x="([\d.]+)" y="([\d.]+)" font-size="11"(?: text-anchor="(end|middle)")?>([^<]*)</text>)re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), label_re); it != std::sregex_iterator(); ++it) {
    const std::string text = (*it)[4];
    std::size_t chars = 0;
    for (unsigned char c : text) chars += (c & 0xC0) != 0x80;
    const double width = 0.56 * 11 * static_cast<double>(chars);
    const double x = std::stod((*it)[1]), y = std::stod((*it)[2]);
    const std::string anchor = (*it)[3];
    const double x0 = anchor == "end" ? x - width : anchor == "middle" ? x - width / 2 : x;
    boxes.push_back({x0, y - 9, x0 + width, y + 2});
  }
  ASSERT_EQ(boxes.size(), 5u) << svg;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i];
    EXPECT_TRUE(b.x0 >= fx && b.x1 <= fx + fw && b.y0 >= fy && b.y1 <= fy + fh) << "label " << i << " leaves the frame";
    for (std::size_t j = 0; j < i; ++j) {
      const Box& o = boxes[j];
      EXPECT_FALSE(b.x0 < o.x1 && o.x0 < b.x1 && b.y0 < o.y1 && o.y0 < b.y1) << "labels " << j << " and " << i;
    }
  }
}

// Moves of 10 µm among targets 1 mm apart: the arrows are enlarged so the
// longest stays within 0.6 of that spacing (and 0.12 of the panel), not
// the panel's span alone (which would draw them 20 mm long).
TEST(DiffSvg, ArrowsStayWithinTheTargetsSpacing) {
  std::string points, moved, uses;
  for (int k = 0; k < 8; ++k) {
    points += fmt::format("Point P{} = XY({}.0, 10.0, -3.0, 0.0)\n", k, 100 + k);
    moved += fmt::format("Point P{} = XY({}, 10.0, -3.0, 0.0)\n", k, 100 + k + 0.01);
    uses += fmt::format("  Jump P{}\n", k);
  }
  const std::string head = "Program L\nUnits mm\nPoint Far = XY(300.0, 200.0, -3.0, 0.0)\n";
  const std::string tail = "\nFunction Main\n" + uses + "  Jump Far\nFend\n";
  auto run = RunDiff(head + points + tail, head + moved + tail);
  const std::string svg = PlotDiffSvg(run->diff);
  const std::regex stated(R"(the longest, 10\.0 µm, is drawn ([\d.]+) mm long, within 0\.6 of the targets' median spacing \(([\d.]+) mm\))");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(svg, match, stated)) << svg;
  const double drawn_mm = std::stod(match[1]), spacing_mm = std::stod(match[2]);
  EXPECT_DOUBLE_EQ(spacing_mm, 1.0);
  EXPECT_LE(drawn_mm, 0.6 * spacing_mm);
  EXPECT_GE(drawn_mm, 0.6 * spacing_mm / 2.5);  // the round factor is at most 2.5 below the limit
}

// ------------------------------------------------------------------ the command

namespace fs = std::filesystem;

fs::path GoldenDir() { return fs::path(SMTCAL_SOURCE_DIR) / "tests" / "golden" / "diff"; }

TEST(DiffCommand, GateFailureExitsOneAndExitZeroReportsOnly) {
  test::SmtcalRun gate = test::RunSmtcal("diff threshold_default.place new/threshold_default.place", GoldenDir());
  EXPECT_EQ(gate.exit_code, 1) << gate.err;
  EXPECT_NE(gate.out.find("gate: failed"), std::string::npos);
  EXPECT_EQ(gate.err, "");  // a failed gate is a verdict, not a diagnostic
  test::SmtcalRun wider =
      test::RunSmtcal("diff --threshold 25 threshold_default.place new/threshold_default.place", GoldenDir());
  EXPECT_EQ(wider.exit_code, 0) << wider.err;
  test::SmtcalRun added = test::RunSmtcal("diff added_removed.place new/added_removed.place", GoldenDir());
  EXPECT_EQ(added.exit_code, 1) << "added and removed statements fail the gate";
  test::SmtcalRun report =
      test::RunSmtcal("diff --exit-zero added_removed.place new/added_removed.place", GoldenDir());
  EXPECT_EQ(report.exit_code, 0);
  EXPECT_EQ(report.out, added.out);
}

TEST(DiffCommand, UsageAndIoErrors) {
  EXPECT_EQ(test::RunSmtcal("diff moved.place", GoldenDir()).exit_code, 2);
  EXPECT_EQ(test::RunSmtcal("diff --threshold -1 moved.place new/moved.place", GoldenDir()).exit_code, 2);
  EXPECT_EQ(test::RunSmtcal("diff - -", GoldenDir()).exit_code, 2);
  test::SmtcalRun missing = test::RunSmtcal("diff moved.place new/no-such-file.place", GoldenDir());
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_EQ(missing.out, "");
}

TEST(DiffCommand, SvgIsWrittenBesideTheReport) {
  fs::path svg = fs::temp_directory_path() / fmt::format("smtcal_diff_test_{}.svg", ::getpid());
  test::SmtcalRun run = test::RunSmtcal(
      fmt::format("diff --exit-zero --svg '{}' moved_frame.place new/moved_frame.place", svg.string()), GoldenDir());
  EXPECT_EQ(run.exit_code, 0) << run.err;
  std::string text = test::ReadFileText(svg);
  EXPECT_EQ(text.rfind("<svg ", 0), 0u);
  EXPECT_NE(text.find("panel: Board"), std::string::npos);       // no --cell: the fixture's own frame
  EXPECT_NE(text.find("panel: robot base"), std::string::npos);
  EXPECT_NE(run.out.find("gate: failed"), std::string::npos);
  fs::remove(svg);
  test::SmtcalRun unwritable = test::RunSmtcal(
      "diff --svg /no-such-dir/x.svg moved.place new/moved.place", GoldenDir());
  EXPECT_EQ(unwritable.exit_code, 3);
}

}  // namespace
}  // namespace smtcal::diff
