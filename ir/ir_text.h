// Expressions, points and number literals as text, exactly as the canonical
// form writes them (docs/language.md, "Canonical form"). The program printer
// (backend/place/place_printer.h) prints whole programs with these; passes
// use them to name what they report on.
#pragma once

#include <string>

#include "ir/ir.h"

namespace smtcal {

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
