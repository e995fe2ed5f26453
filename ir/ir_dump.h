// A readable, deterministic S-expression dump of the IR, for tests and
// debugging. Every field of every node is printed (numbers with fmt's
// shortest round-trip "{}", comments included), so two programs are the same
// IR exactly when their dumps without locations are equal; the parser tests
// and the fmt round-trip test rely on that.
//
// One statement per line, blocks indented by two spaces:
//
//   (program
//     (comment " layer_a.place")
//     (point-decl C1 (xy 12.7 8.25 -3 90) :frame Board :comment " off-line")
//     (function Main
//       (place (point (name C1) (+x (* (var layer) (real 55)))))
//       (end)))
//
// Optional fields appear as ":key value" only when set; flags as ":taught",
// ":blank" (a blank line precedes the statement). Whole-number literals print
// as (int 1), others as (real 1.5). With locations, each node with a
// SourceLoc gets "@file:line:column" after its head word, plus "/length"
// where the node has a length; a name, number or keyword with a location of
// its own gets it right after itself ("Board @1:3:9", ":limz @1:8:12 ...").
#pragma once

#include <string>

#include "ir/ir.h"

namespace smtcal {

std::string DumpIr(const ir::Program& program, bool with_locations = false);
// One expression on one line, e.g. "(+ (var a) (int 1))".
std::string DumpExpr(const ir::Expr& expr, bool with_locations = false);

}  // namespace smtcal
