// Printing expressions, points and number literals as the canonical form
// writes them (ir/ir_text.h).
#include "ir/ir_text.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>

#include "base/check.h"
#include "ir/ir_ops.h"

namespace smtcal {
namespace {

// Reals print in plain decimal inside this magnitude range and with an
// exponent outside it, so neither 1e-9 nor 1e20 becomes a wall of zeros.
constexpr double kSmallestPlainReal = 1e-5;
constexpr double kLargestPlainReal = 1e15;

int ExprPrecedence(const ir::Expr& expr) {
  if (const auto* binary = std::get_if<ir::BinaryExpr>(&expr.node)) {
    return ir::BinaryOpPrecedence(binary->op);
  }
  if (std::holds_alternative<ir::UnaryExpr>(expr.node)) return ir::kUnaryPrecedence;
  return ir::kPrimaryPrecedence;
}

std::string Parenthesized(const ir::Expr& expr, bool parenthesize) {
  std::string text = PrintExpr(expr);
  return parenthesize ? "(" + text + ")" : text;
}

}  // namespace

std::string PrintCoords(const ir::Coords& coords) {
  std::string text = "XY(";
  for (std::size_t i = 0; i < coords.values.size(); ++i) {
    if (i > 0) text += ", ";
    text += FormatRealLiteral(coords.values[i]);
  }
  return text + ")";
}

std::string FormatRealLiteral(double value) {
  SMTCAL_CHECK(std::isfinite(value), "non-finite number literal");
  double magnitude = std::fabs(value);
  bool plain = magnitude == 0 || (magnitude >= kSmallestPlainReal && magnitude < kLargestPlainReal);
  char buffer[64];
  auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value,
                                    plain ? std::chars_format::fixed : std::chars_format::scientific);
  SMTCAL_CHECK(error == std::errc(), "number does not fit the format buffer");
  std::string text(buffer, end);
  if (plain) {
    if (text.find('.') == std::string::npos) text += ".0";
    return text;
  }
  // to_chars writes "2.5e-07" or "1e+20"; canonical is "2.5e-7" and "1.0e20".
  std::size_t e = text.find('e');
  std::string mantissa = text.substr(0, e);
  if (mantissa.find('.') == std::string::npos) mantissa += ".0";
  std::string exponent = text.substr(e + 1);
  std::string sign;
  if (exponent[0] == '+' || exponent[0] == '-') {
    if (exponent[0] == '-') sign = "-";
    exponent.erase(0, 1);
  }
  exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
  return mantissa + "e" + sign + exponent;
}

std::string FormatIntegerLiteral(double value) {
  SMTCAL_CHECK(std::isfinite(value) && value == std::trunc(value), "integer literal is not an integer");
  // Shortest round-trip digits in plain notation: 99999999999999999999
  // (stored as 1e20) prints as 100000000000000000000, which reads back the same.
  char buffer[400];
  auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed);
  SMTCAL_CHECK(error == std::errc(), "number does not fit the format buffer");
  return std::string(buffer, end);
}

std::string PrintExpr(const ir::Expr& expr) {
  return std::visit(
      [&](const auto& node) -> std::string {
        using Node = std::decay_t<decltype(node)>;
        if constexpr (std::is_same_v<Node, ir::NumberLit>) {
          return node.is_integer ? FormatIntegerLiteral(node.value) : FormatRealLiteral(node.value);
        } else if constexpr (std::is_same_v<Node, ir::VariableRef>) {
          return node.name;
        } else if constexpr (std::is_same_v<Node, ir::OnOffLit>) {
          return node.on ? "On" : "Off";
        } else if constexpr (std::is_same_v<Node, ir::UnaryExpr>) {
          SMTCAL_CHECK(node.operand != nullptr, "unary expression without operand");
          std::string operand = Parenthesized(*node.operand, ExprPrecedence(*node.operand) < ir::kUnaryPrecedence);
          // Not is a word and needs a space before its operand; - and + do not.
          std::string_view space = node.op == ir::UnaryOp::Not ? " " : "";
          return fmt::format("{}{}{}", ir::UnaryOpSpelling(node.op), space, operand);
        } else if constexpr (std::is_same_v<Node, ir::BinaryExpr>) {
          SMTCAL_CHECK(node.lhs != nullptr && node.rhs != nullptr, "binary expression without operand");
          // Left-associative: the left operand needs parentheses only when it
          // binds looser, the right one also when it binds equally
          // (a - (b - c) keeps them, (a - b) - c does not).
          int precedence = ir::BinaryOpPrecedence(node.op);
          return Parenthesized(*node.lhs, ExprPrecedence(*node.lhs) < precedence) + " " +
                 std::string(ir::BinaryOpSpelling(node.op)) + " " +
                 Parenthesized(*node.rhs, ExprPrecedence(*node.rhs) <= precedence);
        } else if constexpr (std::is_same_v<Node, ir::SwitchRead>) {
          SMTCAL_CHECK(node.bit != nullptr, "Sw() without a bit");
          return "Sw(" + PrintExpr(*node.bit) + ")";
        } else {
          static_assert(sizeof(Node) == 0, "expression kind not printed");
        }
      },
      expr.node);
}

std::string PrintPointExpr(const ir::PointExpr& point) {
  std::string text = std::visit(
      [&](const auto& base) -> std::string {
        using Base = std::decay_t<decltype(base)>;
        if constexpr (std::is_same_v<Base, ir::NamedPoint>) {
          return base.name;
        } else if constexpr (std::is_same_v<Base, ir::Coords>) {
          return PrintCoords(base);
        } else if constexpr (std::is_same_v<Base, ir::PalletPoint>) {
          SMTCAL_CHECK(base.number != nullptr && base.i != nullptr, "Pallet() without its indexes");
          std::string pallet = "Pallet(" + PrintExpr(*base.number) + ", " + PrintExpr(*base.i);
          if (base.j) pallet += ", " + PrintExpr(*base.j);
          return pallet + ")";
        } else {
          static_assert(sizeof(Base) == 0, "point kind not printed");
        }
      },
      point.base);
  for (const ir::PointOffset& offset : point.offsets) {
    SMTCAL_CHECK(offset.amount != nullptr, "point offset without an amount");
    text += offset.negative ? " - " : " + ";
    text += ir::AxisSpelling(offset.axis);
    text += "(" + PrintExpr(*offset.amount) + ")";
  }
  return text;
}

}  // namespace smtcal
