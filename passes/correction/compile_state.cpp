// Helpers of the compile state (passes/correction/compile_state.h).
#include "passes/correction/compile_state.h"

#include <algorithm>
#include <cmath>

#include "ir/symbols.h"

namespace smtcal {

std::string_view CorrectionKindName(CorrectionKind kind) {
  switch (kind) {
    case CorrectionKind::kStatic: return "static";
    case CorrectionKind::kRunTimeBase: return "run-time";
    case CorrectionKind::kFixture: return "fixture";
    case CorrectionKind::kUncorrected: return "uncorrected";
  }
  return "?";
}

std::unordered_map<const ir::Stmt*, bool> BaseStatementsCommandedAsWritten(const std::vector<Target>& targets) {
  std::unordered_map<const ir::Stmt*, bool> as_written;
  as_written.reserve(static_cast<std::size_t>(
      std::count_if(targets.begin(), targets.end(), [](const Target& t) { return t.fixture < 0; })));
  for (const Target& target : targets) {
    if (target.fixture >= 0) continue;
    // The first position counts when it is known; a second one never does.
    auto [it, first] = as_written.emplace(target.stmt, target.known);
    if (!first) it->second = false;
  }
  return as_written;
}

FixtureBinding NominalBinding(const ir::Stmt& stmt, const ir::FixtureDecl& decl, const cell::Fixture& fixture) {
  FixtureBinding binding;
  binding.name = decl.name;
  binding.decl = &stmt;
  binding.cell_fixture = &fixture;
  binding.nominal = PoseMatrix(fixture.origin_mm.x(), fixture.origin_mm.y(), 0, fixture.angle_deg);
  return binding;
}

bool Target::is_placement() const {
  const auto* pick = std::get_if<ir::PickPlace>(&stmt->node);
  return pick != nullptr && pick->kind == ir::PickPlaceKind::Place;
}

const std::string& SharedText::Empty() {
  static const std::string empty;
  return empty;
}

SharedText CompileState::Share(std::string_view text) {
  if (text.empty()) return SharedText();
  auto it = shared_by_text_.find(text);
  if (it != shared_by_text_.end()) return SharedText(it->second);
  const std::string& kept = shared_.emplace_back(text);
  shared_by_text_.emplace(kept, &kept);
  return SharedText(&kept);
}

int CompileState::FindFixture(std::string_view name) const {
  if (name.empty()) return -1;
  for (std::size_t i = 0; i < fixtures.size(); ++i) {
    if (sema::SameName(fixtures[i].name, name)) return static_cast<int>(i);
  }
  return -1;
}

const InverseSolver& CompileState::SolverFor(const cell::Region& region) {
  std::unique_ptr<InverseSolver>& solver = solvers_[&region];
  if (!solver) solver = std::make_unique<InverseSolver>(region.table);
  return *solver;
}

Pose4 PoseToBase(const Eigen::Affine3d& fix, const Pose4& in_fixture) {
  Eigen::Vector3d p = fix * Eigen::Vector3d(in_fixture[0], in_fixture[1], in_fixture[2]);
  return {p.x(), p.y(), p.z(), in_fixture[3] + PoseValues(fix)[3]};
}

Pose4 PoseToFixture(const Eigen::Affine3d& fix, const Pose4& in_base) {
  Eigen::Vector3d p = fix.inverse() * Eigen::Vector3d(in_base[0], in_base[1], in_base[2]);
  return {p.x(), p.y(), p.z(), in_base[3] - PoseValues(fix)[3]};
}

TeachPose EstimateTeachPose(const cell::Fixture& fixture, const cell::Cell& cell) {
  ScanResult scan = TeachScan(cell, fixture);
  if (scan.fix) return {*scan.fix, ""};
  return {std::nullopt, DescribeFailure(scan, fixture)};
}

const FixtureErrorModel& CompileState::ErrorModelFor(const cell::Fixture& fixture) const {
  std::unique_ptr<FixtureErrorModel>& model = error_models_[&fixture];
  if (!model) model = std::make_unique<FixtureErrorModel>(*cell, fixture, RegionTableNoiseOnce());
  return *model;
}

const std::vector<Eigen::Vector2d>& CompileState::RegionTableNoiseOnce() const {
  if (region_table_se_.empty()) region_table_se_ = RegionTableNoise(*cell);
  return region_table_se_;
}

ErrorBudget CompileState::BudgetOf(const Target& target) const {
  if (target.kind == CorrectionKind::kFixture) {
    return ErrorModelFor(*fixtures[target.fixture].cell_fixture).At(Xy(target.in_frame), target.region,
                                                                     target.residual_mm);
  }
  if (target.region == nullptr) return StaticBudget(*cell, nullptr, target.residual_mm);
  return StaticBudget(*cell, target.region, target.residual_mm,
                      RegionTableNoiseOnce()[static_cast<std::size_t>(target.region - cell->regions.data())]);
}

std::string_view TargetKeyword(const ir::Stmt& stmt) {
  if (const auto* pick = std::get_if<ir::PickPlace>(&stmt.node)) {
    return pick->kind == ir::PickPlaceKind::Pick ? "Pick" : "Place";
  }
  switch (std::get<ir::Motion>(stmt.node).kind) {
    case ir::MotionKind::Jump: return "Jump";
    case ir::MotionKind::Go: return "Go";
    case ir::MotionKind::Move: return "Move";
  }
  return "?";
}

double RoundForProgramText(double value) { return std::round(value * 1e10) / 1e10; }

}  // namespace smtcal

