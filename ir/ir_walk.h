// Visiting every statement of a block, or every node of an expression, in
// source order. For the checks that only look for one kind of node (the
// Calls of a function, the Sw() reads of an expression); a check whose
// judgement depends on where a node sits (inside which Cycle, after which
// declaration) walks the tree itself.
#pragma once

#include "ir/ir.h"

namespace smtcal::ir {

// Calls visit(stmt) for each statement of `block` and, after each, for the
// statements nested in it (For and Cycle bodies, every If branch's body).
// A Function's body counts as nested too.
template <typename Visit>
void ForEachStmt(const Block& block, Visit&& visit) {
  for (const StmtPtr& stmt : block) {
    visit(*stmt);
    if (const auto* function = std::get_if<Function>(&stmt->node)) ForEachStmt(function->body, visit);
    if (const auto* loop = std::get_if<For>(&stmt->node)) ForEachStmt(loop->body, visit);
    if (const auto* cycle = std::get_if<Cycle>(&stmt->node)) ForEachStmt(cycle->body, visit);
    if (const auto* branch = std::get_if<If>(&stmt->node)) {
      for (const IfBranch& b : branch->branches) ForEachStmt(b.body, visit);
    }
  }
}

// Calls visit(expr) for `expr` and then for each of its operands, depth
// first; a null `expr` visits nothing.
template <typename Visit>
void ForEachExpr(const Expr* expr, Visit&& visit) {
  if (expr == nullptr) return;
  visit(*expr);
  if (const auto* unary = std::get_if<UnaryExpr>(&expr->node)) ForEachExpr(unary->operand.get(), visit);
  if (const auto* binary = std::get_if<BinaryExpr>(&expr->node)) {
    ForEachExpr(binary->lhs.get(), visit);
    ForEachExpr(binary->rhs.get(), visit);
  }
  if (const auto* sw = std::get_if<SwitchRead>(&expr->node)) ForEachExpr(sw->bit.get(), visit);
}

}  // namespace smtcal::ir
