// Our own broken invariants (base/check.h): a message and exit 3, as
// docs/files-and-exit-codes.md promises, never an abort; an abort only when
// the environment asks for one (a core file for a developer, the fuzz
// harnesses' findings).
#include <csignal>
#include <cstdlib>

#include <gtest/gtest.h>

#include "base/check.h"

namespace smtcal {
namespace {

TEST(CheckDeathTest, AFailedCheckIsExitThreeWithAMessage) {
  EXPECT_EXIT(
      {
        ::unsetenv(kAbortOnInternalErrorVariable);
        SMTCAL_CHECK(sizeof(int) == 0, "the check that fails");
      },
      testing::ExitedWithCode(3),
              "smtcal: error: internal error at .*check_test.cpp:[0-9]+: the check that fails \\(sizeof\\(int\\) == "
              "0\\); this is a bug in smtcal");
}

TEST(CheckDeathTest, TheEnvironmentSwitchAbortsForACoreFile) {
  EXPECT_EXIT(
      {
        ::setenv(kAbortOnInternalErrorVariable, "1", 1);
        SMTCAL_CHECK(sizeof(int) == 0, "the check that fails");
      },
      testing::KilledBySignal(SIGABRT), "internal error at");
  EXPECT_EXIT(
      {
        ::setenv(kAbortOnInternalErrorVariable, "0", 1);
        InternalError("a broken invariant");
      },
      testing::ExitedWithCode(3), "smtcal: error: a broken invariant");
}

void ReportToStdout(const std::string& message) { std::printf("reported: %s\n", message.c_str()); }

TEST(CheckDeathTest, TheDriverSaysItsOwnWay) {
  EXPECT_EXIT(
      {
        ::unsetenv(kAbortOnInternalErrorVariable);
        SetInternalErrorReporter(ReportToStdout);
        std::fprintf(stderr, "before\n");
        InternalError("x");
      },
      testing::ExitedWithCode(3), "^before\n$");
}

}  // namespace
}  // namespace smtcal
