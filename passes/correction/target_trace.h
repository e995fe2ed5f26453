// Finding every motion target by running the program at compile time.
//
// The program is executed from Function Main with what is known before it
// runs: literals, assignments, For loops with constant bounds, Calls. What
// only the cell knows at run time (Sw() inputs) is "unknown": an If whose
// condition is unknown runs every branch, each on its own copy of the
// variables, and a variable the branches leave different is unknown after
// it; a For with unknown bounds runs its body once with the loop variable
// unknown. A target that depends on an unknown value is recorded as not
// known (its correction happens at run time and it cannot be verified).
//
// Each (statement, position) is recorded once, in the order first reached.
// For the cycle-time estimate the first execution of each Cycle is also
// recorded as a sequence of events, following the path on which every
// unknown condition is false (for `If Sw(13) = On` that is the Else: the
// input's usual state).
//
// The run stops after kMaxTraceSteps statements (a loop over a million boards
// needs no million-fold check; a 100 000-placement program takes about
// 300 000); the caller reports that. It also stops, reported here, where
// blocks and calls nest more than kMaxTraceDepth deep (each is a level of
// the C++ stack; real programs nest a few levels), and reports a pallet
// number computed at compile time that names no declared pallet (the checks
// see only constant numbers).
#pragma once

#include "base/diagnostics.h"
#include "ir/ir.h"
#include "ir/symbols.h"
#include "passes/correction/compile_state.h"

namespace smtcal {

inline constexpr long kMaxTraceSteps = 5'000'000;
inline constexpr int kMaxTraceDepth = 1000;

// Fills state.targets, state.cycle_traces and state.trace_complete. Expects a
// program that passed the checks and state.fixtures bound. Taught points get
// their taught (robot) coordinates as `in_frame` until fixture-correction
// converts them.
void TraceTargets(const ir::Program& program, const sema::SymbolTable& symbols, CompileState& state,
                  Diagnostics& diags);

// The position of a point declared in `frame` (empty = base) at `local`, in
// the frame's root: the fixture it hangs on (fixture_name set) or the base.
struct RootedPose {
  std::string fixture;  // empty = robot base
  Pose4 pose{};
};
RootedPose ResolveFrame(const sema::SymbolTable& symbols, const std::string& frame, const Pose4& local);

}  // namespace smtcal
