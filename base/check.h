// Our own broken invariants: never used for user input (that is Diagnostics)
// or for I/O (that is Result). A failed check is a bug in smtcal: it says
// where, and ends the process with exit 3 (docs/files-and-exit-codes.md),
// never with an abort, so a user sees a message and the documented code.
//
// For a core file to debug, set SMTCAL_ABORT_ON_INTERNAL_ERROR=1 in the
// environment: a failed check then aborts after its message. The fuzz
// harnesses set it (tests/fuzz/), so a broken invariant is a crash there.
#pragma once

#include <string>

namespace smtcal {

// Reports the internal error `message` (one or more lines, without a final
// newline) and ends the process: exit 3, or abort() when the environment
// asks for it. What "reports" means is the driver's choice
// (SetInternalErrorReporter); by default a line on stderr.
[[noreturn]] void InternalError(const std::string& message);
[[noreturn]] void CheckFailed(const char* file, int line, const char* what, const char* condition);

// The driver's way of saying an internal error: it gets the message and must
// return (the process ends after it). nullptr restores the default.
using InternalErrorReporter = void (*)(const std::string& message);
void SetInternalErrorReporter(InternalErrorReporter reporter);

// The environment variable that turns the exit into an abort.
inline constexpr const char* kAbortOnInternalErrorVariable = "SMTCAL_ABORT_ON_INTERNAL_ERROR";
// The exit code of an internal error (tools' kExitIoError: I/O, resources
// and internal errors).
inline constexpr int kInternalErrorExitCode = 3;

}  // namespace smtcal

#define SMTCAL_CHECK(cond, msg)                                   \
  do {                                                            \
    if (!(cond)) ::smtcal::CheckFailed(__FILE__, __LINE__, msg, #cond); \
  } while (0)
