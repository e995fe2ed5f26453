// The canonical printer: tables on hand-built IR (numbers, parentheses,
// statements and comments), then round trips through the parser.
#include "backend/place/place_printer.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "frontend/parse.h"
#include "ir/ir_dump.h"
#include "tests/unit/parse_text.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

using ir::BinaryOp;
using ir::UnaryOp;

// ------------------------------------------------------------ IR builders

ir::ExprPtr Make(auto node) {
  auto expr = std::make_unique<ir::Expr>();
  expr->node = std::move(node);
  return expr;
}
ir::ExprPtr Int(double value) { return Make(ir::NumberLit{value, true}); }
ir::ExprPtr Real(double value) { return Make(ir::NumberLit{value, false}); }
ir::ExprPtr Var(std::string name) { return Make(ir::VariableRef{std::move(name)}); }
ir::ExprPtr OnOff(bool on) { return Make(ir::OnOffLit{on}); }
ir::ExprPtr Sw(ir::ExprPtr bit) { return Make(ir::SwitchRead{std::move(bit)}); }
ir::ExprPtr Un(UnaryOp op, ir::ExprPtr operand) { return Make(ir::UnaryExpr{op, std::move(operand)}); }
ir::ExprPtr Bin(BinaryOp op, ir::ExprPtr lhs, ir::ExprPtr rhs) {
  return Make(ir::BinaryExpr{op, std::move(lhs), std::move(rhs)});
}
ir::ExprPtr A() { return Var("a"); }
ir::ExprPtr B() { return Var("b"); }
ir::ExprPtr C() { return Var("c"); }

ir::StmtPtr S(auto node, std::string comment = "", bool blank_line_before = false) {
  auto stmt = std::make_unique<ir::Stmt>();
  stmt->node = std::move(node);
  stmt->trailing_comment = std::move(comment);
  stmt->blank_line_before = blank_line_before;
  return stmt;
}
ir::StmtPtr Blank(ir::StmtPtr stmt) {
  stmt->blank_line_before = true;
  return stmt;
}
template <typename... Stmts>
ir::Block Body(Stmts... stmts) {
  ir::Block block;
  (block.push_back(std::move(stmts)), ...);
  return block;
}
ir::PointExpr Named(std::string name) {
  ir::PointExpr point;
  point.base = ir::NamedPoint{std::move(name)};
  return point;
}
ir::PointExpr WithOffset(ir::PointExpr point, bool negative, ir::Axis axis, ir::ExprPtr amount) {
  ir::PointOffset offset;
  offset.negative = negative;
  offset.axis = axis;
  offset.amount = std::move(amount);
  point.offsets.push_back(std::move(offset));
  return point;
}
ir::Coords XY(double x, double y, double z, double u) {
  ir::Coords coords;
  coords.values = {x, y, z, u};
  return coords;
}

// ------------------------------------------------------------ numbers

TEST(FmtNumbers, RealLiteralsAreShortestRoundTripWithADot) {
  struct Case {
    double value;
    const char* text;
  };
  const Case cases[] = {
      {12.70, "12.7"},
      {-12.00, "-12.0"},
      {0.0, "0.0"},
      {-0.0, "-0.0"},
      {90.0, "90.0"},
      {0.1, "0.1"},
      {0.1 + 0.2, "0.30000000000000004"},
      {1.0 / 3.0, "0.3333333333333333"},
      {171.204, "171.204"},
      {1e-5, "0.00001"},
      {9.5e-6, "9.5e-6"},
      {2.5e-7, "2.5e-7"},
      {123456789012345.0, "123456789012345.0"},
      {1e15, "1.0e15"},
      {1e20, "1.0e20"},
      {-1.25e300, "-1.25e300"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(FormatRealLiteral(c.value), c.text) << "value " << c.value;
  }
}

TEST(FmtNumbers, IntegerLiteralsHaveNoDot) {
  EXPECT_EQ(FormatIntegerLiteral(0), "0");
  EXPECT_EQ(FormatIntegerLiteral(42), "42");
  EXPECT_EQ(FormatIntegerLiteral(1e20), "100000000000000000000");
  EXPECT_EQ(PrintExpr(*Int(7)), "7");
  EXPECT_EQ(PrintExpr(*Real(7)), "7.0");
}

// ------------------------------------------------------------ parentheses

struct ExprCase {
  ir::ExprPtr expr;
  std::string text;
};

// Trees and their canonical text. Every tree here is one the parser can
// produce, so the round-trip test below parses each text back.
std::vector<ExprCase> ExprCases() {
  std::vector<ExprCase> cases;
  cases.push_back({Bin(BinaryOp::Sub, A(), Bin(BinaryOp::Sub, B(), C())), "a - (b - c)"});
  cases.push_back({Bin(BinaryOp::Sub, Bin(BinaryOp::Sub, A(), B()), C()), "a - b - c"});
  cases.push_back({Bin(BinaryOp::Add, A(), Bin(BinaryOp::Add, B(), C())), "a + (b + c)"});
  cases.push_back({Bin(BinaryOp::Add, A(), Bin(BinaryOp::Mul, B(), C())), "a + b * c"});
  cases.push_back({Bin(BinaryOp::Mul, Bin(BinaryOp::Add, A(), B()), C()), "(a + b) * c"});
  cases.push_back({Bin(BinaryOp::Div, A(), Bin(BinaryOp::Div, B(), C())), "a / (b / c)"});
  cases.push_back({Bin(BinaryOp::Div, Bin(BinaryOp::Mul, A(), B()), C()), "a * b / c"});
  cases.push_back({Bin(BinaryOp::Mod, A(), Bin(BinaryOp::Mul, B(), C())), "a Mod (b * c)"});
  cases.push_back({Bin(BinaryOp::Mod, Bin(BinaryOp::Add, A(), B()), Int(2)), "(a + b) Mod 2"});
  cases.push_back({Bin(BinaryOp::Lt, A(), Bin(BinaryOp::Add, B(), Int(1))), "a < b + 1"});
  cases.push_back({Bin(BinaryOp::Eq, Bin(BinaryOp::Eq, A(), B()), C()), "a = b = c"});
  cases.push_back({Bin(BinaryOp::Ne, A(), Bin(BinaryOp::Ge, B(), C())), "a <> (b >= c)"});
  cases.push_back({Bin(BinaryOp::Or, A(), Bin(BinaryOp::And, B(), C())), "a Or b And c"});
  cases.push_back({Bin(BinaryOp::And, Bin(BinaryOp::Or, A(), B()), C()), "(a Or b) And c"});
  cases.push_back({Bin(BinaryOp::Xor, A(), Bin(BinaryOp::Or, B(), C())), "a Xor (b Or c)"});
  cases.push_back({Bin(BinaryOp::Or, Bin(BinaryOp::Xor, A(), B()), C()), "a Xor b Or c"});
  cases.push_back({Bin(BinaryOp::And, Bin(BinaryOp::Le, A(), B()), Bin(BinaryOp::Gt, B(), C())), "a <= b And b > c"});
  cases.push_back({Un(UnaryOp::Negate, Bin(BinaryOp::Add, A(), B())), "-(a + b)"});
  cases.push_back({Bin(BinaryOp::Mul, Un(UnaryOp::Negate, A()), B()), "-a * b"});
  cases.push_back({Bin(BinaryOp::Sub, A(), Un(UnaryOp::Negate, B())), "a - -b"});
  cases.push_back({Un(UnaryOp::Negate, Un(UnaryOp::Negate, A())), "--a"});
  cases.push_back({Un(UnaryOp::Plus, Real(2.5)), "+2.5"});
  // Not binds tighter than every binary operator (grammar/Place.g4).
  cases.push_back({Un(UnaryOp::Not, Bin(BinaryOp::Eq, A(), B())), "Not (a = b)"});
  cases.push_back({Bin(BinaryOp::Eq, Un(UnaryOp::Not, A()), B()), "Not a = b"});
  cases.push_back({Un(UnaryOp::Not, Un(UnaryOp::Not, A())), "Not Not a"});
  cases.push_back({Bin(BinaryOp::Or, Un(UnaryOp::Not, Bin(BinaryOp::And, A(), B())), C()), "Not (a And b) Or c"});
  cases.push_back({Bin(BinaryOp::Eq, Sw(Bin(BinaryOp::Add, A(), Int(1))), OnOff(true)), "Sw(a + 1) = On"});
  cases.push_back({Bin(BinaryOp::Mul, Bin(BinaryOp::Add, Real(0.5), Un(UnaryOp::Negate, Real(0.0))), Real(12.70)), "(0.5 + -0.0) * 12.7"});
  return cases;
}

TEST(FmtExpressions, MinimalParenthesesKeepTheTree) {
  for (const ExprCase& c : ExprCases()) EXPECT_EQ(PrintExpr(*c.expr), c.text);
}

TEST(FmtExpressions, PointExpressions) {
  ir::PointExpr named = WithOffset(WithOffset(Named("C1"), false, ir::Axis::X, Bin(BinaryOp::Mul, A(), Real(55))),
                                   true, ir::Axis::U, Int(90));
  EXPECT_EQ(PrintPointExpr(named), "C1 + X(a * 55.0) - U(90)");

  ir::PointExpr literal;
  literal.base = XY(212.40, 35.50, -12.00, 0);
  EXPECT_EQ(PrintPointExpr(literal), "XY(212.4, 35.5, -12.0, 0.0)");

  ir::PointExpr pallet;
  pallet.base = ir::PalletPoint{Int(1), Var("i"), Bin(BinaryOp::Add, Var("j"), Int(1))};
  EXPECT_EQ(PrintPointExpr(WithOffset(std::move(pallet), false, ir::Axis::Z, Real(5))),
            "Pallet(1, i, j + 1) + Z(5.0)");

  ir::PointExpr single;
  single.base = ir::PalletPoint{Int(2), Var("k"), nullptr};
  EXPECT_EQ(PrintPointExpr(single), "Pallet(2, k)");
}

// ------------------------------------------------------------ statements

TEST(FmtStatements, EveryStatementWithCommentsAndBlankLines) {
  ir::Program program;
  program.items = Body(
      S(ir::Comment{" layer_a.place - three layers"}),
      S(ir::ProgramDecl{"LayerA", {}}), S(ir::UnitsDecl{"mm", {}}),
      S(ir::FixtureDecl{"Board", {}}, " geometry from the cell file"),
      Blank(S(ir::LocalDecl{"Tray", {}, XY(100, 50, 0, 0), "", {}})),
      S(ir::LocalDecl{"Sub", {}, XY(1, 2, 0, 90), "Tray", {}}),
      S(ir::PointDecl{"Feed0805", {}, false, XY(212.40, 35.50, -12.00, 0), "", {}}),
      S(ir::PointDecl{"C1", {}, false, XY(12.70, 8.25, -3.00, 90), "Board", {}}),
      S(ir::PointDecl{"U3", {}, true, XY(171.204, 97.311, -3.00, 0), "Board", {}}, "taught"),
      S(ir::PalletDecl{1, {}, {"P1", "P2", "P3"}, {}, 4, {}, 3, {}}), S(ir::VacuumDecl{2, {}}),
      S(ir::VarDecl{ir::VarType::Integer, {"a", "b"}, {}}), S(ir::VarDecl{ir::VarType::Real, {"d"}, {}}));

  ir::Block body;
  body.push_back(S(ir::Comment{"  indented comment, spaces kept"}));
  body.push_back(S(ir::VarDecl{ir::VarType::Integer, {"layer"}, {}}));
  body.push_back(S(ir::Assign{"d", Bin(BinaryOp::Mul, Real(0.5), Var("a"))}));
  body.push_back(S(ir::Motion{ir::MotionKind::Jump, Named("Feed0805"), Real(-5), {}}, " above the feeder"));
  body.push_back(S(ir::Motion{ir::MotionKind::Go, Named("C1"), nullptr, {}}));
  body.push_back(S(ir::Motion{ir::MotionKind::Move, WithOffset(Named("C1"), true, ir::Axis::Y, Real(1)), nullptr, {}}));
  body.push_back(S(ir::PickPlace{ir::PickPlaceKind::Pick, Named("Feed0805"), Int(3), Real(-1)}));
  body.push_back(S(ir::PickPlace{ir::PickPlaceKind::Place, Named("U3"), nullptr, Int(0)}));
  body.push_back(Blank(S(ir::SetOutput{true, Int(5)})));
  body.push_back(S(ir::SetOutput{false, Bin(BinaryOp::Add, Var("a"), Int(1))}));
  body.push_back(S(ir::WaitSwitch{Int(4), false}));
  body.push_back(S(ir::WaitTime{Real(0.25)}));
  body.push_back(S(ir::WaitTime{Bin(BinaryOp::Mul, Real(0.5), Var("a"))}, "seconds"));

  ir::For loop;
  loop.var = "layer";
  loop.from = Int(0);
  loop.to = Int(2);
  loop.step = Int(1);
  loop.body = Body(S(ir::PickPlace{ir::PickPlaceKind::Place,
                                   WithOffset(Named("C1"), false, ir::Axis::X,
                                              Bin(BinaryOp::Mul, Var("layer"), Real(55.0))),
                                   nullptr, nullptr}));
  loop.end.comment = "next layer";
  loop.next_var = "";  // written as a bare Next
  ir::If branch;
  {
    ir::IfBranch first;
    first.condition = Bin(BinaryOp::Eq, Var("a"), Int(1));
    first.body = Body(S(ir::Call{"Feed", {}}));
    ir::IfBranch second;
    second.condition = Un(UnaryOp::Not, Sw(Int(3)));
    second.comment = "second";
    second.body = Body(S(ir::ExitFunction{}));
    ir::IfBranch last;
    last.comment = "otherwise";
    last.body = Body(S(ir::Comment{"nothing"}), S(ir::Scan{"Board", {}}));
    branch.branches.push_back(std::move(first));
    branch.branches.push_back(std::move(second));
    branch.branches.push_back(std::move(last));
    branch.end.comment = "done";
  }
  ir::Cycle cycle;
  cycle.fixture = "Board";
  cycle.body.push_back(S(std::move(loop), "three layers"));
  cycle.body.push_back(S(std::move(branch), "first"));
  cycle.end.comment = "";
  body.push_back(Blank(S(std::move(cycle))));

  ir::Function main_function;
  main_function.name = "Main";
  main_function.body = std::move(body);
  main_function.end.comment = "end of Main";
  program.items.push_back(Blank(S(std::move(main_function), "entry")));

  ir::Function feed;
  feed.name = "Feed";
  feed.body = Body(S(ir::Comment{""}));
  program.items.push_back(Blank(S(std::move(feed))));

  EXPECT_EQ(PrintPlace(program),
            "' layer_a.place - three layers\n"
            "Program LayerA\n"
            "Units mm\n"
            "Fixture Board  ' geometry from the cell file\n"
            "\n"
            "Local Tray = XY(100.0, 50.0, 0.0, 0.0)\n"
            "Local Sub = XY(1.0, 2.0, 0.0, 90.0) In Tray\n"
            "Point Feed0805 = XY(212.4, 35.5, -12.0, 0.0)\n"
            "Point C1 = XY(12.7, 8.25, -3.0, 90.0) In Board\n"
            "Taught Point U3 = XY(171.204, 97.311, -3.0, 0.0) On Board  'taught\n"
            "Pallet 1, P1, P2, P3, 4, 3\n"
            "Vacuum 2\n"
            "Integer a, b\n"
            "Real d\n"
            "\n"
            "Function Main  'entry\n"
            "  '  indented comment, spaces kept\n"
            "  Integer layer\n"
            "  d = 0.5 * a\n"
            "  Jump Feed0805 LimZ -5.0  ' above the feeder\n"
            "  Go C1\n"
            "  Move C1 - Y(1.0)\n"
            "  Pick Feed0805 Vacuum 3 LimZ -1.0\n"
            "  Place U3 LimZ 0\n"
            "\n"
            "  On 5\n"
            "  Off a + 1\n"
            "  Wait Sw(4) = Off\n"
            "  Wait 0.25\n"
            "  Wait 0.5 * a  'seconds\n"
            "\n"
            "  Cycle Board\n"
            "    For layer = 0 To 2 Step 1  'three layers\n"
            "      Place C1 + X(layer * 55.0)\n"
            "    Next layer  'next layer\n"
            "    If a = 1 Then  'first\n"
            "      Call Feed\n"
            "    ElseIf Not Sw(3) Then  'second\n"
            "      Exit Function\n"
            "    Else  'otherwise\n"
            "      'nothing\n"
            "      Scan Board\n"
            "    EndIf  'done\n"
            "  EndCycle\n"
            "Fend  'end of Main\n"
            "\n"
            "Function Feed\n"
            "  '\n"
            "Fend\n");
}

TEST(FmtStatements, NextKeepsAForeignVariableForTheChecker) {
  ir::For loop;
  loop.var = "Layer";
  loop.from = Int(1);
  loop.to = Int(3);
  loop.next_var = "LAYER";
  ir::Function f;
  f.name = "Main";
  f.body.push_back(S(std::move(loop)));
  ir::Program program;
  program.items.push_back(S(std::move(f)));
  EXPECT_EQ(PrintPlace(program), "Function Main\n  For Layer = 1 To 3\n  Next Layer\nFend\n");

  auto& changed = std::get<ir::For>(std::get<ir::Function>(program.items[0]->node).body[0]->node);
  changed.next_var = "other";
  EXPECT_EQ(PrintPlace(program), "Function Main\n  For Layer = 1 To 3\n  Next other\nFend\n");
}

TEST(FmtStatements, NoBlankLineAtTheTopOfTheFileAndEmptyProgramIsEmpty) {
  ir::Program program;
  EXPECT_EQ(PrintPlace(program), "");
  program.items.push_back(Blank(S(ir::ProgramDecl{"A", {}})));
  EXPECT_EQ(PrintPlace(program), "Program A\n");
}

TEST(FmtStatements, NoBlankLineOpensABlock) {
  ir::Function f;
  f.name = "Main";
  f.body = Body(Blank(S(ir::Call{"A", {}})), Blank(S(ir::Call{"B", {}})));
  ir::Program program;
  program.items.push_back(S(std::move(f)));
  EXPECT_EQ(PrintPlace(program), "Function Main\n  Call A\n\n  Call B\nFend\n");
}

// ------------------------------------------------------------ round trips

using Parsed = test::ParsedText;
Parsed Parse(const std::string& text) { return test::ParseText(text); }

// The two promises of fmt for a text that parses: printing is idempotent,
// and the printed text parses to the input's IR (up to the changes fmt makes
// on purpose, see ApplyCanonicalChanges). Returns the printed text.
std::string ExpectRoundTrip(const std::string& text) {
  Parsed input = Parse(text);
  EXPECT_TRUE(input.ok()) << input.diagnostics << "in:\n" << text;
  if (!input.ok()) return {};
  std::string printed = PrintPlace(input.program);
  Parsed output = Parse(printed);
  EXPECT_TRUE(output.ok()) << output.diagnostics << "in fmt's output:\n" << printed;
  if (!output.ok()) return printed;
  ApplyCanonicalChanges(input.program);
  EXPECT_EQ(DumpIr(output.program), DumpIr(input.program)) << "input:\n" << text << "\noutput:\n" << printed;
  EXPECT_EQ(PrintPlace(output.program), printed) << "fmt is not idempotent on:\n" << text;
  return printed;
}

TEST(FmtRoundTrip, ExpressionTablesParseBackToTheSameTree) {
  for (const ExprCase& c : ExprCases()) {
    Parsed parsed = Parse("Function F\n  r = " + c.text + "\nFend\n");
    ASSERT_TRUE(parsed.ok()) << parsed.diagnostics;
    const auto& body = std::get<ir::Function>(parsed.program.items.at(0)->node).body;
    const auto& assign = std::get<ir::Assign>(body.at(0)->node);
    EXPECT_EQ(DumpExpr(*assign.value), DumpExpr(*c.expr)) << c.text;
  }
}

TEST(FmtRoundTrip, NoLineEndsInWhitespace) {
  std::string printed = ExpectRoundTrip(
      "' header  \nProgram T ' name \t\nFunction Main\n  Call A '  \n  '\t\nFend ' end \n");
  EXPECT_EQ(printed, "' header\nProgram T  ' name\nFunction Main\n  Call A\n  '\nFend  ' end\n");
}

TEST(FmtRoundTrip, EveryPlaceFileInTheRepository) {
  namespace fs = std::filesystem;
  int formatted = 0;
  for (const char* folder : {"tests/golden", "examples"}) {
    fs::path root = fs::path(SMTCAL_SOURCE_DIR) / folder;
    if (!fs::exists(root)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
      if (!entry.is_regular_file() || entry.path().extension() != ".place") continue;
      std::ifstream in(entry.path(), std::ios::binary);
      std::stringstream text;
      text << in.rdbuf();
      if (!Parse(text.str()).ok()) continue;  // fail_ cases with syntax errors
      SCOPED_TRACE(entry.path().string());
      ExpectRoundTrip(text.str());
      ++formatted;
    }
  }
  EXPECT_GT(formatted, 0) << "no .place file found under " << SMTCAL_SOURCE_DIR;
}

// Messy but syntactically valid programs: every construct, keywords in any
// case, odd spacing and tabs, CRLF lines, comments and blank lines anywhere.
class ProgramGenerator {
 public:
  explicit ProgramGenerator(std::uint32_t seed) : rng_(seed) {}

  std::string Generate() {
    out_.clear();
    int items = Below(12) + 1;
    for (int i = 0; i < items; ++i) TopLevel();
    if (Chance(0.3)) out_ += "' last line without a newline";
    return out_;
  }

 private:
  int Below(int n) { return static_cast<int>(rng_() % static_cast<std::uint32_t>(n)); }
  bool Chance(double p) { return Below(1000) < static_cast<int>(p * 1000); }
  template <typename T>
  const T& Pick(const std::vector<T>& options) { return options[static_cast<std::size_t>(Below(static_cast<int>(options.size())))]; }

  // A keyword in canonical, lower, upper or mixed case.
  std::string Kw(std::string_view word) {
    std::string text(word);
    int style = Below(4);
    for (char& c : text) {
      if (style == 1 || (style == 3 && Chance(0.5))) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (style == 2) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    }
    return text;
  }
  std::string Name() {
    return Pick<std::string>({"a", "b", "Cnt", "x", "u", "layer_2", "_t", "P1", "Feed0805", "c1", "Board", "Main", "Helper"});
  }
  static bool WordChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.'; }
  // Tokens joined by random spaces and tabs (at least one between words).
  std::string J(std::initializer_list<std::string> tokens) {
    std::string text;
    for (const std::string& token : tokens) {
      if (token.empty()) continue;
      bool need = !text.empty() && WordChar(text.back()) && WordChar(token.front());
      if (!text.empty() && (need || Chance(0.3))) text += Pick<std::string>({" ", " ", "  ", "\t", " \t "});
      text += token;
    }
    return text;
  }
  std::string Number(bool integer) {
    if (integer || Chance(0.4)) return Pick<std::string>({"0", "1", "7", "42", "007", "511"});
    return Pick<std::string>({"1.5", ".5", "12.", "2.50e1", "1E3", "0.000001", "12.70", "3.14159", "1e-7",
                              "123456.789e3", "0.1", "55.8"});
  }
  std::string Signed() { return Pick<std::string>({"", "", "-", "+", "- "}) + Number(false); }
  std::string Expr(int depth) {
    if (depth <= 0 || Chance(0.3)) {
      switch (Below(5)) {
        case 0: return Number(false);
        case 1: return Name();
        case 2: return Kw(Chance(0.5) ? "On" : "Off");
        case 3: return J({Kw("Sw"), "(", Expr(depth - 1), ")"});
        default: return Number(true);
      }
    }
    switch (Below(4)) {
      case 0: return J({"(", Expr(depth - 1), ")"});
      case 1: return J({Pick<std::string>({"-", "+", Kw("Not")}), Expr(depth - 1)});
      default:
        return J({Expr(depth - 1),
                  Pick<std::string>({"+", "-", "*", "/", Kw("Mod"), "=", "<>", "<", ">", "<=", ">=", Kw("And"),
                                     Kw("Or"), Kw("Xor")}),
                  Expr(depth - 1)});
    }
  }
  std::string Coords() {
    return J({Kw("XY"), "(", Signed(), ",", Signed(), ",", Signed(), ",", Signed(), ")"});
  }
  std::string PointExpr() {
    std::string text;
    switch (Below(3)) {
      case 0: text = Name(); break;
      case 1: text = Coords(); break;
      default:
        text = J({Kw("Pallet"), "(", Expr(2), ",", Expr(2), Chance(0.5) ? J({",", Expr(2)}) : "", ")"});
    }
    for (int n = Below(3); n > 0; --n) {
      text = J({text, Chance(0.5) ? "+" : "-", Pick<std::string>({"X", "y", "Z", "u"}), "(", Expr(2), ")"});
    }
    return text;
  }
  std::string CommentText() {
    std::string text;
    for (int n = Below(12); n > 0; --n) {
      text += Pick<std::string>({"a", "Z", "0", " ", " ", "'", "\t", "(", "=", "µm", "°", "-"});
    }
    return text;
  }
  // One line: maybe blank lines and a comment line before it, random
  // indentation, maybe a trailing comment, \n or \r\n.
  void Line(const std::string& text) {
    for (int n = Chance(0.15) ? Below(3) + 1 : 0; n > 0; --n) out_ += Pick<std::string>({"", "  ", "\t"}) + Eol();
    if (Chance(0.1)) out_ += Indent() + "'" + CommentText() + Eol();
    out_ += Indent() + text;
    if (Chance(0.25)) out_ += Pick<std::string>({"", " ", "   ", "\t"}) + "'" + CommentText();
    out_ += Eol();
  }
  std::string Indent() { return Pick<std::string>({"", "", "  ", "    ", "\t", " "}); }
  std::string Eol() { return Chance(0.1) ? "\r\n" : "\n"; }

  void TopLevel() {
    switch (Below(11)) {
      case 0: Line(J({Kw("Program"), Name()})); break;
      case 1: Line(J({Kw("Units"), Pick<std::string>({"mm", "MM", "inch"})})); break;
      case 2: Line(J({Kw("Fixture"), Name()})); break;
      case 3: Line(J({Kw("Local"), Name(), "=", Coords(), Chance(0.5) ? J({Kw("In"), Name()}) : ""})); break;
      case 4: Line(J({Kw("Point"), Name(), "=", Coords(), Chance(0.5) ? J({Kw("In"), Name()}) : ""})); break;
      case 5:
        Line(J({Kw("Taught"), Kw("Point"), Name(), "=", Coords(), Chance(0.5) ? J({Kw("On"), Name()}) : ""}));
        break;
      case 6:
        Line(J({Kw("Pallet"), Number(true), ",", Name(), ",", Name(), ",", Name(), ",", Number(true), ",",
                Number(true)}));
        break;
      case 7: Line(J({Kw("Vacuum"), Number(true)})); break;
      case 8: Line(VarDecl()); break;
      default: Function();
    }
  }
  std::string VarDecl() {
    std::string text = J({Kw(Chance(0.5) ? "Integer" : "Real"), Name()});
    for (int n = Below(3); n > 0; --n) text = J({text, ",", Name()});
    return text;
  }
  void Function() {
    Line(J({Kw("Function"), Name(), Chance(0.3) ? "()" : ""}));
    Block(1);
    Line(Kw("Fend"));
  }
  void Block(int nesting) {
    for (int n = Below(6); n > 0; --n) Statement(nesting);
  }
  void Statement(int nesting) {
    int kinds = nesting < 4 ? 16 : 12;
    switch (Below(kinds)) {
      case 0: Line(VarDecl()); break;
      case 1: Line(J({Name(), "=", Expr(3)})); break;
      case 2:
        Line(J({Kw(Pick<std::string>({"Jump", "Go", "Move"})), PointExpr(), Chance(0.4) ? J({Kw("LimZ"), Expr(2)}) : ""}));
        break;
      case 3:
        Line(J({Kw(Chance(0.5) ? "Pick" : "Place"), PointExpr(), Chance(0.4) ? J({Kw("Vacuum"), Expr(2)}) : "",
                Chance(0.4) ? J({Kw("LimZ"), Expr(2)}) : ""}));
        break;
      case 4: Line(J({Kw(Chance(0.5) ? "On" : "Off"), Expr(2)})); break;
      case 5: Line(J({Kw("Wait"), Kw("Sw"), "(", Expr(2), ")", "=", Kw(Chance(0.5) ? "On" : "Off")})); break;
      case 6: Line(J({Kw("Wait"), Expr(3)})); break;
      case 7: Line(J({Kw("Call"), Name(), Chance(0.3) ? "()" : ""})); break;
      case 8: Line(J({Kw("Scan"), Name()})); break;
      case 9: Line(J({Kw("Exit"), Kw("Function")})); break;
      case 10: Line("'" + CommentText()); break;
      case 11: Line(J({Name(), "=", Expr(1)})); break;
      case 12: {
        std::string var = Name();
        Line(J({Kw("For"), var, "=", Expr(2), Kw("To"), Expr(2), Chance(0.4) ? J({Kw("Step"), Expr(2)}) : ""}));
        Block(nesting + 1);
        std::string next_name = Pick<std::string>({"", var, Kw(var), Name()});
        Line(J({Kw("Next"), next_name}));
        break;
      }
      case 13:
      case 14: {
        Line(J({Kw("If"), Expr(3), Kw("Then")}));
        Block(nesting + 1);
        for (int n = Below(3); n > 0; --n) {
          Line(J({Kw("ElseIf"), Expr(3), Kw("Then")}));
          Block(nesting + 1);
        }
        if (Chance(0.5)) {
          Line(Kw("Else"));
          Block(nesting + 1);
        }
        Line(Kw("EndIf"));
        break;
      }
      default:
        Line(J({Kw("Cycle"), Name()}));
        Block(nesting + 1);
        Line(Kw("EndCycle"));
    }
  }

  std::mt19937 rng_;
  std::string out_;
};

// SMTCAL_FMT_SEED=n runs one other seed (e.g. to reproduce a failure).
TEST(FmtRoundTrip, RandomMessyPrograms) {
  std::uint32_t first_seed = 1;
  int count = 300;
  if (const char* seed = std::getenv("SMTCAL_FMT_SEED")) {
    first_seed = static_cast<std::uint32_t>(std::strtoul(seed, nullptr, 10));
    count = 1;
  }
  for (std::uint32_t seed = first_seed; seed < first_seed + static_cast<std::uint32_t>(count); ++seed) {
    SCOPED_TRACE(fmt::format("seed {} (rerun with SMTCAL_FMT_SEED={})", seed, seed));
    std::string text = ProgramGenerator(seed).Generate();
    ExpectRoundTrip(text);
    if (HasFailure()) break;  // one failing program is enough to read
  }
}

// ------------------------------------------------------------ the reference

// Every example in docs/language.md is valid and canonical. ```place blocks
// are whole files; ```place-statements blocks are statements, checked as the
// body of a function.
TEST(FmtDocs, LanguageReferenceExamplesParseAndAreCanonical) {
  std::ifstream in(std::filesystem::path(SMTCAL_SOURCE_DIR) / "docs" / "language.md");
  ASSERT_TRUE(in) << "docs/language.md not found";
  std::string line;
  std::string block;
  std::string kind;  // "" outside a block
  int block_line = 0;
  int line_number = 0;
  int examples = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (kind.empty()) {
      if (line == "```place" || line == "```place-statements") {
        kind = line.substr(3);
        block.clear();
        block_line = line_number;
      }
      continue;
    }
    if (line != "```") {
      block += line + "\n";
      continue;
    }
    SCOPED_TRACE(fmt::format("docs/language.md:{}", block_line));
    std::string text = block;
    if (kind == "place-statements") {
      text = "Function Doc\n";
      std::istringstream lines(block);
      for (std::string body_line; std::getline(lines, body_line);) {
        text += body_line.empty() ? "\n" : "  " + body_line + "\n";
      }
      text += "Fend\n";
    }
    EXPECT_EQ(ExpectRoundTrip(text), text) << "not in canonical form";
    ++examples;
    kind.clear();
  }
  EXPECT_TRUE(kind.empty()) << "unclosed ``` block at docs/language.md:" << block_line;
  EXPECT_GE(examples, 20);
}

// ------------------------------------------------------------ smtcal fmt

// A scratch folder per test, and the real executable run in it.
class FmtCommand : public testing::Test {
 protected:
  using Run = test::SmtcalRun;

  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           fmt::format("smtcal_fmt_{}_{}", ::getpid(), testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string PathOf(const std::string& name) const { return (dir_ / name).string(); }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  std::string Read(const std::string& name) const { return test::ReadFileText(dir_ / name); }
  // `args` run in the scratch folder; stdin from the file `input` if given.
  Run Smtcal(const std::string& args, const std::string& input = "") const {
    return test::RunSmtcal(args, dir_, input.empty() ? "" : Read(input));
  }

  static constexpr const char* kMessy = "program A\nfunction   MAIN\njump p1   limz -5.00\nfend";
  static constexpr const char* kCanonical = "Program A\nFunction MAIN\n  Jump p1 LimZ -5.0\nFend\n";
  std::filesystem::path dir_;
};

TEST_F(FmtCommand, PrintsToStdoutByDefaultAndReadsStdin) {
  Write("a.place", kMessy);
  Run run = Smtcal("fmt a.place");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, kCanonical);
  EXPECT_EQ(run.err, "");
  EXPECT_EQ(Read("a.place"), kMessy);

  Run piped = Smtcal("fmt -", "a.place");
  EXPECT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(piped.out, kCanonical);
}

TEST_F(FmtCommand, WritesTheOutputFile) {
  Write("a.place", kMessy);
  Run run = Smtcal("fmt a.place -o b.place");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, "");
  EXPECT_EQ(Read("b.place"), kCanonical);
  EXPECT_EQ(Read("a.place"), kMessy);
}

TEST_F(FmtCommand, InPlaceRewritesOnlyAFileThatChanges) {
  Write("a.place", kMessy);
  Run run = Smtcal("fmt --in-place a.place");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, "");
  EXPECT_EQ(Read("a.place"), kCanonical);

  // A canonical file is not touched: its modification time stays.
  auto old_time = std::filesystem::file_time_type::clock::now() - std::chrono::hours(24);
  std::filesystem::last_write_time(dir_ / "a.place", old_time);
  EXPECT_EQ(Smtcal("fmt --in-place a.place").exit_code, 0);
  EXPECT_EQ(std::filesystem::last_write_time(dir_ / "a.place"), old_time);
  // No temporary file is left behind.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 1);
}

TEST_F(FmtCommand, CheckNamesAFileNotInCanonicalFormAndWritesNothing) {
  Write("a.place", kMessy);
  Run messy = Smtcal("fmt --check a.place");
  EXPECT_EQ(messy.exit_code, 1);
  EXPECT_EQ(messy.out, "a.place\n");
  EXPECT_EQ(messy.err, "");
  EXPECT_EQ(Read("a.place"), kMessy);

  Write("b.place", kCanonical);
  Run canonical = Smtcal("fmt --check b.place");
  EXPECT_EQ(canonical.exit_code, 0);
  EXPECT_EQ(canonical.out, "");
  EXPECT_EQ(canonical.err, "");
}

TEST_F(FmtCommand, ConflictingOptionsAreUsageErrors) {
  Write("a.place", kMessy);
  for (const char* args : {"fmt a.place -o b.place --in-place", "fmt a.place --check -o b.place",
                           "fmt a.place --check --in-place", "fmt --in-place -", "fmt"}) {
    SCOPED_TRACE(args);
    Run run = Smtcal(args, "a.place");
    EXPECT_EQ(run.exit_code, 2);
    EXPECT_NE(run.err, "");
  }
  EXPECT_EQ(Read("a.place"), kMessy);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "b.place"));
}

TEST_F(FmtCommand, ASyntaxErrorIsReportedAndNothingIsWritten) {
  const std::string broken = "Program A\nFunction Main\n  Jump P1 LimZ\nFend\n";
  Write("a.place", broken);
  for (const char* args : {"fmt a.place", "fmt --in-place a.place", "fmt a.place -o b.place", "fmt --check a.place"}) {
    SCOPED_TRACE(args);
    Run run = Smtcal(args);
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_EQ(run.out, "");
    EXPECT_NE(run.err.find("a.place:3:"), std::string::npos) << run.err;
  }
  EXPECT_EQ(Read("a.place"), broken);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "b.place"));

  Run json = Smtcal("fmt a.place --diagnostics=json");
  EXPECT_EQ(json.exit_code, 1);
  EXPECT_EQ(json.err.front(), '[') << json.err;
}

TEST_F(FmtCommand, AMissingFileIsAnIoError) {
  Run run = Smtcal("fmt nowhere.place");
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.err.find("nowhere.place"), std::string::npos);
}

}  // namespace
}  // namespace smtcal
