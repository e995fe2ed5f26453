// Constant folding for the range checks, deliberately small: numeric
// literals, unary plus and minus, and + - * of constants. Anything else
// (variables, division, Sw(), comparisons) is "not a constant" and is left to
// run time; the checks only judge what they can see for certain.
#pragma once

#include <optional>

#include "ir/ir.h"

namespace smtcal::sema {

struct Constant {
  double value = 0;
  bool is_integer = false;  // every literal in it was an Integer literal
};

std::optional<Constant> FoldConstant(const ir::Expr* expr);
// The value when `expr` folds to an Integer constant that fits an int.
std::optional<int> FoldInteger(const ir::Expr* expr);

}  // namespace smtcal::sema
