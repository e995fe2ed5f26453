// The pass registry and runner: names, descriptions, selection by name, and
// the verify-after-each switch that names the pass that broke the IR.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "passes/pass_manager.h"
#include "tests/unit/ir/ir_builder.h"
#include "tests/unit/test_support.h"

namespace smtcal {
namespace {

using test::IrBuilder;

TEST(PassRegistry, EveryEntryHasAUniqueNameADescriptionAndAFactory) {
  std::set<std::string> names;
  for (const PassInfo& info : PassRegistry()) {
    EXPECT_TRUE(names.insert(info.name).second) << info.name;
    EXPECT_FALSE(info.description.empty()) << info.name;
    std::unique_ptr<Pass> pass = info.create();
    ASSERT_NE(pass, nullptr);
    EXPECT_EQ(pass->Name(), info.name);
  }
  EXPECT_GE(names.size(), 6u);
}

TEST(PassRegistry, DescribePassesListsEveryPass) {
  std::string text = DescribePasses();
  for (const PassInfo& info : PassRegistry()) {
    EXPECT_NE(text.find(info.name), std::string::npos);
    EXPECT_NE(text.find(info.description), std::string::npos);
  }
}

TEST(FindPasses, KeepsTheGivenOrderAndNamesTheValidOnesOnAMistake) {
  Result<std::vector<const PassInfo*>> found = FindPasses({"check-types", "check-header"});
  ASSERT_TRUE(found.ok());
  ASSERT_EQ(found.value().size(), 2u);
  EXPECT_EQ(found.value()[0]->name, "check-types");
  EXPECT_EQ(found.value()[1]->name, "check-header");

  Result<std::vector<const PassInfo*>> unknown = FindPasses({"check-header", "check-spelling"});
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().message.rfind("unknown pass 'check-spelling'; valid passes: check-header, ", 0), 0u)
      << unknown.error().message;
}

TEST(RunPasses, RunsOnlyTheNamedPasses) {
  IrBuilder b;  // an empty program: no header, no Main
  ir::Program& program = b.Finish();
  Diagnostics only_names(b.sources);
  ASSERT_TRUE(RunPasses(program, only_names, {std::string("check-names")}, false).ok());
  EXPECT_TRUE(only_names.all().empty());

  Diagnostics all(b.sources);
  ASSERT_TRUE(RunPasses(program, all, std::vector<std::string>{}, true).ok());
  EXPECT_EQ(all.error_count(), 3u);  // Program, Units, Main missing

  Diagnostics bad(b.sources);
  EXPECT_FALSE(RunPasses(program, bad, {std::string("no-such-pass")}, false).ok());
}

// A pass with a bug: it leaves a Wait without its time.
class BreakIr final : public Pass {
 public:
  std::string_view Name() const override { return "break-ir"; }
  void Run(ir::Program& program, Diagnostics&) override {
    auto& main = std::get<ir::Function>(program.items.back()->node);
    std::get<ir::WaitTime>(main.body[0]->node).seconds.reset();
  }
};

void WaitProgram(IrBuilder& b) {
  b.Header("T");
  b.Function("Main");
  b.Wait(b.Int(1));
  b.End();
  b.Finish();
}

TEST(RunPassesDeathTest, VerifyEachNamesThePassThatBrokeTheIr) {
  IrBuilder b;
  WaitProgram(b);
  PassInfo breaker{"break-ir", "breaks the IR on purpose", [] { return std::make_unique<BreakIr>(); }};
  std::vector<const PassInfo*> passes = {&PassRegistry()[0], &breaker, &PassRegistry()[1]};
  Diagnostics diags(b.sources);
  // An internal error: exit 3 with the message, never an abort (base/check.h).
  EXPECT_EXIT(RunPasses(b.program, diags, passes, /*verify_each=*/true), testing::ExitedWithCode(3),
              "internal error: the IR is broken after pass 'break-ir' \\(1 problem\\)(.|\n)*"
              "test.place:4:1: WaitTime: the wait time is null");
}

TEST(RunPassesDeathTest, VerifyEachChecksTheInputFirst) {
  IrBuilder b;
  WaitProgram(b);
  BreakIr().Run(b.program, *std::make_unique<Diagnostics>(b.sources));
  Diagnostics diags(b.sources);
  EXPECT_EXIT((void)RunPasses(b.program, diags, std::vector<std::string>{}, /*verify_each=*/true),
              testing::ExitedWithCode(3), "the IR is broken in the input to the first pass");
}

TEST(RunPasses, WithoutVerifyEachABrokenIrIsNotLookedAt) {
  IrBuilder b;
  WaitProgram(b);
  PassInfo breaker{"break-ir", "breaks the IR on purpose", [] { return std::make_unique<BreakIr>(); }};
  Diagnostics diags(b.sources);
  RunPasses(b.program, diags, std::vector<const PassInfo*>{&breaker}, /*verify_each=*/false);
  EXPECT_TRUE(diags.all().empty());
}

// ---------------------------------------------------------------- smtcal check

using CheckRun = test::SmtcalRun;

// `smtcal check ARGS p.place` on `program_text`, in a scratch folder.
CheckRun RunCheck(const std::string& args, const std::string& program_text) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / fmt::format("smtcal_pass_test_{}", ::getpid());
  fs::create_directories(dir);
  std::ofstream(dir / "p.place") << program_text;
  CheckRun run = test::RunSmtcal(fmt::format("check {} p.place", args), dir);
  fs::remove_all(dir);
  return run;
}

constexpr const char* kCleanProgram = "Program P\nUnits mm\nFunction Main\n  On 1\nFend\n";

TEST(CheckCommand, HelpListsEveryPassWithItsDescription) {
  CheckRun help = RunCheck("--help", kCleanProgram);
  EXPECT_EQ(help.exit_code, 0);
  for (const PassInfo& info : PassRegistry()) {
    EXPECT_NE(help.out.find(info.name), std::string::npos) << info.name;
    EXPECT_NE(help.out.find(info.description), std::string::npos) << info.name;
  }
}

TEST(CheckCommand, AnUnknownPassIsAUsageErrorListingTheValidOnes) {
  CheckRun run = RunCheck("--passes=check-names,check-spelling", kCleanProgram);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("unknown pass 'check-spelling'; valid passes: check-header, check-names"),
            std::string::npos)
      << run.err;
}

TEST(CheckCommand, ExitCodesAndVerifyEach) {
  CheckRun clean = RunCheck("--verify-each", kCleanProgram);
  EXPECT_EQ(clean.exit_code, 0) << clean.err;
  EXPECT_EQ(clean.err, "smtcal: p.place: no errors, no warnings\n");  // the success line
  EXPECT_EQ(clean.out, "");
  CheckRun quiet = RunCheck("-q --verify-each", kCleanProgram);
  EXPECT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");  // -q: no success line

  CheckRun warning = RunCheck("", "Program P\nUnits mm\nFunction Main\nFend\nFunction Spare\nFend\n");
  EXPECT_EQ(warning.exit_code, 0);
  EXPECT_NE(warning.err.find("warning: function 'Spare' is never called"), std::string::npos) << warning.err;

  CheckRun error = RunCheck("--passes=check-names", "Program P\nUnits mm\nFunction Main\n  Jump P1\nFend\n");
  EXPECT_EQ(error.exit_code, 1);
  EXPECT_NE(error.err.find("p.place:4:8: error: undefined point 'P1'"), std::string::npos) << error.err;
}

TEST(CheckCommand, SemanticChecksWaitForACleanParse) {
  // A syntax error, and an undefined point that check-names would report.
  CheckRun run = RunCheck("", "Program P\nUnits mm\nFunction Main\n  Jump P1 +\nFend\n");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err.find("undefined point"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace smtcal
