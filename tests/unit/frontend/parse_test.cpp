// The .place parser: input text -> IR dump, or -> error text with caret.
#include "frontend/parse.h"

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "ir/ir_dump.h"
#include "tests/unit/parse_text.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

struct Parsed {
  ir::Program program;
  std::string dump;
  std::string errors;  // RenderText of all diagnostics
  std::size_t error_count = 0;
};

Parsed Parse(const std::string& text) {
  test::ParsedText parsed = test::ParseText(text);
  Parsed out;
  out.dump = DumpIr(parsed.program);
  out.program = std::move(parsed.program);
  out.errors = std::move(parsed.diagnostics);
  out.error_count = parsed.error_count;
  return out;
}

// A statement inside Function Main; returns the dump of the function body.
std::string BodyDump(const std::string& statement, std::string* errors = nullptr) {
  Parsed parsed = Parse("Function Main\n  " + statement + "\nFend\n");
  if (errors != nullptr) *errors = parsed.errors;
  EXPECT_EQ(parsed.program.items.size(), 1u) << statement;
  if (parsed.program.items.size() != 1) return parsed.dump;
  auto* function = std::get_if<ir::Function>(&parsed.program.items[0]->node);
  if (function == nullptr) return parsed.dump;
  ir::Program body;
  body.items = std::move(function->body);
  std::string dump = DumpIr(body);
  // "(program\n  X)\n" -> "X" for a single statement.
  if (dump.rfind("(program\n  ", 0) == 0 && dump.size() > 14) return dump.substr(11, dump.size() - 13);
  return dump;
}

// ------------------------------------------------------------------ statements

struct StmtCase {
  const char* input;
  const char* dump;
};

const StmtCase kStatements[] = {
    // motion, case-insensitive keywords
    {"Jump P", "(jump (point (name P)))"},
    {"JUMP P", "(jump (point (name P)))"},
    {"jump P", "(jump (point (name P)))"},
    {"Go XY(1, 2.5, -3, +90)", "(go (point (xy 1 2.5 -3 90)))"},
    {"Move P LimZ -2", "(move (point (name P)) :limz (neg (int 2)))"},
    {"Jump Pallet(1, 2, 3)", "(jump (point (pallet (int 1) (int 2) (int 3))))"},
    {"Jump Pallet(1, k + 1)", "(jump (point (pallet (int 1) (+ (var k) (int 1)))))"},
    {"Jump P + X(1) - Y(2) + z(.5) - u(1e3)",
     "(jump (point (name P) (+x (int 1)) (-y (int 2)) (+z (real 0.5)) (-u (real 1000))))"},
    {"Jump P + X(layer * 55.0)", "(jump (point (name P) (+x (* (var layer) (real 55)))))"},
    // pick and place
    {"Pick Feed Vacuum 2 LimZ 0", "(pick (point (name Feed)) :vacuum (int 2) :limz (int 0))"},
    {"Place C1 LimZ 5", "(place (point (name C1)) :limz (int 5))"},
    {"place C1 vacuum 1", "(place (point (name C1)) :vacuum (int 1))"},
    // I/O and waiting
    {"On 3", "(on (int 3))"},
    {"OFF n + 1", "(off (+ (var n) (int 1)))"},
    {"Wait Sw(1) = On", "(wait-sw (int 1) on)"},
    {"wait sw(k) = off", "(wait-sw (var k) off)"},
    {"Wait 0.5", "(wait (real 0.5))"},
    {"Wait Sw(1) = 1", "(wait (= (sw (int 1)) (int 1)))"},
    // assignment and expressions: precedence and associativity
    {"x = 1 + 2 * 3", "(assign x (+ (int 1) (* (int 2) (int 3))))"},
    {"x = (1 + 2) * 3", "(assign x (* (+ (int 1) (int 2)) (int 3)))"},
    {"x = 1 - 2 - 3", "(assign x (- (- (int 1) (int 2)) (int 3)))"},
    {"x = 8 / 4 Mod 3", "(assign x (mod (/ (int 8) (int 4)) (int 3)))"},
    {"x = -2", "(assign x (neg (int 2)))"},
    {"x = 1 - -2", "(assign x (- (int 1) (neg (int 2))))"},
    {"x = +a", "(assign x (plus (var a)))"},
    {"x = Not a And b", "(assign x (and (not (var a)) (var b)))"},
    {"x = a Or b And c", "(assign x (or (var a) (and (var b) (var c))))"},
    {"x = a Xor b Or c", "(assign x (or (xor (var a) (var b)) (var c)))"},
    // comparisons share one level and associate to the left, as in SPEL
    {"x = a < 1 = b >= 2", "(assign x (>= (= (< (var a) (int 1)) (var b)) (int 2)))"},
    {"x = a <> b", "(assign x (<> (var a) (var b)))"},
    {"x = a <= b", "(assign x (<= (var a) (var b)))"},
    {"x = a > b", "(assign x (> (var a) (var b)))"},
    {"x = Sw(2) = On", "(assign x (= (sw (int 2)) (on)))"},
    // number forms
    {"x = 1", "(assign x (int 1))"},
    {"x = 1.5", "(assign x (real 1.5))"},
    {"x = .5", "(assign x (real 0.5))"},
    {"x = 1e3", "(assign x (real 1000))"},
    {"x = 2.", "(assign x (real 2))"},
    {"x = 007", "(assign x (int 7))"},
    {"x = 1.5E-3", "(assign x (real 0.0015))"},
    {"x = 0.1", "(assign x (real 0.1))"},
    // the rest
    {"Call Feed", "(call Feed)"},
    {"call Feed()", "(call Feed)"},
    {"Scan Board", "(scan Board)"},
    {"Exit Function", "(exit-function)"},
    {"Integer a, b", "(integer a b)"},
    {"Real d", "(real d)"},
    {"Jump P ' go there", "(jump (point (name P)) :comment \" go there\")"},
    {"Jump P '", "(jump (point (name P)))"},
};

TEST(Parse, Statements) {
  for (const StmtCase& c : kStatements) {
    std::string errors;
    EXPECT_EQ(BodyDump(c.input, &errors), c.dump) << c.input;
    EXPECT_EQ(errors, "") << c.input;
  }
}

TEST(Parse, TopLevelDeclarations) {
  Parsed parsed = Parse(
      "Program LayerA\n"
      "units MM\n"
      "Fixture Board\n"
      "Local L1 = XY(1, 2, 0, 0) In Board\n"
      "Local L2 = XY(1, 2, 0, 0)\n"
      "Point Feed0805 = XY(212.40, 35.50, -12.00, 0)\n"
      "Point C1 = XY(12.70, 8.25, -3.00, 90) In Board\n"
      "TAUGHT POINT U3 = XY(171.204, 97.311, -3.00, 0) ON Board\n"
      "Taught Point T2 = XY(1, 2, 3, 4)\n"
      "Pallet 1, A, B, C, 3, 4\n"
      "Vacuum 2\n"
      "Integer count\n"
      "Function Main()\n"
      "Fend");
  EXPECT_EQ(parsed.errors, "");
  EXPECT_EQ(parsed.dump,
            "(program\n"
            "  (program-decl LayerA)\n"
            "  (units MM)\n"
            "  (fixture Board)\n"
            "  (local L1 (xy 1 2 0 0) :frame Board)\n"
            "  (local L2 (xy 1 2 0 0))\n"
            "  (point-decl Feed0805 (xy 212.4 35.5 -12 0))\n"
            "  (point-decl C1 (xy 12.7 8.25 -3 90) :frame Board)\n"
            "  (point-decl U3 :taught (xy 171.204 97.311 -3 0) :frame Board)\n"
            "  (point-decl T2 :taught (xy 1 2 3 4))\n"
            "  (pallet-decl 1 A B C 3 4)\n"
            "  (vacuum-decl 2)\n"
            "  (integer count)\n"
            "  (function Main\n"
            "    (end)))\n");
}

TEST(Parse, Blocks) {
  Parsed parsed = Parse(
      "Function Main\n"
      "  Cycle Board\n"
      "    For layer = 0 To 2\n"
      "      Pick Feed0805\n"
      "    Next\n"
      "    for i = 10 to 1 step -1\n"
      "    next i\n"
      "  EndCycle\n"
      "  If a = 1 Then\n"
      "    Jump P\n"
      "  ElseIf a = 2 Then\n"
      "  elseif a = 3 then\n"
      "    Jump Q\n"
      "  Else\n"
      "    Jump R\n"
      "  EndIf\n"
      "  If b Then\n"
      "  endif\n"
      "Fend\n");
  EXPECT_EQ(parsed.errors, "");
  EXPECT_EQ(parsed.dump,
            "(program\n"
            "  (function Main\n"
            "    (cycle Board\n"
            "      (for layer (int 0) (int 2)\n"
            "        (pick (point (name Feed0805)))\n"
            "        (end))\n"
            "      (for i (int 10) (int 1) :step (neg (int 1)) :next i\n"
            "        (end))\n"
            "      (end))\n"
            "    (if\n"
            "      (branch (= (var a) (int 1))\n"
            "        (jump (point (name P))))\n"
            "      (branch (= (var a) (int 2)))\n"
            "      (branch (= (var a) (int 3))\n"
            "        (jump (point (name Q))))\n"
            "      (else\n"
            "        (jump (point (name R))))\n"
            "      (end))\n"
            "    (if\n"
            "      (branch (var b))\n"
            "      (end))\n"
            "    (end)))\n");
}

// ------------------------------------------------------------------ comments and blank lines

TEST(Parse, CommentsAndBlankLinesLandInTheirBlock) {
  Parsed parsed = Parse(
      "' layer_a.place\r\n"
      "Program T ' the name\n"
      "\n"
      "\n"
      "'  two spaces\n"
      "Function Main  ' fm\n"
      "  ' first in body\n"
      "\n"
      "  If a = 1 Then ' if line\n"
      "    ' in then\n"
      "  ElseIf a <> 2 Then  ' elseif line\n"
      "    x = 1\n"
      "\n"
      "    ' last in elseif\n"
      "  Else ' else line\n"
      "  EndIf ' endif line\n"
      "  For i = 1 To 2\n"
      "    ' before next\n"
      "  Next ' next line\n"
      "  Cycle Board\n"
      "\n"
      "  EndCycle '\n"
      "  ' before fend\n"
      "Fend ' fend line\n"
      "'\n"
      "' end");
  EXPECT_EQ(parsed.errors, "");
  EXPECT_EQ(parsed.dump,
            "(program\n"
            "  (comment \" layer_a.place\")\n"
            "  (program-decl T :comment \" the name\")\n"
            "  (comment \"  two spaces\" :blank)\n"
            "  (function Main :comment \" fm\"\n"
            "    (comment \" first in body\")\n"
            "    (if :blank :comment \" if line\"\n"
            "      (branch (= (var a) (int 1))\n"
            "        (comment \" in then\"))\n"
            "      (branch (<> (var a) (int 2)) :comment \" elseif line\"\n"
            "        (assign x (int 1))\n"
            "        (comment \" last in elseif\" :blank))\n"
            "      (else :comment \" else line\")\n"
            "      (end :comment \" endif line\"))\n"
            "    (for i (int 1) (int 2)\n"
            "      (comment \" before next\")\n"
            "      (end :comment \" next line\"))\n"
            "    (cycle Board\n"
            "      (end))\n"
            "    (comment \" before fend\")\n"
            "    (end :comment \" fend line\"))\n"
            "  (comment \"\")\n"
            "  (comment \" end\"))\n");
}

// Trailing spaces and tabs are invisible and would end a canonical line in
// whitespace, so comments lose them; the spaces after the ' stay.
TEST(Parse, CommentsLoseTrailingWhitespaceOnly) {
  Parsed parsed = Parse(
      "'  header \t \n"
      "Program T ' name\t\n"
      "'   \n"
      "Function Main '\t \n"
      "  For i = 1 To 2 ' a\tb  \r\n"
      "  Next ' next \n"
      "Fend\n");
  EXPECT_EQ(parsed.errors, "");
  EXPECT_EQ(parsed.dump,
            "(program\n"
            "  (comment \"  header\")\n"
            "  (program-decl T :comment \" name\")\n"
            "  (comment \"\")\n"
            "  (function Main\n"
            "    (for i (int 1) (int 2) :comment \" a\\tb\"\n"
            "      (end :comment \" next\"))\n"
            "    (end)))\n");
}

// ------------------------------------------------------------------ locations

TEST(Parse, Locations) {
  Parsed parsed = Parse(
      "Program T\n"
      "Point C1 = XY(1, 2, 3, 4) In Board\n"
      "Function Main\n"
      "\tPlace C1 + X(a * 2.5)  ' tab indent\n"
      "  Integer i, j\n"
      "Fend\n");
  ASSERT_EQ(parsed.errors, "");
  ASSERT_EQ(parsed.program.items.size(), 3u);
  EXPECT_EQ(parsed.program.file, 1u);

  const ir::Stmt& point = *parsed.program.items[1];
  EXPECT_EQ(point.loc, (SourceLoc{1, 2, 1}));
  EXPECT_EQ(point.length, 5u);
  const auto& decl = std::get<ir::PointDecl>(point.node);
  EXPECT_EQ(decl.coords.loc, (SourceLoc{1, 2, 12}));
  EXPECT_EQ(decl.frame_loc, (SourceLoc{1, 2, 30}));

  const auto& function = std::get<ir::Function>(parsed.program.items[2]->node);
  EXPECT_EQ(parsed.program.items[2]->length, 8u);
  EXPECT_EQ(function.end.loc, (SourceLoc{1, 6, 1}));
  const ir::Stmt& place = *function.body[0];
  EXPECT_EQ(place.loc, (SourceLoc{1, 4, 2}));  // after a tab: byte columns
  EXPECT_EQ(place.length, 5u);
  const auto& pick = std::get<ir::PickPlace>(place.node);
  EXPECT_EQ(pick.target.loc, (SourceLoc{1, 4, 8}));
  EXPECT_EQ(std::get<ir::NamedPoint>(pick.target.base).length, 2u);
  ASSERT_EQ(pick.target.offsets.size(), 1u);
  EXPECT_EQ(pick.target.offsets[0].loc, (SourceLoc{1, 4, 11}));
  const ir::Expr& amount = *pick.target.offsets[0].amount;
  EXPECT_EQ(amount.loc, (SourceLoc{1, 4, 15}));
  EXPECT_EQ(amount.length, 7u);  // "a * 2.5"
  const auto& product = std::get<ir::BinaryExpr>(amount.node);
  EXPECT_EQ(product.rhs->loc, (SourceLoc{1, 4, 19}));
  EXPECT_EQ(product.rhs->length, 3u);

  const auto& vars = std::get<ir::VarDecl>(function.body[1]->node);
  ASSERT_EQ(vars.name_locs.size(), 2u);
  EXPECT_EQ(vars.name_locs[1], (SourceLoc{1, 5, 14}));
}

TEST(Parse, LocationsInTheDump) {
  Parsed parsed = Parse("Function Main\n  x = (1 + b)\nFend\n");
  EXPECT_EQ(DumpIr(parsed.program, true),
            "(program @1\n"
            "  (function @1:1:1/8 Main @1:1:10\n"
            "    (assign @1:2:3/1 x (+ @1:2:8/5 (int @1:2:8/1 1) (var @1:2:12/1 b)))\n"
            "    (end @1:3:1)))\n");
}

// Every name and number a check may underline keeps its own location, so
// the checks never have to search the line for it.
TEST(Parse, NameAndNumberLocations) {
  Parsed parsed = Parse(
      "Program T\n"
      "Units mm\n"
      "Fixture Board\n"
      "Local L1 = XY(1, 2, 0, 0) In Board\n"
      "Taught Point U3 = XY(1, 2, 3, 0) On Board\n"
      "Pallet 12, A, B, C, 34, 5\n"
      "Vacuum 007\n"
      "Function Main\n"
      "  Jump U3 LimZ -1\n"
      "  For i = 1 To 2\n"
      "  Next  i\n"
      "  Call Sub\n"
      "  Cycle Board\n"
      "    Scan Board\n"
      "  EndCycle\n"
      "Fend\n");
  EXPECT_EQ(parsed.errors, "");
  EXPECT_EQ(DumpIr(parsed.program, true),
            "(program @1\n"
            "  (program-decl @1:1:1/7 T @1:1:9)\n"
            "  (units @1:2:1/5 mm @1:2:7)\n"
            "  (fixture @1:3:1/7 Board @1:3:9)\n"
            "  (local @1:4:1/5 L1 @1:4:7 (xy @1:4:12 1 2 0 0) :frame @1:4:30 Board)\n"
            "  (point-decl @1:5:1/6 U3 @1:5:14 :taught (xy @1:5:19 1 2 3 0) :frame @1:5:37 Board)\n"
            "  (pallet-decl @1:6:1/6 12 @1:6:8 A @1:6:12 B @1:6:15 C @1:6:18 34 @1:6:21 5 @1:6:25)\n"
            "  (vacuum-decl @1:7:1/6 7 @1:7:8)\n"
            "  (function @1:8:1/8 Main @1:8:10\n"
            "    (jump @1:9:3/4 (point @1:9:8 (name /2 U3)) :limz @1:9:11 (neg @1:9:16/2 (int @1:9:17/1 1)))\n"
            "    (for @1:10:3/3 i @1:10:7 (int @1:10:11/1 1) (int @1:10:16/1 2) :next i @1:11:9\n"
            "      (end @1:11:3))\n"
            "    (call @1:12:3/4 Sub @1:12:8)\n"
            "    (cycle @1:13:3/5 Board @1:13:9\n"
            "      (scan @1:14:5/4 Board @1:14:10)\n"
            "      (end @1:15:3))\n"
            "    (end @1:16:1)))\n");
}

TEST(Parse, NumberFlags) {
  Parsed parsed = Parse("Function Main\n  x = 1e3 + 12\nFend\n");
  const auto& function = std::get<ir::Function>(parsed.program.items[0]->node);
  const auto& sum = std::get<ir::BinaryExpr>(std::get<ir::Assign>(function.body[0]->node).value->node);
  EXPECT_FALSE(std::get<ir::NumberLit>(sum.lhs->node).is_integer);
  EXPECT_EQ(std::get<ir::NumberLit>(sum.lhs->node).value, 1000.0);
  EXPECT_TRUE(std::get<ir::NumberLit>(sum.rhs->node).is_integer);
}

// ------------------------------------------------------------------ errors

struct ErrorCase {
  const char* input;
  const char* errors;  // the full RenderText
};

const ErrorCase kErrors[] = {
    // ---- characters and structure (the line pre-scan)
    {"Function Main\n  x = 1 $ 2\nFend\n",
     "t.place:2:9: error: unexpected character '$'\n"
     "    x = 1 $ 2\n"
     "          ^\n"},
    {"Function Main\n  Jump P\xC3\xA9\nFend\n",
     "t.place:2:9: error: unexpected character '\xC3\xA9'; outside comments a program uses only plain ASCII "
     "letters, digits and signs\n"
     "    Jump P\xC3\xA9\n"
     "          ^\n"},
    {"Program A\nNext\n",
     "t.place:2:1: error: unexpected 'Next': no For is open\n"
     "  Next\n"
     "  ^~~~\n"},
    {"Function Main\n  ENDIF\nFend\n",
     "t.place:2:3: error: unexpected 'EndIf': no If is open\n"
     "    ENDIF\n"
     "    ^~~~~\n"},
    {"Function Main\n  For i = 1 To 2\n    If a Then\n  Next\nFend\n",
     "t.place:4:3: error: missing 'EndIf' for the If at line 3\n"
     "    Next\n"
     "    ^~~~\n"
     "t.place:3:5: note: the If starts here\n"
     "      If a Then\n"
     "      ^~\n"},
    {"Function Main\n  Jump P\nFunction Other\nFend\n",
     "t.place:3:1: error: missing 'Fend' for Function Main at line 1\n"
     "  Function Other\n"
     "  ^~~~~~~~\n"
     "t.place:1:1: note: Function Main starts here\n"
     "  Function Main\n"
     "  ^~~~~~~~\n"},
    {"Program A\n\nFunction Main\n  Cycle Board\n    Jump P",
     "t.place:3:1: error: missing 'Fend' at end of file for Function Main at line 3\n"
     "  Function Main\n"
     "  ^~~~~~~~\n"
     "t.place:4:3: error: missing 'EndCycle' at end of file for the Cycle at line 4\n"
     "    Cycle Board\n"
     "    ^~~~~\n"},
    {"Function Main\n  If a Then\n  Else\n  ElseIf b Then\n  EndIf\nFend\n",
     "t.place:4:3: error: 'ElseIf' after 'Else' in the If at line 2; 'Else' must be the last branch\n"
     "    ElseIf b Then\n"
     "    ^~~~~~\n"},
    {"Function Main\n  If a Then Jump P\nFend\n",
     "t.place:2:8: error: 'Then' must end its line: put the statement after 'Then' on the next line and "
     "close the block with 'EndIf'\n"
     "    If a Then Jump P\n"
     "         ^~~~\n"},
    {"Program A\nJump P\nGo Q\nPoint R = XY(0, 0, 0, 0)\nx = 1\n",
     "t.place:2:1: error: 'Jump' must be inside a Function ... Fend\n"
     "  Jump P\n"
     "  ^~~~\n"
     "t.place:5:1: error: an assignment must be inside a Function ... Fend\n"
     "  x = 1\n"
     "  ^\n"},
    {"Function Main\n  Taught Point P = XY(0, 0, 0, 0)\nFend\n",
     "t.place:2:3: error: 'Taught Point' declarations belong at the top of the program, outside "
     "Function Main\n"
     "    Taught Point P = XY(0, 0, 0, 0)\n"
     "    ^~~~~~\n"},
    {"Function Main\n  Jmp P\n  3 + 4\nFend\n",
     "t.place:2:3: error: expected a statement, found 'Jmp'; did you mean 'Jump'?\n"
     "    Jmp P\n"
     "    ^~~\n"
     "t.place:3:3: error: expected a statement, found '3'\n"
     "    3 + 4\n"
     "    ^\n"},
    {"Pont P = XY(0, 0, 0, 0)\n",
     "t.place:1:1: error: expected a declaration (Program, Units, Fixture, Local, Point, Pallet, Vacuum, "
     "Integer, Real or Function), found 'Pont'; did you mean 'Point'?\n"
     "  Pont P = XY(0, 0, 0, 0)\n"
     "  ^~~~\n"},
    // ---- inside a line (ANTLR, messages rewritten)
    {"Function Main\n  Jump 3\nFend\n",
     "t.place:2:8: error: expected a point name, XY(...) or Pallet(...) after 'Jump', found '3'\n"
     "    Jump 3\n"
     "         ^\n"},
    {"Function Main\n  Pick\nFend\n",
     "t.place:2:7: error: expected a point name, XY(...) or Pallet(...) after 'Pick', found end of line\n"
     "    Pick\n"
     "        ^\n"},
    {"Function Main\n  Jump P + 3\nFend\n",
     "t.place:2:12: error: expected an offset X(...), Y(...), Z(...) or U(...) after '+', found '3'\n"
     "    Jump P + 3\n"
     "             ^\n"},
    {"Function Main\n  Jump P + W(1)\nFend\n",
     "t.place:2:12: error: unknown offset axis 'W'; use X, Y, Z or U\n"
     "    Jump P + W(1)\n"
     "             ^\n"},
    {"Function Main\n  Wait\nFend\n",
     "t.place:2:7: error: expected an expression after 'Wait', found end of line\n"
     "    Wait\n"
     "        ^\n"},
    {"Function Main\n  x = 1 +* 2\nFend\n",
     "t.place:2:10: error: expected an expression after '+', found '*'\n"
     "    x = 1 +* 2\n"
     "           ^\n"},
    {"Function Main\n  Wait (1 + 2\nFend\n",
     "t.place:2:14: error: missing ')' for the '(' at column 8; found end of line\n"
     "    Wait (1 + 2\n"
     "               ^\n"},
    {"Point = XY(0, 0, 0, 0)\n",
     "t.place:1:7: error: expected a point name after 'Point', found '='\n"
     "  Point = XY(0, 0, 0, 0)\n"
     "        ^\n"},
    {"Function Main\n  Integer Jump\nFend\n",
     "t.place:2:11: error: 'Jump' is a keyword and cannot be used as a variable name\n"
     "    Integer Jump\n"
     "            ^~~~\n"},
    {"Function Main\n  If a = 1\n  EndIf\nFend\n",
     "t.place:2:11: error: expected 'Then' after '1', found end of line; write: If condition Then\n"
     "    If a = 1\n"
     "            ^\n"},
    {"Function Main\n  For i = 1 2\n  Next\nFend\n",
     "t.place:2:13: error: expected 'To' after '1', found '2'; write: For var = start To end [Step step]\n"
     "    For i = 1 2\n"
     "              ^\n"},
    {"Function Main\n  Jump P Q\nFend\n",
     "t.place:2:10: error: unexpected 'Q' after 'P'; expected end of line\n"
     "    Jump P Q\n"
     "           ^\n"},
    {"Function Main\n  Next i j\nFend\n",
     "t.place:2:3: error: unexpected 'Next': no For is open\n"
     "    Next i j\n"
     "    ^~~~\n"},
    {"Point P = XY(1, 2, 3)\n",
     "t.place:1:21: error: XY(...) needs exactly 4 numbers (x, y, z, u); found 3\n"
     "  Point P = XY(1, 2, 3)\n"
     "                      ^\n"},
    {"Point P = XY(1, 2, 3, 4, 5)\n",
     "t.place:1:24: error: XY(...) needs exactly 4 numbers (x, y, z, u); found more than 4\n"
     "  Point P = XY(1, 2, 3, 4, 5)\n"
     "                         ^\n"},
    {"Point P = XY(1, a, 3, 4)\n",
     "t.place:1:17: error: XY(...) takes plain numbers (x, y, z, u), found 'a'\n"
     "  Point P = XY(1, a, 3, 4)\n"
     "                  ^\n"},
    {"Pallet 1, A, B, C, 3\n",
     "t.place:1:21: error: expected ',' after '3', found end of line; "
     "write: Pallet n, P1, P2, P3, columns, rows\n"
     "  Pallet 1, A, B, C, 3\n"
     "                      ^\n"},
    // ---- checks on what parsed
    {"Taught Point P = XY(0, 0, 0, 0) In Board\n",
     "t.place:1:33: error: a taught point is recorded 'On' a fixture, not 'In' a frame; write 'On Board'\n"
     "  Taught Point P = XY(0, 0, 0, 0) In Board\n"
     "                                  ^~\n"},
    {"Point P = XY(0, 0, 0, 0) On Board\n",
     "t.place:1:26: error: 'On Board' is for taught points; write 'In Board' for a programmed point, or "
     "'Taught Point' if it was taught\n"
     "  Point P = XY(0, 0, 0, 0) On Board\n"
     "                           ^~\n"},
    {"Pallet 1.5, A, B, C, 3, 4\n",
     "t.place:1:8: error: the pallet number must be a whole number, found '1.5'\n"
     "  Pallet 1.5, A, B, C, 3, 4\n"
     "         ^~~\n"},
    {"Vacuum 99999999999\n",
     "t.place:1:8: error: the vacuum output must be at most 2147483647, found '99999999999'\n"
     "  Vacuum 99999999999\n"
     "         ^~~~~~~~~~~\n"},
    {"Function Main\n  Wait 1e999\nFend\n",
     "t.place:2:8: error: number '1e999' is out of range\n"
     "    Wait 1e999\n"
     "         ^~~~~\n"},
};

TEST(Parse, Errors) {
  for (const ErrorCase& c : kErrors) {
    Parsed parsed = Parse(c.input);
    EXPECT_EQ(parsed.errors, c.errors) << c.input;
  }
}

TEST(Parse, ALineWithAnErrorIsDroppedTheRestIsKept) {
  Parsed parsed = Parse(
      "Function Main\n"
      "  Jump P\n"
      "  Jump 3\n"
      "  For i = 1 To\n"
      "    Go Q\n"
      "  Next\n"
      "  Go R\n"
      "Fend\n");
  EXPECT_EQ(parsed.error_count, 2u) << parsed.errors;
  EXPECT_EQ(parsed.dump,
            "(program\n"
            "  (function Main\n"
            "    (jump (point (name P)))\n"
            "    (go (point (name R)))\n"
            "    (end)))\n");
}

TEST(Parse, TooManyErrorsStopsAtTen) {
  std::string text = "Function Main\n";
  for (int i = 0; i < 30; ++i) text += "  Jump 3\n";
  text += "Fend\n";
  Parsed parsed = Parse(text);
  EXPECT_EQ(parsed.error_count, 11u);
  EXPECT_NE(parsed.errors.find("t.place: error: too many syntax errors; fix the ones above first\n"),
            std::string::npos);
}

TEST(Parse, EmptyInputsAreEmptyPrograms) {
  for (const char* text : {"", "\n", "\n\n  \n", "\xEF\xBB\xBF"}) {
    Parsed parsed = Parse(text);
    EXPECT_EQ(parsed.errors, "") << text;
    EXPECT_EQ(parsed.dump, "(program)\n") << text;
  }
}

TEST(Parse, ByteOrderMarkIsSkipped) {
  Parsed parsed = Parse("\xEF\xBB\xBFProgram A\n");
  EXPECT_EQ(parsed.errors, "");
  EXPECT_EQ(parsed.dump, "(program\n  (program-decl A))\n");
}

// ------------------------------------------------------------------ robustness

// Parses `text` with stderr captured: nothing may reach the console (ANTLR's
// own listener is removed) and the error count stays bounded.
void ExpectQuietAndBounded(const std::string& text) {
  testing::internal::CaptureStderr();
  Parsed parsed = Parse(text);
  std::string console = testing::internal::GetCapturedStderr();
  EXPECT_EQ(console, "");
  EXPECT_LE(parsed.error_count, 11u);
  (void)DumpIr(parsed.program, true);
}

TEST(ParseRobustness, RandomBytes) {
  std::uint32_t seed = 20240611;
  SCOPED_TRACE(fmt::format("seed {}", seed));
  std::mt19937 rng(seed);
  for (int round = 0; round < 40; ++round) {
    std::size_t size = std::uniform_int_distribution<std::size_t>(1, round < 36 ? 4000 : 100000)(rng);
    std::string text(size, '\0');
    for (char& c : text) c = static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    SCOPED_TRACE(fmt::format("round {} size {}", round, size));
    ExpectQuietAndBounded(text);
  }
}

// Random sequences of the language's own words: these reach ANTLR (random
// bytes mostly stop at the first bad character) and exercise its recovery.
TEST(ParseRobustness, RandomTokens) {
  static const char* const kWords[] = {
      "Program", "Units", "mm",    "Fixture", "Local",   "Point",  "Taught", "In",      "On",     "Off",
      "XY",      "Pallet", "Vacuum", "Integer", "Real",  "Function", "Fend", "Jump",    "Go",     "Move",
      "LimZ",    "Pick",  "Place", "Wait",    "Sw",      "For",    "To",     "Step",    "Next",   "If",
      "Then",    "ElseIf", "Else", "EndIf",   "Call",    "Cycle",  "EndCycle", "Scan",  "Exit",   "And",
      "Or",      "Xor",   "Not",   "Mod",     "=",       "<>",     "<",      ">",       "<=",     ">=",
      ",",       "(",     ")",     "+",       "-",       "*",      "/",      "1",       "2.5",    ".5",
      "1e3",     "P",     "X",     "Y",       "Z",       "U",      "W",      "i",       "Main",   "' note",
      "\n",      "\n",    "\n",    "\n",      "\n  ",    "$",      "\xC3\xA9", "1e999", "9999999999"};
  std::uint32_t seed = 7;
  SCOPED_TRACE(fmt::format("seed {}", seed));
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, std::size(kWords) - 1);
  for (int round = 0; round < 300; ++round) {
    std::string text;
    std::size_t count = std::uniform_int_distribution<std::size_t>(1, 400)(rng);
    for (std::size_t i = 0; i < count; ++i) {
      text += kWords[pick(rng)];
      text += ' ';
    }
    SCOPED_TRACE(fmt::format("round {}: {}", round, text.substr(0, 200)));
    ExpectQuietAndBounded(text);
  }
}

// A mistake stays on its line: junk added to the end of any one line of a
// valid program gives exactly one error, on that line, whatever the line is
// (a block's first or last line included).
TEST(ParseRobustness, JunkOnOneLineGivesOneErrorOnThatLine) {
  const std::vector<std::string> lines = {
      "Program LayerA",
      "Units mm",
      "Fixture Board",
      "Point C1 = XY(12.70, 8.25, -3.00, 90) In Board",
      "Pallet 1, C1, C1, C1, 3, 4",
      "Function Main",
      "  Integer i",
      "  Cycle Board",
      "    For i = 0 To 2 Step 1",
      "      Pick Pallet(1, i) Vacuum 1",
      "      Place C1 + X(i * 55.0) LimZ -3",
      "    Next i",
      "  EndCycle",
      "  If Sw(1) = On Then",
      "    Wait Sw(2) = Off",
      "  ElseIf i > 2 Then",
      "    On 3",
      "  Else",
      "    Call Other",
      "  EndIf",
      "Fend",
      "Function Other()",
      "  Exit Function",
      "Fend"};
  const std::vector<std::string> junk = {" 1 2", " )", " Foo Bar", " = =", " Next", " ,", " (", " 3",
                                         " Jump", " Then", " + X", " .5 .5"};
  std::uint32_t seed = 99;
  SCOPED_TRACE(fmt::format("seed {}", seed));
  std::mt19937 rng(seed);
  for (std::size_t line = 0; line < lines.size(); ++line) {
    for (int k = 0; k < 4; ++k) {
      std::string added = junk[std::uniform_int_distribution<std::size_t>(0, junk.size() - 1)(rng)];
      std::string text;
      for (std::size_t i = 0; i < lines.size(); ++i) text += lines[i] + (i == line ? added : "") + "\n";
      SourceManager sources;
      std::uint32_t file = sources.Add("t.place", text);
      Diagnostics diags(sources);
      (void)ParseProgram(file, diags);
      SCOPED_TRACE(fmt::format("line {}: '{}{}'", line + 1, lines[line], added));
      ASSERT_EQ(diags.all().size(), 1u) << diags.RenderText();
      EXPECT_EQ(diags.all()[0].range.begin.line, line + 1) << diags.RenderText();
    }
  }
}

TEST(ParseRobustness, DeepNesting) {
  std::string parens(10000, '(');
  std::string minus(10000, '-');
  std::string sum;
  for (int i = 0; i < 5000; ++i) sum += "1 + ";
  std::string fors = "Function Main\n";
  for (int i = 0; i < 10000; ++i) fors += "For i = 1 To 2\n";
  for (int i = 0; i < 10000; ++i) fors += "Next\n";
  fors += "Fend\n";
  for (const std::string& text :
       {parens, "Function Main\n  x = " + parens + "1\nFend\n", "Function Main\n  x = " + minus + "1\nFend\n",
        "Function Main\n  Jump Pallet" + parens + "\nFend\n", "Function Main\n  x = " + sum + "1\nFend\n",
        "Function Main\n  x = " + std::string(5000, '(') + "1" + std::string(5000, ')') + "\nFend\n", fors}) {
    SCOPED_TRACE(text.substr(0, 40));
    testing::internal::CaptureStderr();
    Parsed parsed = Parse(text);
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
    EXPECT_GE(parsed.error_count, 1u);
    EXPECT_LE(parsed.error_count, 3u) << parsed.errors;
  }
}

TEST(ParseRobustness, NestingBelowTheLimitParses) {
  std::string deep = std::string(150, '(') + "1" + std::string(150, ')');
  Parsed parsed = Parse("Function Main\n  x = " + deep + "\nFend\n");
  EXPECT_EQ(parsed.errors, "");
  EXPECT_EQ(parsed.dump, "(program\n  (function Main\n    (assign x (int 1))\n    (end)))\n");
  std::string fors = "Function Main\n";
  for (int i = 0; i < 50; ++i) fors += "For i = 1 To 2\n";
  for (int i = 0; i < 50; ++i) fors += "Next\n";
  EXPECT_EQ(Parse(fors + "Fend\n").errors, "");
}

}  // namespace
}  // namespace smtcal
