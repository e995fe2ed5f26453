#include "ir/constant_fold.h"

#include <cmath>
#include <limits>

namespace smtcal::sema {

std::optional<Constant> FoldConstant(const ir::Expr* expr) {
  if (expr == nullptr) return std::nullopt;
  if (const auto* number = std::get_if<ir::NumberLit>(&expr->node)) {
    return Constant{number->value, number->is_integer};
  }
  if (const auto* unary = std::get_if<ir::UnaryExpr>(&expr->node)) {
    if (unary->op == ir::UnaryOp::Not) return std::nullopt;
    std::optional<Constant> operand = FoldConstant(unary->operand.get());
    if (!operand) return std::nullopt;
    if (unary->op == ir::UnaryOp::Negate) operand->value = -operand->value;
    return operand;
  }
  if (const auto* binary = std::get_if<ir::BinaryExpr>(&expr->node)) {
    if (binary->op != ir::BinaryOp::Add && binary->op != ir::BinaryOp::Sub &&
        binary->op != ir::BinaryOp::Mul) {
      return std::nullopt;
    }
    std::optional<Constant> lhs = FoldConstant(binary->lhs.get());
    std::optional<Constant> rhs = FoldConstant(binary->rhs.get());
    if (!lhs || !rhs) return std::nullopt;
    double value = binary->op == ir::BinaryOp::Add   ? lhs->value + rhs->value
                   : binary->op == ir::BinaryOp::Sub ? lhs->value - rhs->value
                                                     : lhs->value * rhs->value;
    if (!std::isfinite(value)) return std::nullopt;
    return Constant{value, lhs->is_integer && rhs->is_integer};
  }
  return std::nullopt;
}

std::optional<int> FoldInteger(const ir::Expr* expr) {
  std::optional<Constant> constant = FoldConstant(expr);
  if (!constant || !constant->is_integer) return std::nullopt;
  if (constant->value < std::numeric_limits<int>::min() ||
      constant->value > std::numeric_limits<int>::max()) {
    return std::nullopt;
  }
  return static_cast<int>(constant->value);
}

}  // namespace smtcal::sema
