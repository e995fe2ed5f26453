// check-types: expressions are Integer, Real or Boolean and used as such.
//
// Assumes: an IR that passes the verifier. Names that do not resolve to a
// variable are check-names' to report: their type is unknown here and
// nothing built on them is reported again.
// Guarantees when it reports no error:
// - literals: Integer when written without '.' or exponent, else Real;
//   On/Off, Sw(n), comparisons and And/Or/Xor/Not are Boolean;
// - + - * of Integers is Integer, of any Real is Real; / is always Real;
//   Mod takes Integers; arithmetic and < > <= >= take numbers; = and <>
//   compare two numbers or two Booleans; And/Or/Xor/Not take Booleans;
// - If/ElseIf conditions are Boolean; a variable is never assigned a
//   Boolean, and an Integer variable never a Real (it would truncate; the
//   same holds for a For's bounds and step);
// - I/O bits, vacuum outputs, pallet numbers and indices are Integer; LimZ,
//   point offsets, Wait times and For bounds are numbers;
// - `Next v` names its For's variable.
// Reads the IR, never changes it.
#include "ir/ir_ops.h"
#include "ir/symbols.h"
#include "passes/checks/checks.h"

namespace smtcal {
namespace {

enum class Type { Integer, Real, Boolean, Unknown };

const char* TypeName(Type type) {
  switch (type) {
    case Type::Integer: return "Integer";
    case Type::Real: return "Real";
    case Type::Boolean: return "Boolean";
    case Type::Unknown: return "unknown";
  }
  return "unknown";
}

const char* TypeWithArticle(Type type) {
  return type == Type::Integer ? "an Integer" : type == Type::Real ? "a Real" : "a Boolean";
}

bool IsNumber(Type type) { return type == Type::Integer || type == Type::Real; }

constexpr const char* kCompareHint = "; compare it, e.g. 'x <> 0'";

class CheckTypes final : public Pass {
 public:
  std::string_view Name() const override { return "check-types"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    diags_ = &diags;
    const sema::SymbolTable& table = sema::SymbolsOf(program);
    for (const ir::StmtPtr& item : program.items) {
      const auto* function = std::get_if<ir::Function>(&item->node);
      if (function == nullptr) continue;
      sema::LocalScope scope(table);
      scope_ = &scope;
      Block(function->body);
      scope_ = nullptr;
    }
  }

 private:
  // ---------------------------------------------------------------- expressions

  Type TypeOf(const ir::Expr& expr) {
    if (const auto* number = std::get_if<ir::NumberLit>(&expr.node)) {
      return number->is_integer ? Type::Integer : Type::Real;
    }
    if (const auto* variable = std::get_if<ir::VariableRef>(&expr.node)) {
      const sema::Symbol* symbol = scope_->Find(variable->name);
      if (symbol == nullptr || symbol->kind != sema::SymbolKind::Variable) return Type::Unknown;
      return symbol->var_type == ir::VarType::Integer ? Type::Integer : Type::Real;
    }
    if (std::holds_alternative<ir::OnOffLit>(expr.node)) return Type::Boolean;
    if (const auto* sw = std::get_if<ir::SwitchRead>(&expr.node)) {
      Integer(sw->bit.get(), "an I/O bit number");
      return Type::Boolean;
    }
    if (const auto* unary = std::get_if<ir::UnaryExpr>(&expr.node)) {
      Type operand = TypeOf(*unary->operand);
      if (unary->op == ir::UnaryOp::Not) {
        if (IsNumber(operand)) {
          // Usually `Not a > b`, which is (Not a) > b: Not binds tightest.
          diags_->Report(DiagKind::OperandType, sema::ExprRange(*unary->operand), "Not", "Boolean",
                         TypeName(operand), "; Not binds tighter than comparisons, so write 'Not (a > b)'");
          return Type::Unknown;
        }
        return operand == Type::Boolean ? Type::Boolean : Type::Unknown;
      }
      return Operand(*unary->operand, operand, ir::UnaryOpSpelling(unary->op), /*want_number=*/true) ? operand
                                                                                                 : Type::Unknown;
    }
    const auto& binary = std::get<ir::BinaryExpr>(expr.node);
    Type lhs = TypeOf(*binary.lhs);
    Type rhs = TypeOf(*binary.rhs);
    std::string_view op = ir::BinaryOpSpelling(binary.op);
    switch (binary.op) {
      case ir::BinaryOp::Add:
      case ir::BinaryOp::Sub:
      case ir::BinaryOp::Mul:
      case ir::BinaryOp::Div: {
        bool lhs_ok = Operand(*binary.lhs, lhs, op, true);
        bool rhs_ok = Operand(*binary.rhs, rhs, op, true);
        if (!lhs_ok || !rhs_ok) return Type::Unknown;
        if (binary.op == ir::BinaryOp::Div) return Type::Real;
        return lhs == Type::Integer && rhs == Type::Integer ? Type::Integer : Type::Real;
      }
      case ir::BinaryOp::Mod: {
        bool lhs_ok = IntegerOperand(*binary.lhs, lhs, op);
        bool rhs_ok = IntegerOperand(*binary.rhs, rhs, op);
        return lhs_ok && rhs_ok ? Type::Integer : Type::Unknown;
      }
      case ir::BinaryOp::Eq:
      case ir::BinaryOp::Ne:
        if (lhs != Type::Unknown && rhs != Type::Unknown && IsNumber(lhs) != IsNumber(rhs)) {
          diags_->Report(DiagKind::ComparisonTypes, sema::ExprRange(expr), op, TypeWithArticle(lhs),
                         TypeWithArticle(rhs));
        }
        return Type::Boolean;
      case ir::BinaryOp::Lt:
      case ir::BinaryOp::Gt:
      case ir::BinaryOp::Le:
      case ir::BinaryOp::Ge:
        Operand(*binary.lhs, lhs, op, true);
        Operand(*binary.rhs, rhs, op, true);
        return Type::Boolean;
      case ir::BinaryOp::And:
      case ir::BinaryOp::Or:
      case ir::BinaryOp::Xor: {
        bool lhs_ok = Operand(*binary.lhs, lhs, op, false);
        bool rhs_ok = Operand(*binary.rhs, rhs, op, false);
        return lhs_ok && rhs_ok ? Type::Boolean : Type::Unknown;
      }
    }
    return Type::Unknown;
  }

  // Whether an operand of `op` has the type it needs (numbers, or Boolean);
  // reports it when not. Unknown operands were reported elsewhere.
  bool Operand(const ir::Expr& operand, Type type, std::string_view op, bool want_number) {
    if (type == Type::Unknown) return false;
    if (IsNumber(type) == want_number) return true;
    diags_->Report(DiagKind::OperandType, sema::ExprRange(operand), op, want_number ? "number" : "Boolean",
                   TypeName(type), want_number ? "" : kCompareHint);
    return false;
  }

  bool IntegerOperand(const ir::Expr& operand, Type type, std::string_view op) {
    if (type == Type::Unknown) return false;
    if (type == Type::Integer) return true;
    diags_->Report(DiagKind::OperandType, sema::ExprRange(operand), op, "Integer", TypeName(type), "");
    return false;
  }

  // ---------------------------------------------------------------- contexts

  Type Integer(const ir::Expr* expr, const char* what) {
    if (expr == nullptr) return Type::Unknown;
    Type type = TypeOf(*expr);
    if (type == Type::Real || type == Type::Boolean) {
      diags_->Report(DiagKind::ExpectedInteger, sema::ExprRange(*expr), what, TypeName(type));
    }
    return type;
  }

  Type Number(const ir::Expr* expr, const char* what, std::string_view hint = "") {
    if (expr == nullptr) return Type::Unknown;
    Type type = TypeOf(*expr);
    if (type == Type::Boolean) diags_->Report(DiagKind::ExpectedNumber, sema::ExprRange(*expr), what, hint);
    return type;
  }

  void Condition(const ir::Expr* expr, const char* what) {
    if (expr == nullptr) return;
    Type type = TypeOf(*expr);
    if (IsNumber(type)) diags_->Report(DiagKind::ConditionNotBoolean, sema::ExprRange(*expr), what, TypeName(type));
  }

  // A value of type `type` stored into `variable`.
  void Store(const sema::Symbol* variable, const ir::Expr* value, Type type, const char* what) {
    if (variable == nullptr || value == nullptr || variable->kind != sema::SymbolKind::Variable) return;
    if (type == Type::Boolean) {
      diags_->Report(DiagKind::AssignBoolean, sema::ExprRange(*value),
                     variable->var_type == ir::VarType::Integer ? "Integer" : "Real", variable->name);
    } else if (type == Type::Real && variable->var_type == ir::VarType::Integer) {
      diags_->Report(DiagKind::IntegerTruncation, sema::ExprRange(*value), what, variable->name, variable->name);
    }
  }

  void Point(const ir::PointExpr& point) {
    if (const auto* pallet = std::get_if<ir::PalletPoint>(&point.base)) {
      Integer(pallet->number.get(), "a pallet number");
      Integer(pallet->i.get(), "a pallet index");
      Integer(pallet->j.get(), "a pallet index");
    }
    for (const ir::PointOffset& offset : point.offsets) Number(offset.amount.get(), "a point offset");
  }

  // ---------------------------------------------------------------- statements

  void Block(const ir::Block& block) {
    for (const ir::StmtPtr& stmt : block) Stmt(*stmt);
  }

  void Stmt(const ir::Stmt& stmt) {
    if (std::holds_alternative<ir::VarDecl>(stmt.node)) {
      for (sema::Symbol& local : sema::VariablesDeclaredBy(stmt, /*global=*/false)) {
        (void)scope_->Declare(std::move(local));  // clashes are check-names' to report
      }
    } else if (const auto* assign = std::get_if<ir::Assign>(&stmt.node)) {
      Type type = TypeOf(*assign->value);
      Store(scope_->Find(assign->name), assign->value.get(), type, "the assigned value");
    } else if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) {
      Point(motion->target);
      Number(motion->limz.get(), "LimZ");
    } else if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) {
      Point(pick->target);
      Integer(pick->vacuum.get(), "a vacuum output");
      Number(pick->limz.get(), "LimZ");
    } else if (const auto* output = std::get_if<ir::SetOutput>(&stmt.node)) {
      Integer(output->bit.get(), "an I/O bit number");
    } else if (const auto* wait = std::get_if<ir::WaitTime>(&stmt.node)) {
      Number(wait->seconds.get(), "the Wait time",
             "; to wait for an input, write 'Wait Sw(n) = On'");
    } else if (const auto* wait_sw = std::get_if<ir::WaitSwitch>(&stmt.node)) {
      Integer(wait_sw->bit.get(), "an I/O bit number");
    } else if (const auto* loop = std::get_if<ir::For>(&stmt.node)) {
      For(*loop);
    } else if (const auto* branch = std::get_if<ir::If>(&stmt.node)) {
      for (std::size_t i = 0; i < branch->branches.size(); ++i) {
        Condition(branch->branches[i].condition.get(), i == 0 ? "If" : "ElseIf");
        Block(branch->branches[i].body);
      }
    } else if (const auto* cycle = std::get_if<ir::Cycle>(&stmt.node)) {
      Block(cycle->body);
    }
  }

  void For(const ir::For& loop) {
    const sema::Symbol* variable = scope_->Find(loop.var);
    // A Boolean bound is reported as not a number; only Reals can truncate.
    auto bound = [&](const ir::ExprPtr& expr, const char* what) {
      if (Number(expr.get(), what) == Type::Real) Store(variable, expr.get(), Type::Real, what);
    };
    bound(loop.from, "the For start value");
    bound(loop.to, "the For end value");
    bound(loop.step, "the For step");
    Block(loop.body);
    if (!loop.next_var.empty() && !sema::SameName(loop.next_var, loop.var)) {
      Diagnostic* diag = diags_->Report(DiagKind::NextMismatch, sema::NameAt(loop.next_var_loc, loop.next_var),
                                        loop.next_var, loop.var, loop.var);
      Diagnostics::AddNote(diag, sema::NameAt(loop.var_loc, loop.var),
                           fmt::format("the For of '{}' is here", loop.var));
    }
  }

  Diagnostics* diags_ = nullptr;
  sema::LocalScope* scope_ = nullptr;
};

}  // namespace

std::unique_ptr<Pass> CreateCheckTypesPass() { return std::make_unique<CheckTypes>(); }

}  // namespace smtcal
