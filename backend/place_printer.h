// The canonical printer for .place programs (`smtcal fmt`, and the `place`
// target's output). The canonical form is documented in docs/language.md,
// section "Canonical form". Printing keeps everything the IR holds: comments,
// blank lines between statements, names as written; parsing the output gives
// the same IR as the input, and printing that again gives the same text.
#pragma once

#include <string>

#include "passes/ir.h"

namespace smtcal {

// The whole program in canonical form: every line ends with '\n', an empty
// program prints as "".
std::string PrintPlace(const ir::Program& program);

// What printing changes on purpose, done to an IR: a `Next` that is bare or
// spells its loop variable differently gets the For's spelling, and the first
// statement of the file and of every block loses its blank line. For every
// program p that parses, parsing PrintPlace(p) gives exactly the IR of
// ApplyCanonicalChanges(p) (equal DumpIr without locations).
void ApplyCanonicalChanges(ir::Program& program);

// One expression with the minimal parentheses that keep its tree.
std::string PrintExpr(const ir::Expr& expr);

// A point expression: `P1 + X(d)`, `XY(...)`, `Pallet(n, i, j) - Z(h)`.
std::string PrintPointExpr(const ir::PointExpr& point);
// XY(x, y, z, u) as the canonical form writes it.
std::string PrintCoords(const ir::Coords& coords);

// Number literals. A real literal is its shortest round-trip decimal and
// always has a '.' (12.70 -> "12.7", -12 -> "-12.0"); magnitudes outside
// [1e-5, 1e15) use an exponent ("1.0e20", "2.5e-7"). An integer literal is
// printed without '.'.
std::string FormatRealLiteral(double value);
std::string FormatIntegerLiteral(double value);

}  // namespace smtcal
