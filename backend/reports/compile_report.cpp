// Reports of a compiled program (backend/reports/compile_report.h).
#include "backend/reports/compile_report.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "backend/reports/capability_report.h"
#include "backend/reports/table_report.h"
#include "calibration/error_table.h"

namespace smtcal {

namespace {

using nlohmann::json;

// Decimals of the JSON report's numbers (docs/compile.md, "The report").
// Poses (targets, taught points, fixtures) as the corrected program writes
// its coordinates (1e-10 mm and degrees, RoundForProgramText), so a
// report's nominal reads exactly as the program's; residuals to
// kInversePolishMm; times to a microsecond.
constexpr int kPoseDecimals = 10;
constexpr int kResidualDecimals = 12;
constexpr int kSecondsDecimals = 6;
constexpr int kShareDecimals = 6;

json PoseJson(const Pose4& pose) {
  return json{{"x_mm", RoundedJson(pose[0], kPoseDecimals)},
              {"y_mm", RoundedJson(pose[1], kPoseDecimals)},
              {"z_mm", RoundedJson(pose[2], kPoseDecimals)},
              {"u_deg", RoundedJson(pose[3], kPoseDecimals)}};
}

json FixJson(const Eigen::Affine3d& fix) {
  std::array<double, 4> pose = PoseValues(fix);
  return json{{"x_mm", RoundedJson(pose[0], kPoseDecimals)},
              {"y_mm", RoundedJson(pose[1], kPoseDecimals)},
              {"angle_deg", RoundedJson(pose[3], kPoseDecimals)}};
}

std::string FixtureName(const CompileState& state, int fixture) {
  return fixture < 0 ? std::string("base") : state.fixtures[fixture].name;
}

}  // namespace

std::vector<std::pair<std::string, Capability>> PredictedCapability(const CompileState& state) {
  std::map<std::string, ModelCapability> by_region;
  ModelCapability overall;
  std::vector<std::string> order;
  for (const Target& target : state.targets) {
    if (!target.is_placement() || !target.known || target.region == nullptr || !target.budget_bounded) continue;
    if (target.kind == CorrectionKind::kUncorrected) continue;
    const ErrorShare total = state.BudgetOf(target).Total();
    const double tolerance = target.region->tolerance_mm;
    if (!by_region.contains(target.region->name)) order.push_back(target.region->name);
    by_region[target.region->name].Add(total.mean_mm, total.bound_mm, total.covariance_mm2, tolerance);
    overall.Add(total.mean_mm, total.bound_mm, total.covariance_mm2, tolerance);
  }
  std::vector<std::pair<std::string, Capability>> result;
  for (const std::string& name : order) result.emplace_back(name, by_region.at(name).Result());
  if (!order.empty()) result.emplace_back("overall", overall.Result());
  return result;
}

std::string LocationText(const SourceManager& sources, SourceLoc loc) {
  if (!loc.known()) return "<unknown>";
  return fmt::format("{}:{}:{}", sources.File(loc.file).name, loc.line, loc.column);
}

json CompileReportJson(const ir::Program& program, const CompileState& state, const SourceManager& sources,
                       ReportCounts counts) {
  json targets = json::array();
  for (const Target& target : state.targets) {
    json entry{{"statement", TargetKeyword(*target.stmt)},
               {"target", target.text},
               {"location", LocationText(sources, target.stmt->loc)},
               {"reached_from", target.call_path.str()},
               {"frame", FixtureName(state, target.fixture)},
               {"correction", CorrectionKindName(target.kind)},
               {"known_at_compile_time", target.known}};
    if (!target.known) {
      entry["depends_on"] = target.unknown_because.str();
      targets.push_back(std::move(entry));
      continue;
    }
    if (target.fixture >= 0) entry["in_fixture"] = PoseJson(target.in_frame);
    entry["required"] = PoseJson(target.required);
    entry["nominal"] = PoseJson(target.nominal);
    entry["region"] = target.region != nullptr ? json(target.region->name) : json(nullptr);
    entry["residual_mm"] = RoundedJson(target.residual_mm, kResidualDecimals);
    entry["iterations"] = target.iterations;
    entry["iteration_bound"] = target.iteration_bound;
    if (target.kind != CorrectionKind::kUncorrected) {
      const ErrorBudget budget = state.BudgetOf(target);
      json parts = json::object();
      for (std::size_t k = 0; k < kErrorSources; ++k) {
        parts[std::string(ErrorSourceName(static_cast<ErrorSource>(k)))] = RoundedJson(budget.shares[k].BudgetMm(), 6);
      }
      entry["budget_mm"] = RoundedJson(target.budget_mm, 6);
      entry["budget_bounded"] = target.budget_bounded;
      entry["budget_parts_mm"] = std::move(parts);
      entry["worst_case_mm"] = RoundedJson(target.worst_case_mm, 6);
    }
    if (target.region != nullptr) entry["tolerance_mm"] = target.region->tolerance_mm;
    targets.push_back(std::move(entry));
  }
  json fixtures = json::array();
  for (const FixtureBinding& binding : state.fixtures) {
    json entry{{"name", binding.name}, {"nominal", FixJson(binding.nominal)}};
    if (binding.fix0) entry["fix0"] = FixJson(*binding.fix0);
    fixtures.push_back(std::move(entry));
  }
  json taught = json::array();
  for (const TaughtPoint& point : state.taught) {
    const auto& decl = std::get<ir::PointDecl>(point.decl->node);
    taught.push_back(json{{"name", decl.name},
                          {"location", LocationText(sources, point.decl->loc)},
                          {"taught", PoseJson(point.taught)},
                          {"reached", PoseJson(point.reached)},
                          {"fixpos0", PoseJson(point.fixpos0)},
                          {"region", point.region != nullptr ? json(point.region->name) : json(nullptr)}});
  }
  json cycles = json::array();
  for (const CycleEstimate& cycle : state.cycles) {
    double total = cycle.total_s();
    cycles.push_back(json{{"fixture", cycle.fixture},
                          {"location", LocationText(sources, cycle.cycle->loc)},
                          {"placements", cycle.placements},
                          {"motion_s", RoundedJson(cycle.motion_s, kSecondsDecimals)},
                          {"scan_s", RoundedJson(cycle.scan_s, kSecondsDecimals)},
                          {"first_scan_s", RoundedJson(cycle.first_scan_s, kSecondsDecimals)},
                          {"scan_floor_s", RoundedJson(cycle.scan_floor_s, kSecondsDecimals)},
                          {"scan_floor_ratio",
                           RoundedJson(cycle.scan_floor_s > 0 ? cycle.scan_s / cycle.scan_floor_s : 0.0, 2)},
                          {"total_s", RoundedJson(total, kSecondsDecimals)},
                          {"scan_share", RoundedJson(total > 0 ? cycle.scan_s / total : 0.0, kShareDecimals)}});
  }
  json process = json::object();
  for (const auto& [name, capability] : PredictedCapability(state)) process[name] = CapabilityJson(capability);
  // What every region's table leaves open between its nodes: the budgets'
  // `interpolation` part comes from these.
  json regions = json::array();
  for (const cell::Region& region : state.cell->regions) {
    regions.push_back(json{{"name", region.name},
                           {"table", region.table_path},
                           {"interpolation", InterpolationJson(region.interpolation, region.tolerance_mm)}});
  }
  return json{{"program", sources.File(program.file).name},
              {"cell", state.cell->path},
              {"errors", counts.errors},
              {"warnings", counts.warnings},
              {"complete", state.trace_complete},
              {"fixtures", fixtures},
              {"taught_points", taught},
              {"targets", targets},
              {"cycles", cycles},
              {"regions", regions},
              {"process", process}};
}

std::string VerifySummaryText(const ir::Program& program, const CompileState& state, const SourceManager& sources,
                              ReportCounts counts) {
  std::map<CorrectionKind, int> by_kind;
  int placements = 0, unknown = 0;
  const Target* worst_residual = nullptr;
  const Target* worst_budget = nullptr;
  for (const Target& target : state.targets) {
    ++by_kind[target.kind];
    if (target.is_placement()) ++placements;
    if (!target.known) {
      ++unknown;
      continue;
    }
    if (target.kind == CorrectionKind::kUncorrected || target.region == nullptr) continue;
    if (worst_residual == nullptr || target.residual_mm > worst_residual->residual_mm) worst_residual = &target;
    bool pick_place = std::holds_alternative<ir::PickPlace>(target.stmt->node);
    if (pick_place && (worst_budget == nullptr ||
                       target.budget_mm / target.region->tolerance_mm >
                           worst_budget->budget_mm / worst_budget->region->tolerance_mm)) {
      worst_budget = &target;
    }
  }
  auto describe = [&](const Target& target) {
    return fmt::format("{} {} at {}", TargetKeyword(*target.stmt), target.text, LocationText(sources, target.stmt->loc));
  };
  std::string text = fmt::format("{}: compiled for cell '{}' ({})\n", sources.File(program.file).name,
                                 state.cell->name, state.cell->path);
  text += fmt::format("  targets: {} ({} static, {} fixture, {} run-time, {} uncorrected), {} placement targets\n",
                      state.targets.size(), by_kind[CorrectionKind::kStatic], by_kind[CorrectionKind::kFixture],
                      by_kind[CorrectionKind::kRunTimeBase], by_kind[CorrectionKind::kUncorrected], placements);
  if (unknown > 0) text += fmt::format("  {} target(s) known only at run time: not verified\n", unknown);
  if (worst_residual != nullptr) {
    text += fmt::format("  worst residual: {:.1e} mm, {}\n", worst_residual->residual_mm, describe(*worst_residual));
  }
  if (worst_budget != nullptr && worst_budget->budget_bounded) {
    const ErrorBudget budget = state.BudgetOf(*worst_budget);
    text += fmt::format("  worst budget: {:.4f} mm at 4σ of ±{} mm (worst case {:.4f} mm), {}\n",
                        worst_budget->budget_mm, FormatMm(worst_budget->region->tolerance_mm),
                        worst_budget->worst_case_mm, describe(*worst_budget));
    std::string parts;
    for (std::size_t k = 0; k < kErrorSources; ++k) {
      if (budget.shares[k].BudgetMm() == 0) continue;
      parts += fmt::format("{}{} {:.4f}", parts.empty() ? "" : ", ", ErrorSourceName(static_cast<ErrorSource>(k)),
                           budget.shares[k].BudgetMm());
    }
    text += fmt::format("    its parts, each alone at 4σ (mm): {}\n", parts);
  }
  std::string interpolation;
  for (const cell::Region& region : state.cell->regions) {
    interpolation += fmt::format("{}{} {:.4f} ({})", interpolation.empty() ? "" : ", ", region.name,
                                 region.interpolation.NormMm(), InterpolationKindShortName(region.interpolation.Kind()));
  }
  if (!interpolation.empty()) {
    text += fmt::format("  interpolation between the table nodes (mm, budget part `interpolation`): {}\n", interpolation);
  }
  // Backlash has no part in the budget (docs/measure.md, "Backlash"): say so
  // where it can move a placement, on fixture targets through the scan.
  if (state.cell->robot.final_approach_mm && by_kind[CorrectionKind::kFixture] > 0) {
    const Eigen::Vector2d& approach = *state.cell->robot.final_approach_mm;
    text += fmt::format(
        "  not in the budget: backlash. Targets reached by the final approach ({}, {}) mm carry the backlash their "
        "tables measured; a scan trip whose leg runs against that approach may be off by up to an axis's backlash "
        "across its edge, which moves every placement on the board (docs/measure.md, \"Backlash\")\n",
        FormatMm(approach.x()), FormatMm(approach.y()));
  }
  const auto process = PredictedCapability(state);
  if (!process.empty()) {
    text += "  process, from the budget's model (normal assumption):\n";
    for (const auto& [name, capability] : process) text += "    " + CapabilityLine(name, capability) + "\n";
  }
  for (const CycleEstimate& cycle : state.cycles) {
    double total = cycle.total_s();
    text += fmt::format("  cycle {} at {}: {} placements, about {:.1f} s, of which the scan {:.1f} s ({:.1f} %)",
                        cycle.fixture, LocationText(sources, cycle.cycle->loc), cycle.placements, total, cycle.scan_s,
                        total > 0 ? 100.0 * cycle.scan_s / total : 0.0);
    if (cycle.scan_floor_s > 0) {
      text += cycle.first_scan_s > cycle.scan_s
                  ? fmt::format(" predicted from the last scan (the first cycle's, searched in full, {:.1f} s)",
                                cycle.first_scan_s)
                  : std::string();
      text += fmt::format("; the scan's floor {:.1f} s, {:.2f} x it (docs/periphery.md)", cycle.scan_floor_s,
                          cycle.scan_s / cycle.scan_floor_s);
    }
    text += "\n";
  }
  if (!state.trace_complete) text += "  the compile-time run stopped early: later targets were not verified\n";
  text += counts.errors == 0
              ? fmt::format("  verdict: ok{}\n", counts.warnings > 0 ? fmt::format(" ({} warning(s) above)", counts.warnings) : "")
              : fmt::format("  verdict: {} problem(s), {}; do not deploy\n", counts.errors,
                            counts.errors_cut ? "the first of them listed above" : "listed above");
  return text;
}

}  // namespace smtcal
