// Internal errors (base/check.h).
#include "base/check.h"

#include <cstdio>
#include <cstdlib>

#include <fmt/format.h>

namespace smtcal {
namespace {

InternalErrorReporter g_reporter = nullptr;

// Plain stdio: the state of everything else is in doubt.
void PrintToStderr(const std::string& message) {
  std::fputs(("smtcal: error: " + message + "\n").c_str(), stderr);
}

}  // namespace

void SetInternalErrorReporter(InternalErrorReporter reporter) { g_reporter = reporter; }

void InternalError(const std::string& message) {
  // A reporter that fails again (a check inside it) must not recurse.
  static bool reporting = false;
  InternalErrorReporter reporter = reporting || g_reporter == nullptr ? PrintToStderr : g_reporter;
  reporting = true;
  reporter(message);
  std::fflush(stderr);
  const char* abort = std::getenv(kAbortOnInternalErrorVariable);
  if (abort != nullptr && *abort != '\0' && std::string(abort) != "0") std::abort();
  // _Exit: no static destructors or atexit handlers run on state a broken
  // invariant may have left half-made, and buffered standard output is
  // dropped, so nothing half-written reaches it; temporaries of outputs
  // are removed by the next run (base/source.h).
  std::_Exit(kInternalErrorExitCode);
}

void CheckFailed(const char* file, int line, const char* what, const char* condition) {
  InternalError(fmt::format("internal error at {}:{}: {} ({}); this is a bug in smtcal, not in the input: please "
                            "report it with the input",
                            file, line, what, condition));
}

}  // namespace smtcal
