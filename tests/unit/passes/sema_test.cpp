// The semantic checks on IR built by hand: the symbol table, constant
// folding, and each check pass (header, names, types, ranges, fixture scope
// across Calls, reachability). The golden suite tests/golden/check/ runs the
// same checks on parsed files and shows the exact messages.
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ir/constant_fold.h"
#include "ir/symbols.h"
#include "passes/pass_manager.h"
#include "tests/unit/ir/ir_builder.h"

namespace smtcal {
namespace {

using ir::BinaryOp;
using ir::VarType;
using test::IrBuilder;

std::vector<DiagKind> Kinds(const Diagnostics& diags) {
  std::vector<DiagKind> kinds;
  for (const Diagnostic& diag : diags.all()) kinds.push_back(diag.kind);
  return kinds;
}

// Runs one pass (or all of them, when empty) on the built program.
std::unique_ptr<Diagnostics> Check(IrBuilder& b, const std::string& pass = "") {
  ir::Program& program = b.Finish();
  auto diags = std::make_unique<Diagnostics>(b.sources);
  std::vector<std::string> names;
  if (!pass.empty()) names.push_back(pass);
  EXPECT_TRUE(RunPasses(program, *diags, names, /*verify_each=*/true).ok());
  return diags;
}

// Program T, Units mm, Fixture Board, Fixture Tray, Vacuum 8, a few points.
void Prelude(IrBuilder& b) {
  b.Header("T");
  b.Fixture("Board");
  b.Fixture("Tray");
  b.Vacuum(8);
  b.Point("Feed0805", {212.4, 35.5, -12, 0});
  b.Point("C1", {12.7, 8.25, -3, 90}, "Board");
  b.Point("T1", {1, 1, -3, 0}, "Tray");
}

// ---------------------------------------------------------------- symbols

TEST(SymbolTable, OneCaseInsensitiveNamespaceWhereTheFirstDefinitionWins) {
  IrBuilder b;
  b.Fixture("Board");
  b.Point("C1", {0, 0, 0, 0}, "Board");
  b.Function("c1");
  b.End();
  b.Variables(VarType::Integer, {"count", "COUNT"});
  ir::Program& program = b.Finish();
  sema::SymbolTable table = sema::SymbolTable::Build(program);

  const sema::Symbol* c1 = table.Find("c1");
  ASSERT_NE(c1, nullptr);
  EXPECT_EQ(c1->kind, sema::SymbolKind::Point);
  EXPECT_EQ(c1->name, "C1");
  ASSERT_EQ(table.duplicates().size(), 2u);
  EXPECT_EQ(table.duplicates()[0].again.name, "c1");
  EXPECT_EQ(table.duplicates()[0].first.name, "C1");
  EXPECT_EQ(table.duplicates()[1].again.name, "COUNT");
  EXPECT_EQ(table.Find("Count")->var_type, VarType::Integer);
  EXPECT_EQ(table.NamesOf({sema::SymbolKind::Fixture, sema::SymbolKind::Variable}),
            (std::vector<std::string>{"Board", "count"}));
}

// NameIndex against a plain map of lowercased names, on random names that
// differ in case, share prefixes and collide in the table's low bits (seed
// printed; SMTCAL_TEST_SEED repeats a run).
TEST(SymbolTable, NameIndexAgreesWithAMapOfLowercaseNames) {
  const char* seed_text = std::getenv("SMTCAL_TEST_SEED");
  const std::uint64_t seed = seed_text != nullptr ? std::strtoull(seed_text, nullptr, 10) : 19940101;
  SCOPED_TRACE(::testing::Message() << "SMTCAL_TEST_SEED=" << seed);
  std::mt19937_64 rng(seed);
  const std::string letters = "aAbBcCpP_0123456789";
  std::deque<sema::Symbol> symbols;
  sema::NameIndex index;
  std::map<std::string, const sema::Symbol*> reference;
  for (int i = 0; i < 20000; ++i) {
    std::string name(1, "PpCcRr"[rng() % 6]);
    for (std::size_t n = rng() % 6; n > 0; --n) name += letters[rng() % letters.size()];
    sema::Symbol& symbol = symbols.emplace_back();
    symbol.name = name;
    auto [it, added] = reference.emplace(sema::Lowercase(name), &symbol);
    EXPECT_EQ(index.Insert(symbol), added ? nullptr : it->second) << name;
    // Every lookup so far, in another case, finds the first definition.
    if (i % 97 == 0) {
      for (const auto& [lower, first] : reference) {
        std::string upper = lower;
        for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        ASSERT_EQ(index.Find(upper), first) << upper;
      }
    }
  }
  EXPECT_EQ(index.Find("Q"), nullptr);
  EXPECT_EQ(index.Find(""), nullptr);
  EXPECT_EQ(sema::NameIndex().Find("P1"), nullptr);
}

// A point named in a statement remembers what its name was found as, for
// the table that found it only: another table (built after a pass changed
// the declarations) looks the name up again.
TEST(SymbolTable, NamedPointsRememberTheirSymbolPerTable) {
  IrBuilder b;
  b.Fixture("Board");
  b.Point("C1", {0, 0, 0, 0}, "Board");
  ir::Program& program = b.Finish();
  ir::NamedPoint use{"c1", 2};
  sema::SymbolTable first = sema::SymbolTable::Build(program);
  const sema::Symbol* found = first.Find(use);
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(found, first.Find("C1"));
  EXPECT_EQ(use.symbol, found);
  EXPECT_EQ(use.symbol_table, first.id());
  EXPECT_EQ(first.Find(use), found);

  sema::SymbolTable second = sema::SymbolTable::Build(program);
  EXPECT_NE(second.id(), first.id());
  EXPECT_EQ(second.Find(use), second.Find("C1"));
  EXPECT_NE(second.Find(use), found);  // the second table's own symbol
  ir::NamedPoint missing{"C2", 2};
  EXPECT_EQ(second.Find(missing), nullptr);
  EXPECT_EQ(missing.symbol_table, second.id());
  EXPECT_EQ(second.Find(missing), nullptr);
}

TEST(SymbolTable, DeclarationsRangeUnderlinesTheName) {
  IrBuilder b;
  ir::Stmt& stmt = b.Point("Feed", {0, 0, 0, 0});
  b.Variables(VarType::Real, {"a", "bee"});
  ir::Program& program = b.Finish();
  sema::SymbolTable table = sema::SymbolTable::Build(program);
  EXPECT_EQ(table.Find("feed")->range.begin, (SourceLoc{IrBuilder::kFile, stmt.loc.line, 7}));
  EXPECT_EQ(table.Find("feed")->range.length, 4u);
  EXPECT_EQ(table.Find("bee")->range.begin.column, 9u);
}

TEST(SymbolTable, FixtureOfPointsFollowsLocalChainsAndTaughtFixtures) {
  IrBuilder b;
  b.Fixture("Board");
  b.Local("Layer", {10, 0, 0, 0}, "Board");
  b.Local("Site", {1, 1, 0, 0}, "Layer");
  b.Local("Free", {0, 0, 0, 0});
  b.Local("LoopA", {0, 0, 0, 0}, "LoopB");
  b.Local("LoopB", {0, 0, 0, 0}, "LoopA");
  b.Point("Direct", {0, 0, 0, 0}, "Board");
  b.Point("Deep", {0, 0, 0, 0}, "Site");
  b.Point("Base", {0, 0, 0, 0});
  b.Point("Loose", {0, 0, 0, 0}, "Free");
  b.Point("Looping", {0, 0, 0, 0}, "LoopA");
  b.Taught("U3", {0, 0, 0, 0}, "Board");
  ir::Program& program = b.Finish();
  sema::SymbolTable table = sema::SymbolTable::Build(program);
  auto fixture = [&](const char* point) {
    const sema::Symbol* found = table.FixtureOfPoint(*table.Find(point));
    return found == nullptr ? std::string("-") : found->name;
  };
  EXPECT_EQ(fixture("Direct"), "Board");
  EXPECT_EQ(fixture("Deep"), "Board");
  EXPECT_EQ(fixture("U3"), "Board");
  EXPECT_EQ(fixture("Base"), "-");
  EXPECT_EQ(fixture("Loose"), "-");
  EXPECT_EQ(fixture("Looping"), "-");
}

TEST(SymbolTable, PalletBelongsToTheFixtureOfCornersInOneFrame) {
  IrBuilder b;
  b.Fixture("Board");
  b.Point("A", {0, 0, 0, 0}, "Board");
  b.Point("B", {10, 0, 0, 0}, "Board");
  b.Point("C", {0, 10, 0, 0}, "Board");
  b.Taught("D", {0, 10, 0, 0}, "Board");
  b.PalletDecl(1, {"A", "B", "C"}, 2, 2);
  b.PalletDecl(2, {"A", "B", "D"}, 2, 2);  // taught on Board is another frame than In Board
  ir::Program& program = b.Finish();
  sema::SymbolTable table = sema::SymbolTable::Build(program);
  ASSERT_NE(table.FixtureOfPallet(1), nullptr);
  EXPECT_EQ(table.FixtureOfPallet(1)->name, "Board");
  EXPECT_EQ(table.FixtureOfPallet(2), nullptr);
  EXPECT_EQ(table.FixtureOfPallet(3), nullptr);
  EXPECT_EQ(table.PalletNumbers(), (std::vector<int>{1, 2}));
}

TEST(SymbolTable, LocalScopeRefusesClashesAndFallsBackToGlobals) {
  IrBuilder b;
  b.Variables(VarType::Real, {"speed"});
  b.Point("P1", {0, 0, 0, 0});
  ir::Program& program = b.Finish();
  sema::SymbolTable table = sema::SymbolTable::Build(program);
  sema::LocalScope scope(table);
  sema::Symbol local;
  local.kind = sema::SymbolKind::Variable;
  local.name = "i";
  local.global = false;
  EXPECT_EQ(scope.Declare(local), nullptr);
  EXPECT_NE(scope.Declare(local), nullptr);  // twice
  local.name = "SPEED";
  const sema::Symbol* clash = scope.Declare(local);  // reported, and then hides the global
  ASSERT_NE(clash, nullptr);
  EXPECT_TRUE(clash->global);
  EXPECT_FALSE(scope.Find("speed")->global);
  EXPECT_EQ(scope.Find("I")->global, false);
  EXPECT_EQ(scope.Find("p1")->kind, sema::SymbolKind::Point);
  EXPECT_EQ(scope.VariableNames(), (std::vector<std::string>{"i", "SPEED"}));
  EXPECT_EQ(sema::DescribeKind(*scope.Find("i")), "an Integer local variable");
  EXPECT_EQ(sema::DescribeKind(*table.Find("speed")), "a Real variable");
}

// ---------------------------------------------------------------- folding

TEST(ConstantFold, FoldsLiteralsUnaryMinusAndPlusMinusTimes) {
  IrBuilder b;
  auto e = b.Binary(BinaryOp::Sub, b.Int(500), b.Binary(BinaryOp::Mul, b.Int(2), b.Unary(ir::UnaryOp::Negate, b.Int(7))));
  std::optional<sema::Constant> value = sema::FoldConstant(e.get());
  ASSERT_TRUE(value);
  EXPECT_EQ(value->value, 514);
  EXPECT_TRUE(value->is_integer);
  EXPECT_EQ(sema::FoldInteger(e.get()), 514);

  auto real = b.Binary(BinaryOp::Add, b.Int(1), b.Real(0.5));
  EXPECT_FALSE(sema::FoldConstant(real.get())->is_integer);
  EXPECT_EQ(sema::FoldInteger(real.get()), std::nullopt);
}

TEST(ConstantFold, LeavesEverythingElseToRunTime) {
  IrBuilder b;
  auto variable = b.Binary(BinaryOp::Add, b.Var("i"), b.Int(1));
  auto division = b.Binary(BinaryOp::Div, b.Int(4), b.Int(2));
  auto sw = b.Sw(b.Int(3));
  auto huge = b.Binary(BinaryOp::Mul, b.Real(1e300), b.Real(1e300));
  EXPECT_EQ(sema::FoldConstant(variable.get()), std::nullopt);
  EXPECT_EQ(sema::FoldConstant(division.get()), std::nullopt);
  EXPECT_EQ(sema::FoldConstant(sw.get()), std::nullopt);
  EXPECT_EQ(sema::FoldConstant(huge.get()), std::nullopt);
  EXPECT_EQ(sema::FoldConstant(nullptr), std::nullopt);
}

// ---------------------------------------------------------------- header

TEST(CheckHeader, AcceptsAWellFormedHeader) {
  IrBuilder b;
  b.Comment("a comment may come first");
  b.Header("T");
  b.Function("MAIN");
  b.End();
  EXPECT_EQ(Kinds(*Check(b, "check-header")), std::vector<DiagKind>{});
}

TEST(CheckHeader, ReportsMissingAndMisplacedHeaderLines) {
  IrBuilder b;
  b.Fixture("Board");
  b.Program("T");
  b.Units("inch");
  b.Units("mm");
  b.Program("Again");
  EXPECT_EQ(Kinds(*Check(b, "check-header")),
            (std::vector<DiagKind>{DiagKind::ProgramNotFirst, DiagKind::UnsupportedUnit,
                                   DiagKind::RepeatedDeclaration, DiagKind::RepeatedDeclaration,
                                   DiagKind::MissingMain}));
}

TEST(CheckHeader, AnEmptyProgramLacksEverything) {
  IrBuilder b;
  auto diags = Check(b, "check-header");
  EXPECT_EQ(Kinds(*diags),
            (std::vector<DiagKind>{DiagKind::MissingProgram, DiagKind::MissingUnits, DiagKind::MissingMain}));
}

// ---------------------------------------------------------------- names

TEST(CheckNames, DuplicatesAreCaseInsensitiveWithANoteAtTheFirst) {
  IrBuilder b;
  b.Header("T");
  ir::Stmt& first = b.Point("C1", {0, 0, 0, 0});
  ir::Stmt& again = b.Function("c1");
  b.End();
  auto diags = Check(b, "check-names");
  ASSERT_EQ(Kinds(*diags), std::vector<DiagKind>{DiagKind::DuplicateName});
  const Diagnostic& diag = diags->all()[0];
  EXPECT_EQ(diag.message, "'c1' is already defined as a point; names are case-insensitive, so rename one of them");
  EXPECT_EQ(diag.range.begin.line, again.loc.line);
  EXPECT_EQ(diag.range.begin.column, 10u);  // the name, not 'Function'
  ASSERT_EQ(diag.notes.size(), 1u);
  EXPECT_EQ(diag.notes[0].first.begin.line, first.loc.line);
  EXPECT_EQ(diag.notes[0].second, "'C1' was first defined here");
}

TEST(CheckNames, UndefinedNamesSuggestTheClosestOfTheRightKind) {
  IrBuilder b;
  Prelude(b);
  b.Function("Main");
  b.Pick(b.Named("Feed805"));
  b.Cycle("Bord");
  b.End();
  b.Call("Maiin");
  b.Assign("countr", b.Int(1));
  b.End();
  b.Variables(VarType::Integer, {"counter"});
  auto diags = Check(b, "check-names");
  ASSERT_EQ(diags->all().size(), 4u);
  EXPECT_EQ(diags->all()[0].message, "undefined point 'Feed805'; did you mean 'Feed0805'?");
  EXPECT_EQ(diags->all()[1].message, "undefined fixture 'Bord'; did you mean 'Board'?");
  EXPECT_EQ(diags->all()[2].message, "undefined function 'Maiin'; did you mean 'Main'?");
  EXPECT_EQ(diags->all()[3].message, "undefined variable 'countr'; did you mean 'counter'?");
}

TEST(CheckNames, NamesOfTheWrongKindSayBothKinds) {
  IrBuilder b;
  Prelude(b);
  b.Local("Layer", {0, 0, 0, 0}, "Board");
  b.Point("P", {0, 0, 0, 0}, "C1");              // a point as a frame
  b.Taught("Q", {0, 0, 0, 0}, "Layer");           // taught On a Local
  b.Variables(VarType::Integer, {"i"});
  b.Function("Main");
  b.Jump(b.Named("i"));                           // a variable as a point
  b.Cycle("Layer");                               // a Local in Cycle
  b.End();
  b.Call("Board");
  b.End();
  auto diags = Check(b, "check-names");
  ASSERT_EQ(diags->all().size(), 5u);
  EXPECT_EQ(diags->all()[0].message,
            "'In' needs a frame (a Fixture or a Local), but 'C1' is a point");
  EXPECT_EQ(diags->all()[1].message, "a taught point's 'On' needs a fixture, but 'Layer' is a Local frame");
  EXPECT_EQ(diags->all()[2].message, "Jump needs a point, but 'i' is an Integer variable");
  EXPECT_EQ(diags->all()[3].message, "Cycle needs a fixture, but 'Layer' is a Local frame");
  EXPECT_EQ(diags->all()[4].message, "Call needs a function, but 'Board' is a fixture");
  for (const Diagnostic& diag : diags->all()) EXPECT_EQ(diag.notes.size(), 1u);
}

TEST(CheckNames, TopLevelDeclarationsAreOrderIndependent) {
  IrBuilder b;
  b.Header("T");
  b.Function("Main");
  b.Cycle("Board");
  b.Place(b.Named("C1"));
  b.Call("Later");
  b.End();
  b.Assign("total", b.Int(0));
  b.End();
  b.Function("Later");
  b.End();
  b.Point("C1", {0, 0, 0, 0}, "Layer");
  b.Local("Layer", {0, 0, 0, 0}, "Board");
  b.Fixture("Board");
  b.Variables(VarType::Integer, {"total"});
  EXPECT_EQ(Kinds(*Check(b, "check-names")), std::vector<DiagKind>{});
}

TEST(CheckNames, LocalsMustNotShadowGlobalsAndComeBeforeTheirUse) {
  IrBuilder b;
  b.Header("T");
  b.Variables(VarType::Real, {"speed"});
  b.Function("Main");
  b.Assign("k", b.Int(1));
  b.Variables(VarType::Integer, {"speed", "k", "k"});
  b.For("k", b.Int(1), b.Int(3));
  b.Variables(VarType::Integer, {"inner"});
  b.Next();
  b.Assign("inner", b.Int(2));  // function scope: visible after the For
  b.End();
  auto diags = Check(b, "check-names");
  EXPECT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::UndefinedName, DiagKind::LocalShadowsGlobal,
                                                  DiagKind::DuplicateName}));
  ASSERT_EQ(diags->all()[0].notes.size(), 1u);
  EXPECT_EQ(diags->all()[0].notes[0].second, "'k' is declared later, here; declare it before its first use");
  EXPECT_EQ(diags->all()[2].message,
            "'k' is already defined as an Integer local variable; names are case-insensitive, so rename one of them");
}

TEST(CheckNames, PalletsAreNamedByUniqueDeclaredNumbers) {
  IrBuilder b;
  Prelude(b);
  b.PalletDecl(1, {"Feed0805", "Feed0805", "Feed0805"}, 2, 2);
  b.PalletDecl(1, {"Feed0805", "Feed0805", "Feed0805"}, 2, 2);
  b.PalletDecl(2, {"Feed0805", "Nope", "Feed0805"}, 2, 2);
  b.Function("Main");
  b.Pick(b.Pallet(b.Int(3), b.Int(1)));
  b.Pick(b.Pallet(b.Var("n"), b.Int(1)));  // not constant: undefined name only
  b.Pick(b.Pallet(b.Int(99), b.Int(1)));   // out of range: check-ranges' job
  b.End();
  auto diags = Check(b, "check-names");
  EXPECT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::DuplicatePallet, DiagKind::UndefinedName,
                                                  DiagKind::UndefinedPallet, DiagKind::UndefinedName}));
  EXPECT_EQ(diags->all()[2].message, "pallet 3 is not defined; the defined pallets are 1, 2");
}

TEST(CheckNames, LoopsOfLocalFramesAreReportedOnce) {
  IrBuilder b;
  b.Header("T");
  b.Local("A", {0, 0, 0, 0}, "B");
  b.Local("B", {0, 0, 0, 0}, "C");
  b.Local("C", {0, 0, 0, 0}, "A");
  b.Local("Self", {0, 0, 0, 0}, "Self");
  b.Local("Tail", {0, 0, 0, 0}, "A");  // hangs off the loop, is not in it
  auto diags = Check(b, "check-names");
  ASSERT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::LocalFrameLoop, DiagKind::LocalFrameLoop}));
  EXPECT_EQ(diags->all()[0].message,
            "Local frame 'A' is defined 'In' itself through the chain A In B In C In A; give one of these "
            "frames in the robot base or a fixture");
  EXPECT_EQ(diags->all()[0].notes.size(), 2u);
  EXPECT_EQ(diags->all()[1].notes.size(), 0u);
}

// ---------------------------------------------------------------- types

TEST(CheckTypes, ArithmeticPromotesToRealAndIntegersDoNotTruncate) {
  IrBuilder b;
  b.Header("T");
  b.Variables(VarType::Integer, {"i"});
  b.Variables(VarType::Real, {"r"});
  b.Function("Main");
  b.Assign("i", b.Binary(BinaryOp::Add, b.Int(1), b.Int(2)));            // ok
  b.Assign("r", b.Binary(BinaryOp::Mul, b.Int(1), b.Var("i")));          // ok: Integer into Real
  b.Assign("i", b.Binary(BinaryOp::Add, b.Var("i"), b.Real(0.5)));       // Real into Integer
  b.Assign("i", b.Binary(BinaryOp::Div, b.Int(6), b.Int(2)));            // / is always Real
  b.Assign("i", b.Binary(BinaryOp::Mod, b.Int(7), b.Int(2)));            // ok
  b.Assign("r", b.Binary(BinaryOp::Lt, b.Var("i"), b.Int(2)));           // Boolean into a variable
  b.End();
  auto diags = Check(b, "check-types");
  EXPECT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::IntegerTruncation, DiagKind::IntegerTruncation,
                                                  DiagKind::AssignBoolean}));
  EXPECT_EQ(diags->all()[0].message,
            "the assigned value is Real but 'i' is an Integer variable, so the value would truncate; declare "
            "'i' as Real or use an Integer value");
}

TEST(CheckTypes, OperatorsNeedTheirOperandTypes) {
  IrBuilder b;
  b.Header("T");
  b.Variables(VarType::Integer, {"i"});
  b.Variables(VarType::Real, {"r"});
  b.Function("Main");
  b.If(b.Binary(BinaryOp::And, b.Var("i"), b.OnOff(true)));                 // And of an Integer
  b.ElseIf(b.Binary(BinaryOp::Eq, b.Sw(b.Int(1)), b.Int(1)));                // Boolean = number
  b.ElseIf(b.Unary(ir::UnaryOp::Not, b.Binary(BinaryOp::Gt, b.Var("r"), b.Int(0))));  // ok
  b.End();
  b.Assign("i", b.Binary(BinaryOp::Mod, b.Var("r"), b.Int(2)));              // Mod of a Real
  b.Assign("r", b.Binary(BinaryOp::Add, b.OnOff(false), b.Int(2)));          // + of a Boolean
  b.Assign("r", b.Unary(ir::UnaryOp::Negate, b.Sw(b.Int(2))));               // - of a Boolean
  b.End();
  auto diags = Check(b, "check-types");
  EXPECT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::OperandType, DiagKind::ComparisonTypes,
                                                  DiagKind::OperandType, DiagKind::OperandType,
                                                  DiagKind::OperandType}));
  EXPECT_EQ(diags->all()[0].message, "'And' needs Boolean operands, but this one is Integer; compare it, e.g. 'x <> 0'");
  EXPECT_EQ(diags->all()[1].message,
            "'=' compares a Boolean with an Integer; compare numbers with numbers or Booleans with Booleans");
  EXPECT_EQ(diags->all()[2].message, "'Mod' needs Integer operands, but this one is Real");
}

TEST(CheckTypes, ConditionsAreBooleanAndBitsAreIntegers) {
  IrBuilder b;
  b.Header("T");
  b.Variables(VarType::Real, {"r"});
  b.Function("Main");
  b.If(b.Var("r"));
  b.End();
  b.SetOutput(true, b.Real(1.5));
  b.WaitSw(b.Var("r"), true);
  b.Wait(b.Sw(b.Int(3)));
  b.Jump(b.Offset(b.Named("P"), ir::Axis::X, b.OnOff(true)), b.OnOff(false));
  b.Pick(b.Pallet(b.Real(1.0), b.Int(1), b.Var("r")), b.Real(2.0));
  b.End();
  auto diags = Check(b, "check-types");
  EXPECT_EQ(Kinds(*diags),
            (std::vector<DiagKind>{DiagKind::ConditionNotBoolean, DiagKind::ExpectedInteger,
                                   DiagKind::ExpectedInteger, DiagKind::ExpectedNumber, DiagKind::ExpectedNumber,
                                   DiagKind::ExpectedNumber, DiagKind::ExpectedInteger, DiagKind::ExpectedInteger,
                                   DiagKind::ExpectedInteger}));
  EXPECT_EQ(diags->all()[3].message,
            "the Wait time must be a number, but this expression is Boolean; to wait for an input, write 'Wait "
            "Sw(n) = On'");
}

TEST(CheckTypes, ForVariablesAndNext) {
  IrBuilder b;
  b.Header("T");
  b.Function("Main");
  b.Variables(VarType::Integer, {"i"});
  b.Variables(VarType::Real, {"x"});
  b.For("i", b.Int(0), b.Int(10), b.Real(0.5));  // truncating step
  b.Next("I");                                     // case-insensitive match
  b.For("x", b.Int(0), b.Real(1.0), b.Real(0.25));  // fine: Real variable
  b.Next("i");                                       // wrong variable
  b.For("i", b.OnOff(true), b.Int(2));             // Boolean start
  b.Next();
  b.End();
  auto diags = Check(b, "check-types");
  EXPECT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::IntegerTruncation, DiagKind::NextMismatch,
                                                  DiagKind::ExpectedNumber}));
  EXPECT_EQ(diags->all()[1].message, "'Next i' does not match 'For x'; write 'Next x' or just 'Next'");
  EXPECT_EQ(diags->all()[1].range.begin.column, 6u);
}

TEST(CheckTypes, UnresolvedNamesAreNotReportedAgain) {
  IrBuilder b;
  b.Header("T");
  b.Function("Main");
  b.If(b.Binary(BinaryOp::Add, b.Var("nowhere"), b.Int(1)));
  b.End();
  b.Assign("nothing", b.Real(1.5));
  b.End();
  EXPECT_EQ(Kinds(*Check(b, "check-types")), std::vector<DiagKind>{});
}

// ---------------------------------------------------------------- ranges

TEST(CheckRanges, BitsAndOutputsAreWithinLimitsWhenConstant) {
  IrBuilder b;
  b.Header("T");
  b.Vacuum(600);
  b.Function("Main");
  b.Variables(VarType::Integer, {"i"});
  b.SetOutput(true, b.Int(511));                                          // ok
  b.SetOutput(false, b.Binary(BinaryOp::Add, b.Int(500), b.Int(12)));     // 512
  b.SetOutput(true, b.Unary(ir::UnaryOp::Negate, b.Int(1)));              // -1
  b.SetOutput(true, b.Var("i"));                                          // run time
  b.WaitSw(b.Int(1000), true);
  b.If(b.Sw(b.Int(700)));
  b.End();
  b.Pick(b.Named("P"), b.Int(-3));
  b.End();
  auto diags = Check(b, "check-ranges");
  EXPECT_EQ(Kinds(*diags),
            (std::vector<DiagKind>{DiagKind::VacuumOutputOutOfRange, DiagKind::IoBitOutOfRange,
                                   DiagKind::IoBitOutOfRange, DiagKind::IoBitOutOfRange, DiagKind::IoBitOutOfRange,
                                   DiagKind::VacuumOutputOutOfRange}));
  EXPECT_EQ(diags->all()[1].message, "I/O bit 512 is out of range; bits are numbered 0 to 511");
}

TEST(CheckRanges, PalletsNumbersSizesAndIndices) {
  IrBuilder b;
  b.Header("T");
  b.Vacuum(1);
  b.Point("A", {0, 0, 0, 0});
  b.PalletDecl(1, {"A", "A", "A"}, 8, 2);
  b.PalletDecl(16, {"A", "A", "A"}, 0, 2);
  b.Function("Main");
  b.Pick(b.Pallet(b.Int(1), b.Int(8), b.Int(2)));   // ok: last column, last row
  b.Pick(b.Pallet(b.Int(1), b.Int(9), b.Int(0)));   // column 9, row 0
  b.Pick(b.Pallet(b.Int(1), b.Int(17)));            // position 17 of 16
  b.Pick(b.Pallet(b.Int(1), b.Int(16)));            // ok
  b.Pick(b.Pallet(b.Int(20), b.Int(1)));            // number out of range
  b.End();
  auto diags = Check(b, "check-ranges");
  EXPECT_EQ(Kinds(*diags),
            (std::vector<DiagKind>{DiagKind::PalletNumberOutOfRange, DiagKind::PalletSizeInvalid,
                                   DiagKind::PalletIndexOutOfRange, DiagKind::PalletIndexOutOfRange,
                                   DiagKind::PalletIndexOutOfRange, DiagKind::PalletNumberOutOfRange}));
  EXPECT_EQ(diags->all()[2].message,
            "column 9 is outside pallet 1, which has 8 columns and 2 rows; columns run from 1 to 8");
  EXPECT_EQ(diags->all()[4].message,
            "position 17 is outside pallet 1, which has 8 columns and 2 rows; positions run from 1 to 16");
}

TEST(CheckRanges, StepsWaitsAnglesLimZAndVacuum) {
  IrBuilder b;
  b.Header("T");
  b.Point("A", {0, 0, 0, -400});
  b.Local("L", {0, 0, 0, 360});  // exactly one turn is fine
  b.Function("Main");
  b.Variables(VarType::Integer, {"i"});
  b.For("i", b.Int(1), b.Int(3), b.Binary(BinaryOp::Sub, b.Int(1), b.Int(1)));
  b.Next();
  b.Wait(b.Unary(ir::UnaryOp::Negate, b.Real(0.5)));
  b.Wait(b.Int(0));
  b.Motion(ir::MotionKind::Go, b.Named("A"), b.Int(-5));
  b.Jump(b.Literal({0, 0, 0, 720}), b.Int(-5));
  b.Pick(b.Named("A"));
  b.Place(b.Named("A"), b.Int(2));
  b.End();
  auto diags = Check(b, "check-ranges");
  EXPECT_EQ(Kinds(*diags),
            (std::vector<DiagKind>{DiagKind::AngleOutOfRange, DiagKind::ForStepZero, DiagKind::NegativeWait,
                                   DiagKind::LimZNotAllowed, DiagKind::AngleOutOfRange,
                                   DiagKind::MissingVacuumOutput}));
  EXPECT_EQ(diags->all()[0].message, "u = -400 degrees is outside -360 to 360; give the angle within one turn");
  EXPECT_EQ(diags->all()[2].message,
            "'Wait -0.5' waits a negative time; the time is in seconds and must be 0 or more");
  EXPECT_EQ(diags->all()[3].message,
            "LimZ applies only to Jump, Pick and Place; Go moves without lifting, so remove LimZ or use Jump");
}

// ---------------------------------------------------------------- fixture scope

TEST(CheckFixtureScope, FixturePointsOnlyInsideTheirCycle) {
  IrBuilder b;
  Prelude(b);
  b.Local("Layer", {0, 0, 0, 0}, "Board");
  b.Point("Deep", {0, 0, 0, 0}, "Layer");
  b.Taught("U3", {0, 0, 0, 0}, "Board");
  b.Function("Main");
  b.Pick(b.Named("Feed0805"));  // robot base: anywhere
  b.Place(b.Named("C1"));       // outside any Cycle
  b.Cycle("Board");
  b.Place(b.Named("C1"));
  b.Place(b.Named("Deep"));
  b.Place(b.Named("U3"));
  b.Place(b.Named("T1"));       // Tray's point in Board's cycle
  b.End();
  b.Cycle("Tray");
  b.Place(b.Named("Deep"));     // through the Local chain
  b.End();
  b.End();
  auto diags = Check(b, "check-fixture-scope");
  ASSERT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::FixturePointOutsideCycle,
                                                  DiagKind::FixturePointOutsideCycle,
                                                  DiagKind::FixturePointOutsideCycle}));
  EXPECT_EQ(diags->all()[0].message,
            "point 'C1' belongs to fixture 'Board' and may be used only inside 'Cycle Board', but this use is "
            "outside any Cycle");
  EXPECT_EQ(diags->all()[1].message,
            "point 'T1' belongs to fixture 'Tray' and may be used only inside 'Cycle Tray', but this use is "
            "inside 'Cycle Board'");
  EXPECT_EQ(diags->all()[1].notes.size(), 1u);
  EXPECT_EQ(diags->all()[2].message.substr(0, 40), "point 'Deep' belongs to fixture 'Board' ");
}

TEST(CheckFixtureScope, AFunctionCalledOnlyInsideItsCycleMayUseItsPoints) {
  IrBuilder b;
  Prelude(b);
  b.Function("Main");
  b.Cycle("Board");
  b.Call("PlaceAll");
  b.End();
  b.End();
  b.Function("PlaceAll");
  b.Call("PlaceOne");  // inherits Cycle Board
  b.End();
  b.Function("PlaceOne");
  b.Place(b.Named("C1"));
  b.End();
  EXPECT_EQ(Kinds(*Check(b, "check-fixture-scope")), std::vector<DiagKind>{});
}

TEST(CheckFixtureScope, ACallFromElsewhereIsReportedAtTheUseWithTheCallChain) {
  IrBuilder b;
  Prelude(b);
  b.Function("Main");
  b.Cycle("Board");
  b.Call("PlaceAll");
  b.End();
  ir::Stmt& bad_call = b.Call("Helper");  // outside any Cycle
  b.End();
  b.Function("Helper");
  ir::Stmt& inner_call = b.Call("PlaceAll");
  b.End();
  b.Function("PlaceAll");
  ir::Stmt& use = b.Place(b.Named("C1"));
  b.End();
  auto diags = Check(b, "check-fixture-scope");
  ASSERT_EQ(Kinds(*diags), std::vector<DiagKind>{DiagKind::FixturePointOutsideCycle});
  const Diagnostic& diag = diags->all()[0];
  EXPECT_EQ(diag.range.begin.line, use.loc.line);
  EXPECT_EQ(diag.message,
            "point 'C1' belongs to fixture 'Board' and may be used only inside 'Cycle Board', but 'PlaceAll' is "
            "called outside any Cycle");
  ASSERT_EQ(diag.notes.size(), 2u);
  EXPECT_EQ(diag.notes[0].first.begin.line, inner_call.loc.line);
  EXPECT_EQ(diag.notes[0].second, "'PlaceAll' is called here, outside any Cycle");
  EXPECT_EQ(diag.notes[1].first.begin.line, bad_call.loc.line);
  EXPECT_EQ(diag.notes[1].first.begin.column, 6u);
  EXPECT_EQ(diag.notes[1].second, "'Helper' is called here, outside any Cycle");
}

TEST(CheckFixtureScope, ACallInsideAnotherFixturesCycleIsReported) {
  IrBuilder b;
  Prelude(b);
  b.Function("Main");
  b.Cycle("Tray");
  b.If(b.Sw(b.Int(1)));
  ir::Stmt& call = b.Call("PlaceAll");
  b.End();
  b.End();
  b.End();
  b.Function("PlaceAll");
  b.For("k", b.Int(1), b.Int(2));
  b.Place(b.Named("C1"));
  b.Next();
  b.End();
  auto diags = Check(b, "check-fixture-scope");
  ASSERT_EQ(Kinds(*diags), std::vector<DiagKind>{DiagKind::FixturePointOutsideCycle});
  EXPECT_NE(diags->all()[0].message.find("but 'PlaceAll' is called inside 'Cycle Tray'"), std::string::npos);
  ASSERT_EQ(diags->all()[0].notes.size(), 1u);
  EXPECT_EQ(diags->all()[0].notes[0].first.begin.line, call.loc.line);
  EXPECT_EQ(diags->all()[0].notes[0].second, "'PlaceAll' is called here, inside 'Cycle Tray'");
}

TEST(CheckFixtureScope, CyclesDoNotNestNotEvenThroughCalls) {
  IrBuilder b;
  Prelude(b);
  b.Function("Main");
  b.Cycle("Board");
  b.Cycle("Board");  // directly nested
  b.End();
  b.Call("Inner");
  b.End();
  b.End();
  b.Function("Inner");
  b.Cycle("Tray");   // nested through the call
  b.End();
  b.End();
  auto diags = Check(b, "check-fixture-scope");
  ASSERT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::NestedCycle, DiagKind::NestedCycle}));
  EXPECT_EQ(diags->all()[0].message,
            "'Cycle Board' would run inside 'Cycle Board'; cycles cannot nest, so end the outer Cycle first");
  EXPECT_EQ(diags->all()[1].message,
            "'Cycle Tray' would run inside 'Cycle Board' because 'Inner' is called inside it; cycles cannot "
            "nest, so end the outer Cycle first");
  EXPECT_EQ(diags->all()[1].notes.size(), 1u);
}

TEST(CheckFixtureScope, ScansOfAnotherFixtureInsideACycle) {
  IrBuilder b;
  Prelude(b);
  b.Function("Main");
  b.Scan("Tray");    // outside any cycle: fine
  b.Cycle("Board");
  b.Scan("Board");   // its own fixture: fine
  b.Scan("Tray");
  b.Call("Rescan");
  b.End();
  b.End();
  b.Function("Rescan");
  b.Scan("Tray");
  b.End();
  auto diags = Check(b, "check-fixture-scope");
  ASSERT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::ScanInOtherCycle, DiagKind::ScanInOtherCycle}));
  EXPECT_NE(diags->all()[1].message.find("because 'Rescan' is called inside it"), std::string::npos);
}

TEST(CheckFixtureScope, PalletsOfAFixtureAndTheirCorners) {
  IrBuilder b;
  Prelude(b);
  b.Point("C2", {10, 0, 0, 0}, "Board");
  b.Point("C3", {0, 10, 0, 0}, "Board");
  b.PalletDecl(1, {"C1", "C2", "C3"}, 2, 2);
  b.PalletDecl(2, {"C1", "Feed0805", "C3"}, 2, 2);
  b.Function("Main");
  b.Place(b.Pallet(b.Int(1), b.Int(1), b.Int(1)));
  b.Place(b.Pallet(b.Var("n"), b.Int(1), b.Int(1)));  // chosen at run time: not judged
  b.End();
  auto diags = Check(b, "check-fixture-scope");
  ASSERT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::PalletCornersInDifferentFrames,
                                                  DiagKind::FixturePointOutsideCycle}));
  EXPECT_EQ(diags->all()[0].message,
            "the corners of pallet 2 are in different frames: 'C1' is in 'Board', but 'Feed0805' is in the robot "
            "base; give all three corners in one frame");
  EXPECT_EQ(diags->all()[1].message.substr(0, 39), "pallet 1 belongs to fixture 'Board' and");
}

TEST(CheckFixtureScope, FunctionsMainNeverReachesAreJudgedOnlyByTheirOwnCycles) {
  IrBuilder b;
  Prelude(b);
  b.Function("Main");
  b.End();
  b.Function("Unused");
  b.Place(b.Named("C1"));  // context unknown: not judged
  b.Cycle("Tray");
  b.Place(b.Named("C1"));  // but this is wrong wherever it runs
  b.End();
  b.End();
  EXPECT_EQ(Kinds(*Check(b, "check-fixture-scope")), std::vector<DiagKind>{DiagKind::FixturePointOutsideCycle});
}

TEST(CheckFixtureScope, RecursionTerminates) {
  IrBuilder b;
  Prelude(b);
  b.Function("Main");
  b.Cycle("Board");
  b.Call("A");
  b.End();
  b.Call("A");
  b.End();
  b.Function("A");
  b.Call("B");
  b.End();
  b.Function("B");
  b.Call("A");
  b.Place(b.Named("C1"));
  b.End();
  EXPECT_EQ(Kinds(*Check(b, "check-fixture-scope")), std::vector<DiagKind>{DiagKind::FixturePointOutsideCycle});
}

// ---------------------------------------------------------------- reachability

TEST(CheckReachability, StatementsAfterExitFunction) {
  IrBuilder b;
  b.Header("T");
  b.Function("Main");
  b.If(b.Sw(b.Int(1)));
  ir::Stmt& exit = b.Exit();
  b.Comment("comments are not code");
  ir::Stmt& dead = b.SetOutput(true, b.Int(1));
  b.SetOutput(true, b.Int(2));
  b.End();
  b.SetOutput(true, b.Int(3));  // reachable: the If may not be taken
  b.End();
  auto diags = Check(b, "check-reachability");
  ASSERT_EQ(Kinds(*diags), std::vector<DiagKind>{DiagKind::UnreachableCode});
  EXPECT_EQ(diags->all()[0].range.begin.line, dead.loc.line);
  EXPECT_EQ(diags->all()[0].severity, Severity::Warning);
  ASSERT_EQ(diags->all()[0].notes.size(), 1u);
  EXPECT_EQ(diags->all()[0].notes[0].first.begin.line, exit.loc.line);
}

TEST(CheckReachability, AnUnreachableFend) {
  IrBuilder b;
  b.Header("T");
  b.Function("Main");
  b.If(b.Sw(b.Int(1)));
  b.Exit();
  b.Else();
  b.Cycle("Board");
  b.Exit();
  b.End();
  b.End();
  b.End();
  auto diags = Check(b, "check-reachability");
  ASSERT_EQ(Kinds(*diags), std::vector<DiagKind>{DiagKind::UnreachableCode});
  EXPECT_EQ(diags->all()[0].message,
            "Fend is never reached: the function always exits before it; an 'Exit Function' just before Fend is "
            "not needed");
  EXPECT_EQ(diags->all()[0].notes[0].second, "every branch of this If leaves the function");
}

TEST(CheckReachability, LoopsAndIfsWithoutElseMayNotLeave) {
  IrBuilder b;
  b.Header("T");
  b.Function("Main");
  b.For("i", b.Int(1), b.Int(2));
  b.Exit();
  b.Next();
  b.If(b.Sw(b.Int(1)));
  b.Exit();
  b.ElseIf(b.Sw(b.Int(2)));
  b.Exit();
  b.End();
  b.SetOutput(true, b.Int(1));
  b.End();
  EXPECT_EQ(Kinds(*Check(b, "check-reachability")), std::vector<DiagKind>{});
}

TEST(CheckReachability, FunctionsNeverCalledAndRecursion) {
  IrBuilder b;
  b.Header("T");
  b.Function("Main");
  b.Call("A");
  b.Call("Self");
  b.End();
  b.Function("A");
  ir::Stmt& a_calls_b = b.Call("B");
  b.End();
  b.Function("B");
  ir::Stmt& b_calls_a = b.Call("a");
  b.End();
  b.Function("Self");
  b.Call("Self");
  b.End();
  b.Function("Lonely");
  b.Call("Lonely");
  b.End();
  auto diags = Check(b, "check-reachability");
  ASSERT_EQ(Kinds(*diags), (std::vector<DiagKind>{DiagKind::UnusedFunction, DiagKind::RecursiveCall,
                                                  DiagKind::RecursiveCall, DiagKind::RecursiveCall}));
  EXPECT_EQ(diags->all()[0].message, "function 'Lonely' is never called; call it or remove it");
  const Diagnostic& cycle = diags->all()[1];
  EXPECT_EQ(cycle.message,
            "recursive call 'A' -> 'B' -> 'A'; the controller's call stack is small and the compiler needs a "
            "static call graph, so rewrite it as a loop");
  EXPECT_EQ(cycle.range.begin.line, a_calls_b.loc.line);
  ASSERT_EQ(cycle.notes.size(), 1u);
  EXPECT_EQ(cycle.notes[0].first.begin.line, b_calls_a.loc.line);
  EXPECT_EQ(diags->all()[2].message.substr(0, 32), "recursive call 'Self' -> 'Self';");
}

// ---------------------------------------------------------------- all together

TEST(SemanticChecks, AProgramUsingEveryConstructIsClean) {
  IrBuilder b;
  b.Comment("every construct, correctly");
  b.Header("Everything");
  b.Fixture("Board");
  b.Vacuum(8);
  b.Local("Layer1", {12, 20, 0, 0}, "Board");
  b.Point("Feed0805", {212.4, 35.5, -12, 0});
  b.Point("C1", {12.7, 8.25, -3, 90}, "Layer1");
  b.Taught("U3", {171.2, 97.3, -3, 0}, "Board");
  b.Point("A", {0, 0, 0, 0}, "Board");
  b.Point("B", {10, 0, 0, 0}, "Board");
  b.Point("C", {0, 10, 0, 0}, "Board");
  b.PalletDecl(1, {"A", "B", "C"}, 4, 3);
  b.Variables(VarType::Integer, {"placed", "layer"});
  b.Variables(VarType::Real, {"dx"});
  b.Function("Main");
  b.Scan("Board");
  b.Cycle("Board");
  b.For("layer", b.Int(0), b.Int(2), b.Int(1));
  b.Variables(VarType::Integer, {"k"});
  b.Assign("dx", b.Binary(BinaryOp::Mul, b.Var("layer"), b.Real(55.0)));
  b.Pick(b.Named("Feed0805"), nullptr, b.Int(-5));
  b.Place(b.Offset(b.Offset(b.Named("C1"), ir::Axis::X, b.Var("dx")), ir::Axis::Y, b.Real(0.5), true));
  b.For("k", b.Int(1), b.Int(12));
  b.Place(b.Pallet(b.Int(1), b.Var("k")), b.Int(9));
  b.Next("k");
  b.Next("layer");
  b.Call("Finish");
  b.End();
  b.Jump(b.Literal({0, 0, 0, 0}));
  b.Motion(ir::MotionKind::Move, b.Named("Feed0805"));
  b.End();
  b.Function("Finish");
  b.Pick(b.Named("Feed0805"));
  b.Place(b.Named("U3"));
  b.Assign("placed", b.Binary(BinaryOp::Add, b.Var("placed"), b.Int(1)));
  b.If(b.Binary(BinaryOp::Or, b.Binary(BinaryOp::Ge, b.Var("placed"), b.Int(100)),
                b.Binary(BinaryOp::Eq, b.Sw(b.Int(13)), b.OnOff(true))));
  b.SetOutput(true, b.Int(14));
  b.WaitSw(b.Int(15), false);
  b.Exit();
  b.ElseIf(b.Unary(ir::UnaryOp::Not, b.OnOff(false)));
  b.Wait(b.Real(0.05));
  b.Else();
  b.SetOutput(false, b.Int(14));
  b.End();
  b.End();
  auto diags = Check(b);
  EXPECT_EQ(diags->RenderText(), "");
}

}  // namespace
}  // namespace smtcal
