// What a program commands on the machine, position by position, for
// `smtcal diff` (docs/diff.md, "On the machine"): every target the
// compile-time run finds (passes/correction/target_trace.h), with how the
// controller commands it — as written, corrected through the tables at run
// time, or corrected through FIX and the tables every cycle.
// calibration/machine_model.h turns each into the command and where the part
// lands.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "base/diagnostics.h"
#include "calibration/cell.h"
#include "ir/ir.h"
#include "passes/correction/compile_state.h"

namespace smtcal {

struct MachineTarget {
  enum class Kind : std::uint8_t {
    kAsWritten,  // the program's own numbers are the command (static and uncorrected targets)
    kRunTime,    // a base position the controller corrects through its tables
    kFixture,    // a point in a fixture's frame: FIX, then the tables, every cycle
  };
  Kind kind = Kind::kAsWritten;
  bool known = true;  // false: the position is known only at run time
  int fixture = -1;   // kFixture: the fixture's index in the cell
  // kAsWritten: the command; kRunTime: the required base position; kFixture:
  // the point in the fixture's frame. x, y, z mm, u degrees.
  Pose4 position{};
  std::uint32_t unknown_because = 0;  // when not known: MachineTargets::UnknownBecause's index
};

// A program's machine targets, grouped by statement.
class MachineTargets {
 public:
  // The positions `stmt` commands, in the order the compile-time run first
  // reached them; empty for a statement it never reached.
  std::span<const MachineTarget> Of(const ir::Stmt* stmt) const;
  std::size_t size() const { return targets_.size(); }
  // False when the compile-time run stopped at its step limit (some
  // positions were never found).
  bool complete() const { return complete_; }
  // What a position known only at run time depends on.
  const std::string& UnknownBecause(const MachineTarget& target) const { return reasons_[target.unknown_because]; }

  // From a compile state whose targets have their kinds (`compiled`: the
  // program is already what the controller runs, so a static target's
  // command is its traced position, not a nominal computed here).
  static MachineTargets FromState(const CompileState& state, bool compiled);

 private:
  std::vector<MachineTarget> targets_;  // grouped by statement, each group in trace order
  // (statement, its first target), sorted by statement; a group ends where the next begins.
  std::vector<std::pair<const ir::Stmt*, std::uint32_t>> index_;
  std::vector<std::string> reasons_;
  bool complete_ = true;
};

// A program that is already what the controller runs (`smtcal compile
// --target place` output, or a LinuxCNC output read back): its fixtures are
// bound to the cell's of the same name (every one must be there) and it is
// traced as it stands: a base-frame statement with one known position is a
// command as written, any other base-frame one is corrected at run time
// (the compiler decided alike: BaseStatementsCommandedAsWritten). Diagnostics
// of the trace go to `diags`.
MachineTargets CompiledProgramTargets(const ir::Program& program, const cell::Cell& cell, Diagnostics& diags);

// A source program: the correction passes that decide what the controller
// commands (bind, regions, static-inversion, fixture-correction) run on it
// for `cell`, as `smtcal compile` would, and change it as they do (static
// targets become their commands, taught points their fixture points). Their
// diagnostics go to `diags`; with errors the result must not be used.
MachineTargets SourceProgramTargets(ir::Program& program, const cell::Cell& cell, Diagnostics& diags);

}  // namespace smtcal
