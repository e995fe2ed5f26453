// How the .place language writes the IR's operators, axes and motion
// keywords, and how tightly operators bind. One home for them, so the
// canonical printer, the IR dump and the checks' messages cannot drift apart
// (the parser maps tokens to the IR in frontend/parse.cpp).
#pragma once

#include <string>
#include <string_view>

#include "ir/ir.h"

namespace smtcal::ir {

// "+", "-", "*", "/", "Mod", "=", "<>", "<", ">", "<=", ">=", "And", "Or", "Xor".
std::string_view BinaryOpSpelling(BinaryOp op);
// "-", "+", "Not".
std::string_view UnaryOpSpelling(UnaryOp op);
// "X", "Y", "Z", "U".
std::string_view AxisSpelling(Axis axis);
// 0, 1, 2, 3: the axis's place in Coords::values (x, y, z, u).
int AxisIndex(Axis axis);
// "Jump", "Go", "Move".
std::string_view MotionSpelling(MotionKind kind);
// "Pick", "Place".
std::string_view PickPlaceSpelling(PickPlaceKind kind);

// The point a Jump/Go/Move or a Pick/Place commands; null for any other
// statement.
const PointExpr* MotionTarget(const Stmt& stmt);
PointExpr* MotionTarget(Stmt& stmt);

// `smtcal compile --target place` output opens with comments, the first of
// them starting with this: what the program is, so it is never compiled twice.
inline constexpr std::string_view kCorrectedHeaderPrefix = " Corrected by smtcal ";
// The statement holding that comment among the program's leading comments,
// or null: the program is not smtcal output.
const Stmt* CorrectedHeader(const Program& program);

// The name the program's `Program NAME` declares, or "program".
std::string ProgramName(const Program& program);

// Binding strength, from the grammar's expr rule (ANTLR gives the earlier
// alternative the higher precedence); higher binds tighter. All binary
// operators are left-associative. A unary operator's operand is a primary or
// another unary expression, so `-a * b` is (-a) * b and `Not a = b` is
// (Not a) = b.
enum Precedence : int {
  kOrXorPrecedence = 1,
  kAndPrecedence = 2,
  kComparisonPrecedence = 3,
  kAdditivePrecedence = 4,
  kMultiplicativePrecedence = 5,
  kUnaryPrecedence = 6,
  kPrimaryPrecedence = 7,
};
Precedence BinaryOpPrecedence(BinaryOp op);

}  // namespace smtcal::ir
