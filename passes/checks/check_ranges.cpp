// check-ranges: numbers the controller can take, where they are constants.
//
// Assumes: an IR that passes the verifier. Only constants are judged (see
// ir/constant_fold.h): a value computed at run time is the runtime's to
// bound. Pallet numbers that name no pallet are check-names' to report.
// Guarantees when it reports no error, for every constant: I/O bits (On,
// Off, Sw, Wait Sw) and vacuum outputs are within calibration/limits.h; pallet
// numbers are 0..15 and pallets have at least one column and one row; pallet
// indices lie within their pallet; no For has Step 0; no Wait is negative;
// every XY's u is within one turn; LimZ appears only on Jump, Pick and Place;
// every Pick and Place has a vacuum output (its own or the program's
// `Vacuum n`). Reads the IR, never changes it.
#include <cmath>
#include <string>

#include "calibration/limits.h"
#include "ir/constant_fold.h"
#include "ir/ir_ops.h"
#include "ir/ir_walk.h"
#include "ir/symbols.h"
#include "passes/checks/checks.h"

namespace smtcal {
namespace {

class CheckRanges final : public Pass {
 public:
  std::string_view Name() const override { return "check-ranges"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    diags_ = &diags;
    const sema::SymbolTable& table = sema::SymbolsOf(program);
    table_ = &table;
    for (const ir::StmtPtr& item : program.items) {
      if (std::holds_alternative<ir::VacuumDecl>(item->node)) has_default_vacuum_ = true;
    }
    for (const ir::StmtPtr& item : program.items) TopLevel(*item);
  }

 private:
  // A whole number written at `loc`: the caret underlines its digits.
  static SourceRange NumberAt(SourceLoc loc, int value) {
    return SourceRange(loc, static_cast<std::uint32_t>(std::to_string(value).size()));
  }

  void TopLevel(const ir::Stmt& stmt) {
    if (const auto* vacuum = std::get_if<ir::VacuumDecl>(&stmt.node)) {
      if (vacuum->output < limits::kVacuumOutputMin || vacuum->output > limits::kVacuumOutputMax) {
        diags_->Report(DiagKind::VacuumOutputOutOfRange, NumberAt(vacuum->output_loc, vacuum->output),
                       vacuum->output, limits::kVacuumOutputMin, limits::kVacuumOutputMax);
      }
    } else if (const auto* pallet = std::get_if<ir::PalletDecl>(&stmt.node)) {
      Pallet(*pallet);
    } else if (const auto* local = std::get_if<ir::LocalDecl>(&stmt.node)) {
      Angle(local->origin);
    } else if (const auto* point = std::get_if<ir::PointDecl>(&stmt.node)) {
      Angle(point->coords);
    } else if (const auto* function = std::get_if<ir::Function>(&stmt.node)) {
      Block(function->body);
    }
  }

  void Pallet(const ir::PalletDecl& pallet) {
    if (pallet.number < limits::kPalletNumberMin || pallet.number > limits::kPalletNumberMax) {
      diags_->Report(DiagKind::PalletNumberOutOfRange, NumberAt(pallet.number_loc, pallet.number),
                     pallet.number, limits::kPalletNumberMin, limits::kPalletNumberMax);
    }
    if (pallet.columns < limits::kPalletMinColumns) {
      diags_->Report(DiagKind::PalletSizeInvalid, NumberAt(pallet.columns_loc, pallet.columns), pallet.number,
                     pallet.columns, "columns");
    }
    if (pallet.rows < limits::kPalletMinRows) {
      diags_->Report(DiagKind::PalletSizeInvalid, NumberAt(pallet.rows_loc, pallet.rows), pallet.number,
                     pallet.rows, "rows");
    }
  }

  void Angle(const ir::Coords& coords) {
    double u = coords.values[3];
    if (std::abs(u) > limits::kMaxAbsAngleDeg) {
      diags_->Report(DiagKind::AngleOutOfRange, SourceRange(coords.loc, 2), u);
    }
  }

  // ---------------------------------------------------------------- statements

  void Block(const ir::Block& block) {
    for (const ir::StmtPtr& stmt : block) Stmt(*stmt);
  }

  void Stmt(const ir::Stmt& stmt) {
    if (const auto* assign = std::get_if<ir::Assign>(&stmt.node)) {
      Expr(assign->value.get());
    } else if (const auto* motion = std::get_if<ir::Motion>(&stmt.node)) {
      Point(motion->target);
      Expr(motion->limz.get());
      if (motion->limz != nullptr && motion->kind != ir::MotionKind::Jump) {
        diags_->Report(DiagKind::LimZNotAllowed, sema::NameAt(motion->limz_loc, "LimZ"),
                       ir::MotionSpelling(motion->kind));
      }
    } else if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) {
      Point(pick->target);
      Expr(pick->vacuum.get());
      Expr(pick->limz.get());
      if (pick->vacuum != nullptr) {
        Bit(pick->vacuum.get(), DiagKind::VacuumOutputOutOfRange, limits::kVacuumOutputMin,
            limits::kVacuumOutputMax);
      } else if (!has_default_vacuum_) {
        diags_->Report(DiagKind::MissingVacuumOutput, sema::StmtRange(stmt), ir::PickPlaceSpelling(pick->kind));
      }
    } else if (const auto* output = std::get_if<ir::SetOutput>(&stmt.node)) {
      Expr(output->bit.get());
      Bit(output->bit.get(), DiagKind::IoBitOutOfRange, limits::kIoBitMin, limits::kIoBitMax);
    } else if (const auto* wait = std::get_if<ir::WaitTime>(&stmt.node)) {
      Expr(wait->seconds.get());
      std::optional<sema::Constant> seconds = sema::FoldConstant(wait->seconds.get());
      if (seconds && seconds->value < 0) {
        diags_->Report(DiagKind::NegativeWait, sema::ExprRange(*wait->seconds), seconds->value);
      }
    } else if (const auto* wait_sw = std::get_if<ir::WaitSwitch>(&stmt.node)) {
      Expr(wait_sw->bit.get());
      Bit(wait_sw->bit.get(), DiagKind::IoBitOutOfRange, limits::kIoBitMin, limits::kIoBitMax);
    } else if (const auto* loop = std::get_if<ir::For>(&stmt.node)) {
      Expr(loop->from.get());
      Expr(loop->to.get());
      Expr(loop->step.get());
      std::optional<sema::Constant> step = sema::FoldConstant(loop->step.get());
      if (step && step->value == 0) diags_->Report(DiagKind::ForStepZero, sema::ExprRange(*loop->step));
      Block(loop->body);
    } else if (const auto* branch = std::get_if<ir::If>(&stmt.node)) {
      for (const ir::IfBranch& b : branch->branches) {
        Expr(b.condition.get());
        Block(b.body);
      }
    } else if (const auto* cycle = std::get_if<ir::Cycle>(&stmt.node)) {
      Block(cycle->body);
    }
  }

  // A constant bit or output number outside [min, max].
  void Bit(const ir::Expr* expr, DiagKind kind, int min, int max) {
    std::optional<sema::Constant> value = sema::FoldConstant(expr);
    if (value && (value->value < min || value->value > max)) {
      diags_->Report(kind, sema::ExprRange(*expr), value->value, min, max);
    }
  }

  void Point(const ir::PointExpr& point) {
    if (const auto* coords = std::get_if<ir::Coords>(&point.base)) Angle(*coords);
    if (const auto* pallet = std::get_if<ir::PalletPoint>(&point.base)) PalletIndex(*pallet);
    for (const ir::PointOffset& offset : point.offsets) Expr(offset.amount.get());
  }

  void PalletIndex(const ir::PalletPoint& point) {
    Expr(point.number.get());
    Expr(point.i.get());
    Expr(point.j.get());
    std::optional<sema::Constant> number = sema::FoldConstant(point.number.get());
    if (!number) return;
    if (number->value < limits::kPalletNumberMin || number->value > limits::kPalletNumberMax) {
      diags_->Report(DiagKind::PalletNumberOutOfRange, sema::ExprRange(*point.number), number->value,
                     limits::kPalletNumberMin, limits::kPalletNumberMax);
      return;
    }
    std::optional<int> declared = sema::FoldInteger(point.number.get());
    const sema::SymbolTable::PalletEntry* entry = declared ? table_->FindPallet(*declared) : nullptr;
    if (entry == nullptr) return;  // undefined: check-names reports it
    const ir::PalletDecl& pallet = *entry->pallet;
    if (pallet.columns < limits::kPalletMinColumns || pallet.rows < limits::kPalletMinRows) return;
    auto index = [&](const ir::Expr* expr, const char* what, const char* plural, int count) {
      std::optional<sema::Constant> value = sema::FoldConstant(expr);
      if (value && (value->value < limits::kPalletFirstIndex || value->value > count)) {
        diags_->Report(DiagKind::PalletIndexOutOfRange, sema::ExprRange(*expr), what, value->value,
                       pallet.number, pallet.columns, pallet.rows, plural, count);
      }
    };
    if (point.j == nullptr) {
      index(point.i.get(), "position", "positions", pallet.columns * pallet.rows);
    } else {
      index(point.i.get(), "column", "columns", pallet.columns);
      index(point.j.get(), "row", "rows", pallet.rows);
    }
  }

  // Sw(n) reads anywhere in an expression.
  void Expr(const ir::Expr* expr) {
    ir::ForEachExpr(expr, [&](const ir::Expr& node) {
      if (const auto* sw = std::get_if<ir::SwitchRead>(&node.node)) {
        Bit(sw->bit.get(), DiagKind::IoBitOutOfRange, limits::kIoBitMin, limits::kIoBitMax);
      }
    });
  }

  Diagnostics* diags_ = nullptr;
  const sema::SymbolTable* table_ = nullptr;
  bool has_default_vacuum_ = false;
};

}  // namespace

std::unique_ptr<Pass> CreateCheckRangesPass() { return std::make_unique<CheckRanges>(); }

}  // namespace smtcal
