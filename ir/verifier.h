// The IR verifier: checks the IR's own invariants, the promises every pass
// may rely on and must keep. It guards the passes (and the parser), not the
// user's input: a violation is a bug in smtcal, reported as an internal
// error that names the node and where it came from.
//
// Invariants:
// - top level holds only comments, declarations and Functions; blocks hold
//   only statements (a Function never nests, declarations never sit in one);
// - every statement, expression, point expression, offset, Coords, If branch
//   and block end has a known SourceLoc, and every caret length is >= 1;
// - pointers a node requires are non-null (operands, Assign values, bits,
//   Wait times, For bounds, If/ElseIf conditions, offset amounts, pallet
//   number and first index; only Else may lack a condition, and only last);
// - names are non-empty (declared, referenced, called, cycled, scanned);
// - numbers are finite: Coords and literals; an Integer literal is integral;
// - a VarDecl has one location per name; every other name or number a
//   check may underline has a location too (declared names, frames, pallet
//   corners and sizes, the Vacuum output, called, cycled and scanned names,
//   the variable after Next, the LimZ keyword).
#pragma once

#include <string>
#include <vector>

#include "base/source.h"
#include "ir/ir.h"

namespace smtcal {

struct VerifierIssue {
  std::string node;  // what kind of node, e.g. "Motion" or "BinaryExpr"
  SourceLoc loc;     // the node's location (unknown when that is the issue)
  std::string problem;
};

std::vector<VerifierIssue> VerifyProgram(const ir::Program& program);

// "file:line:col: Motion: target offset has no amount". Only the program's
// own file id is looked up in `sources`; other ids are printed as numbers so
// a corrupt id cannot crash the report of a corrupt IR.
std::string FormatVerifierIssue(const VerifierIssue& issue, const SourceManager& sources,
                                std::uint32_t program_file);

}  // namespace smtcal
