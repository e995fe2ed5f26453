#include "ir/ir_ops.h"

#include <utility>

#include "base/check.h"

namespace smtcal::ir {

std::string_view BinaryOpSpelling(BinaryOp op) {
  switch (op) {
    case BinaryOp::Add: return "+";
    case BinaryOp::Sub: return "-";
    case BinaryOp::Mul: return "*";
    case BinaryOp::Div: return "/";
    case BinaryOp::Mod: return "Mod";
    case BinaryOp::Eq: return "=";
    case BinaryOp::Ne: return "<>";
    case BinaryOp::Lt: return "<";
    case BinaryOp::Gt: return ">";
    case BinaryOp::Le: return "<=";
    case BinaryOp::Ge: return ">=";
    case BinaryOp::And: return "And";
    case BinaryOp::Or: return "Or";
    case BinaryOp::Xor: return "Xor";
  }
  SMTCAL_CHECK(false, "unknown binary operator");
  return "";
}

std::string_view UnaryOpSpelling(UnaryOp op) {
  switch (op) {
    case UnaryOp::Negate: return "-";
    case UnaryOp::Plus: return "+";
    case UnaryOp::Not: return "Not";
  }
  SMTCAL_CHECK(false, "unknown unary operator");
  return "";
}

std::string_view AxisSpelling(Axis axis) {
  switch (axis) {
    case Axis::X: return "X";
    case Axis::Y: return "Y";
    case Axis::Z: return "Z";
    case Axis::U: return "U";
  }
  SMTCAL_CHECK(false, "unknown axis");
  return "";
}

int AxisIndex(Axis axis) {
  switch (axis) {
    case Axis::X: return 0;
    case Axis::Y: return 1;
    case Axis::Z: return 2;
    case Axis::U: return 3;
  }
  return 0;
}

std::string_view MotionSpelling(MotionKind kind) {
  switch (kind) {
    case MotionKind::Jump: return "Jump";
    case MotionKind::Go: return "Go";
    case MotionKind::Move: return "Move";
  }
  SMTCAL_CHECK(false, "unknown motion");
  return "";
}

std::string_view PickPlaceSpelling(PickPlaceKind kind) {
  switch (kind) {
    case PickPlaceKind::Pick: return "Pick";
    case PickPlaceKind::Place: return "Place";
  }
  SMTCAL_CHECK(false, "unknown pick or place");
  return "";
}

Precedence BinaryOpPrecedence(BinaryOp op) {
  switch (op) {
    case BinaryOp::Or:
    case BinaryOp::Xor: return kOrXorPrecedence;
    case BinaryOp::And: return kAndPrecedence;
    case BinaryOp::Eq:
    case BinaryOp::Ne:
    case BinaryOp::Lt:
    case BinaryOp::Gt:
    case BinaryOp::Le:
    case BinaryOp::Ge: return kComparisonPrecedence;
    case BinaryOp::Add:
    case BinaryOp::Sub: return kAdditivePrecedence;
    case BinaryOp::Mul:
    case BinaryOp::Div:
    case BinaryOp::Mod: return kMultiplicativePrecedence;
  }
  SMTCAL_CHECK(false, "unknown binary operator");
  return kPrimaryPrecedence;
}

const PointExpr* MotionTarget(const Stmt& stmt) {
  if (const auto* pick = std::get_if<PickPlace>(&stmt.node)) return &pick->target;
  if (const auto* motion = std::get_if<Motion>(&stmt.node)) return &motion->target;
  return nullptr;
}

PointExpr* MotionTarget(Stmt& stmt) { return const_cast<PointExpr*>(MotionTarget(std::as_const(stmt))); }

std::string ProgramName(const Program& program) {
  for (const StmtPtr& item : program.items) {
    if (const auto* decl = std::get_if<ProgramDecl>(&item->node)) return decl->name;
  }
  return "program";
}

const Stmt* CorrectedHeader(const Program& program) {
  for (const StmtPtr& stmt : program.items) {
    const auto* comment = std::get_if<Comment>(&stmt->node);
    if (comment == nullptr) return nullptr;
    if (comment->text.starts_with(kCorrectedHeaderPrefix)) return stmt.get();
  }
  return nullptr;
}

}  // namespace smtcal::ir
