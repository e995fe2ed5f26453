// regions: every motion target gets its calibrated region and its kind of
// correction.
//
// Assumes: bind ran (state.targets found, fixtures bound).
// Guarantees when it reports no error: every region of the cell calibrates
// exactly x and y (D = (2, {x, y})), the only difficulty smtcal serves so far,
// so z and u pass through uncorrected; every Pick and Place target whose
// position is known lies in a region (fixture targets at the fixture's
// nominal pose, taught ones where they were taught); each target's kind is
// set: fixture targets are corrected on the controller every cycle, a
// base-frame statement with one known position is static, one with several
// positions or an unknown one is corrected at run time, and a Jump/Go/Move
// outside every region is commanded uncorrected (warned). Never changes the IR.
#include <algorithm>
#include <memory>
#include <unordered_map>

#include <fmt/format.h>

#include "calibration/error_table.h"
#include "ir/ir_ops.h"
#include "ir/symbols.h"
#include "passes/correction/compile_state.h"
#include "passes/correction/correction_passes.h"

namespace smtcal {

namespace {

std::string RegionList(const cell::Cell& cell) {
  std::vector<std::string> parts;
  for (const cell::Region& region : cell.regions) {
    parts.push_back(fmt::format("{} x {}..{}, y {}..{}", region.name, FormatMm(region.x_mm.lo), FormatMm(region.x_mm.hi),
                                FormatMm(region.y_mm.lo), FormatMm(region.y_mm.hi)));
  }
  return parts.empty() ? std::string("it has none") : fmt::format("{}", fmt::join(parts, "; "));
}

class Regions final : public Pass {
 public:
  std::string_view Name() const override { return "regions"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    SMTCAL_CHECK(program.compile != nullptr, "regions runs after bind");
    CompileState& state = *program.compile;
    const cell::Cell& cell = *state.cell;
    for (const cell::Region& region : cell.regions) CheckDifficulty(region, diags);

    // A base-frame statement is static only when it has one known position.
    const std::unordered_map<const ir::Stmt*, bool> as_written = BaseStatementsCommandedAsWritten(state.targets);
    const std::string regions = RegionList(cell);  // the same in every message
    for (Target& target : state.targets) {
      std::string_view keyword = TargetKeyword(*target.stmt);
      SourceRange where = sema::StmtRange(*target.stmt);
      if (target.fixture >= 0) {
        target.kind = CorrectionKind::kFixture;
      } else {
        target.kind = as_written.at(target.stmt) ? CorrectionKind::kStatic : CorrectionKind::kRunTimeBase;
      }
      if (!target.known) {
        diags.Report(DiagKind::TargetPositionUnknown, where, keyword, target.text, target.unknown_because);
        continue;
      }
      target.required = RequiredPosition(target, state);
      target.region = cell.RegionAt(Xy(target.required));
      if (target.region != nullptr) continue;
      std::string x = FormatComputedMm(target.required[0]), y = FormatComputedMm(target.required[1]);
      if (std::holds_alternative<ir::PickPlace>(target.stmt->node)) {
        diags.Report(DiagKind::TargetOutsideRegions, where, keyword, target.text, x, y, regions);
      } else {
        target.kind = CorrectionKind::kUncorrected;
        target.nominal = target.required;
        diags.Report(DiagKind::TargetUncorrected, where, keyword, target.text, x, y, regions);
      }
    }
  }

 private:
  static void CheckDifficulty(const cell::Region& region, Diagnostics& diags) {
    bool has_x = false, has_y = false, other = false;
    std::vector<std::string_view> names;
    for (cell::TaskAxis axis : region.difficulty_axes) {
      names.push_back(cell::TaskAxisName(axis));
      has_x |= axis == cell::TaskAxis::X;
      has_y |= axis == cell::TaskAxis::Y;
      other |= axis == cell::TaskAxis::Z || axis == cell::TaskAxis::U;
    }
    if (has_x && has_y && !other) return;
    std::string axes = fmt::format("{}", fmt::join(names, ", "));
    diags.Report(DiagKind::RegionDifficultyUnsupported, region.difficulty_range, region.name,
                 names.empty() ? std::string("no axis") : axes, region.difficulty_level, axes);
  }

  // The base-frame position the target requires: fixture targets at the
  // fixture's nominal pose; taught targets where they were taught (their
  // fixture coordinates are not known before fixture-correction).
  static Pose4 RequiredPosition(const Target& target, const CompileState& state) {
    if (target.fixture < 0 || target.taught_decl != nullptr) return target.in_frame;
    return PoseToBase(state.fixtures[target.fixture].nominal, target.in_frame);
  }
};

}  // namespace

std::unique_ptr<Pass> CreateRegionsPass() { return std::make_unique<Regions>(); }

}  // namespace smtcal
