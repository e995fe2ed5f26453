// Reports of `smtcal simulate` (backend/reports/simulate_report.h).
#include "backend/reports/simulate_report.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "backend/reports/capability_report.h"
#include "backend/reports/svg_text.h"
#include "base/field_text.h"

namespace smtcal {
namespace {

struct Summary {
  double mean = 0, p50 = 0, p95 = 0, p99 = 0, max = 0;
};

Summary Summarize(const std::vector<double>& errors_um) {
  Summary s;
  if (errors_um.empty()) return s;
  std::vector<double> sorted = errors_um;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0;
  for (double e : sorted) sum += e;
  s.mean = sum / static_cast<double>(sorted.size());
  s.p50 = Percentile(sorted, 0.50);
  s.p95 = Percentile(sorted, 0.95);
  s.p99 = Percentile(sorted, 0.99);
  s.max = sorted.back();
  return s;
}

double WithinFraction(const ModeResult& m) {
  return m.placements > 0 ? static_cast<double>(m.within) / static_cast<double>(m.placements) : 0.0;
}

// Rounded for the JSON report: a thousandth of a micrometre, a millionth of a fraction.
// A figure rounded to its meaning: `unit` is a power of ten (1e-3, 1e-6).
double Round(double value, double unit) {
  return RoundedToDecimals(value, static_cast<int>(std::lround(-std::log10(unit))));
}

std::string_view ShiftName(ShiftDistribution shift) {
  switch (shift) {
    case ShiftDistribution::kExponential: return "exponential";
    case ShiftDistribution::kNormal: return "normal";
    case ShiftDistribution::kUniform: return "uniform";
    case ShiftDistribution::kFixed: return "fixed";
  }
  return "?";
}

std::string_view TablesName(TruthTables tables) {
  switch (tables) {
    case TruthTables::kDerived: return "derived";
    case TruthTables::kCell: return "cell";
    case TruthTables::kNone: return "none";
  }
  return "?";
}

double SensorAccuracy(const TruthSpec& truth, const cell::Cell& cell) {
  if (!truth.noise) return 0;
  if (truth.sensor_accuracy_mm) return *truth.sensor_accuracy_mm;
  return cell.fixtures.empty() ? 0.0 : cell.fixtures.front().sensor_accuracy_mm;
}

double Repeatability(const TruthSpec& truth, const cell::Cell& cell) {
  return truth.noise ? truth.repeatability_mm.value_or(cell.robot.repeatability_mm) : 0.0;
}

std::string BoardText(const BoardPoseModel& board) {
  if (board.shift == ShiftDistribution::kFixed) {
    return fmt::format("board fixed: shift ({}, {}) mm, rotation {}°", board.fixed_shift_mm.x(),
                       board.fixed_shift_mm.y(), board.fixed_rotation_deg);
  }
  std::string_view scale = board.shift == ShiftDistribution::kExponential ? "mean"
                           : board.shift == ShiftDistribution::kNormal    ? "sd per axis"
                                                                          : "radius";
  return fmt::format("board shift {} ({} {} mm, max {} mm), rotation normal (sd {}°, max {}°)", ShiftName(board.shift),
                     scale, board.shift_scale_mm, board.shift_max_mm, board.rotation_sd_deg, board.rotation_max_deg);
}

// One colour per mode, in SimMode order, whichever modes a run has.
constexpr std::array<const char*, 6> kModeColours = {"#7f7f7f", "#bcbd22", "#1f77b4",
                                                     "#9467bd", "#ff7f0e", "#2ca02c"};
const char* ModeColour(SimMode mode) { return kModeColours[static_cast<std::size_t>(mode) % kModeColours.size()]; }

nlohmann::json ProcessJson(const ModeResult& m, const SimResult& result) {
  if (m.placements == 0) return nullptr;
  nlohmann::json regions = nlohmann::json::object();
  for (std::size_t r = 0; r < m.by_region.size(); ++r) {
    const Capability c = m.by_region[r].Result();
    if (c.placements > 0) regions[result.regions[r]] = CapabilityJson(c);
  }
  return {{"overall", CapabilityJson(m.overall.Result())}, {"regions", regions}};
}

// The drifts of the run, per cycle from start_cycle on: "" without any.
std::string DriftText(const DriftModel& drift) {
  if (!drift.any()) return "";
  std::vector<std::string> parts;
  if (!drift.board_mm_per_cycle.isZero()) {
    parts.push_back(fmt::format("board ({}, {}) mm", drift.board_mm_per_cycle.x(), drift.board_mm_per_cycle.y()));
  }
  if (drift.board_deg_per_cycle != 0) parts.push_back(fmt::format("board {}°", drift.board_deg_per_cycle));
  if (drift.robot_scale_ppm_per_cycle != 0) {
    parts.push_back(fmt::format("robot scale {} ppm about ({}, {})", drift.robot_scale_ppm_per_cycle,
                                drift.robot_scale_about_mm.x(), drift.robot_scale_about_mm.y()));
  }
  if (drift.sensor_threshold_mm_per_cycle != 0) {
    parts.push_back(fmt::format("sensor threshold {} mm", drift.sensor_threshold_mm_per_cycle));
  }
  if (drift.sensor_accuracy_mm_per_cycle != 0) {
    parts.push_back(fmt::format("sensor accuracy +{} mm", drift.sensor_accuracy_mm_per_cycle));
  }
  std::string list;
  for (std::size_t i = 0; i < parts.size(); ++i) list += (i == 0 ? "" : ", ") + parts[i];
  return fmt::format("; drifting per cycle after cycle {}: {}", drift.start_cycle, list);
}

}  // namespace

std::string DescribeTruth(const TruthSpec& truth, const cell::Cell& cell) {
  std::string field = fmt::format("tables {}", TablesName(truth.tables));
  if (truth.tables == TruthTables::kDerived) {
    field += truth.noise ? fmt::format(" (nodes moved by {} x their standard error", truth.perturbation_scale)
                         : " (noise off: the nodes as they are";
    field += fmt::format(", between them departing by {} x the interpolation estimate)", truth.interpolation_scale);
  }
  if (!truth.region_tables.empty()) field += fmt::format(", {} true table(s) given", truth.region_tables.size());
  switch (truth.outside) {
    case TruthOutside::kField: {
      const std::optional<double> declared =
          truth.uncalibrated_accuracy_mm ? truth.uncalibrated_accuracy_mm : cell.robot.uncalibrated_accuracy_mm;
      field += fmt::format(
          ", outside a smooth random field up to {} mm{} (correlation {} mm)", declared.value_or(kAssumedUncalibratedAccuracyMm),
          declared ? "" : " (ASSUMED: the cell does not declare robot.uncalibrated_accuracy_mm)",
          truth.uncalibrated_correlation_mm.value_or(cell.robot.uncalibrated_correlation_mm));
      break;
    }
    case TruthOutside::kFade: field += fmt::format(", outside fading to 0 over {} mm", truth.fade_mm); break;
    case TruthOutside::kClamp: field += ", outside clamped to the edge values"; break;
  }
  if (truth.offset_mm != Eigen::Vector2d::Zero()) {
    field += fmt::format(", offset ({}, {}) mm", truth.offset_mm.x(), truth.offset_mm.y());
  }
  if (truth.rotation_deg != 0 || truth.scale_ppm != 0) {
    field += fmt::format(", rotation {}° and scale {} ppm about ({}, {})", truth.rotation_deg, truth.scale_ppm,
                         truth.about_mm.x(), truth.about_mm.y());
  }
  const double servo_period_s = truth.noise ? truth.servo_period_s.value_or(cell.robot.servo_period_s) : 0.0;
  return fmt::format("{}; {}; sensor ±{} mm, repeatability ±{} mm (uniform), trips latched up to {} s late{}{}", field,
                     BoardText(truth.board), SensorAccuracy(truth, cell), Repeatability(truth, cell), servo_period_s,
                     truth.noise ? "" : ", noise off", DriftText(truth.drift));
}

std::string SimulateReportText(const SimResult& result, const SimulateContext& context) {
  std::string out;
  const SimOptions& o = result.options;
  out += fmt::format("smtcal simulate: {} on cell '{}', {} cycles (seed {}), {} placements planned\n",
                     context.program, context.cell->name, result.cycles, o.seed, result.placements_planned);
  out += fmt::format("truth: {}{}\n", context.truth->path.empty() ? "" : context.truth->path + ": ",
                     DescribeTruth(*context.truth, *context.cell));
  if (o.missed_trip_rate > 0 || o.dirty_marker_rate > 0 || o.board_beyond_rate > 0) {
    out += fmt::format("faults injected: missed trip {} cycles, dirty marker {} (±{} mm), board beyond limits {}\n",
                       result.injected_missed, result.injected_dirty, o.dirty_marker_mm, result.injected_beyond);
  }
  if (result.unknown_targets > 0) {
    out += fmt::format("not simulated: {} placement(s) known only at run time\n", result.unknown_targets);
  }
  if (context.verify_findings > 0) {
    out += fmt::format("smtcal verify refuses this program: {} finding(s) on its tolerance budget (run smtcal verify "
                       "for them); simulated anyway\n",
                       context.verify_findings);
  }
  out += fmt::format("\n{:<12} {:>9} {:>10} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>6}\n", "mode", "placed",
                     "within", "out", "faults", "mean", "p50", "p95", "p99", "max", "scan");
  out += fmt::format("{:<12} {:>9} {:>10} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>6}\n", "", "", "tolerance",
                     "", "cycles", "µm", "µm", "µm", "µm", "µm", "share");
  for (const ModeResult& m : result.modes) {
    const Summary s = Summarize(m.errors_um);
    if (m.placements == 0) {  // every cycle stopped: no distribution to show
      out += fmt::format("{:<12} {:>9} {:>10} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>5.1f}%\n",
                         SimModeName(m.mode), 0, "-", 0, m.faults, "-", "-", "-", "-", "-", 100 * m.scan_share);
      continue;
    }
    out += fmt::format("{:<12} {:>9} {:>9.3f}% {:>7} {:>7} {:>7.1f} {:>7.1f} {:>7.1f} {:>7.1f} {:>7.1f} {:>5.1f}%\n",
                       SimModeName(m.mode), m.placements, 100 * WithinFraction(m), m.placements - m.within, m.faults,
                       s.mean, s.p50, s.p95, s.p99, s.max, 100 * m.scan_share);
  }
  bool any_faults = false;
  for (const ModeResult& m : result.modes) any_faults = any_faults || m.faults > 0;
  if (any_faults) {
    out += "\nfaults (the first failed check of each stopped cycle):\n";
    for (const ModeResult& m : result.modes) {
      if (m.faults == 0) continue;
      std::string list;
      for (const auto& [check, count] : m.fault_checks) list += fmt::format("{}{} {}", list.empty() ? "" : ", ", check, count);
      out += fmt::format("  {:<12} {}\n", SimModeName(m.mode), list);
    }
  }
  std::string unchecked;
  for (const ModeResult& m : result.modes) {
    if (!UsesPeriphery(m.mode) || UsesCellChecks(m.mode)) continue;
    std::string list;
    for (const auto& [check, count] : m.would_stop_checks) {
      list += fmt::format("{}{} {}", list.empty() ? "" : ", ", check, count);
    }
    unchecked += fmt::format("  {:<12} {} of {} cycles{}\n", SimModeName(m.mode), m.would_stop, m.cycles,
                             list.empty() ? "" : " (" + list + ")");
  }
  if (!unchecked.empty()) {
    out += "\nperiphery and paper run as the paper's cell did, without scan checks: only a missing trip or trips "
           "that define no pose stop their cycles.\nThe cell's checks (the first that fails) would have stopped:\n" +
           unchecked;
  }
  if (o.missed_trip_rate > 0 || o.dirty_marker_rate > 0 || o.board_beyond_rate > 0) {
    out += fmt::format("\ncycles with an injected fault: {}; per mode, how many of them stopped and how many parts "
                       "they placed out of tolerance:\n", result.injected_cycles);
    for (const ModeResult& m : result.modes) {
      out += fmt::format("  {:<12} stopped {:>6}   misplaced {:>6}\n", SimModeName(m.mode), m.faults_injected,
                         m.misplaced_injected);
    }
  }
  out += fmt::format("\nprocess figures (per axis; a normal fitted to the placed parts' errors; Cmk at each "
                     "part's tolerance; the placement industry's reference: ±{} µm at 4σ, Cmk ≥ {}):\n",
                     kReferenceToleranceMm * 1000, kReferenceCmk);
  for (const ModeResult& m : result.modes) {
    if (m.placements == 0) {
      out += fmt::format("  {:<12} nothing placed\n", SimModeName(m.mode));
      continue;
    }
    out += fmt::format("  {:<12} {}\n", SimModeName(m.mode), CapabilityLine("all", m.overall.Result()));
  }
  for (const ModeResult& m : result.modes) {
    if (m.mode != SimMode::kImproved || m.placements == 0) continue;
    out += "  improved, per region:\n";
    for (std::size_t r = 0; r < m.by_region.size(); ++r) {
      const Capability c = m.by_region[r].Result();
      if (c.placements > 0) out += "    " + CapabilityLine(result.regions[r], c) + "\n";
    }
  }
  out += "\nmodes:\n";
  for (const ModeResult& m : result.modes) {
    std::string description(SimModeDescription(m.mode));
    if (m.mode == SimMode::kImproved) description += fmt::format(" (estimator {})", result.fixture_estimator);
    if (UsesPeriphery(m.mode) && !UsesCellChecks(m.mode) && !result.paper_estimator.empty()) {
      description += fmt::format(" (estimator {})", result.paper_estimator);
    }
    out += fmt::format("  {:<12} {}\n", SimModeName(m.mode), description);
  }
  return out;
}

nlohmann::json SimulateReportJson(const SimResult& result, const SimulateContext& context) {
  const SimOptions& o = result.options;
  nlohmann::json modes = nlohmann::json::array();
  for (const ModeResult& m : result.modes) {
    const Summary s = Summarize(m.errors_um);
    nlohmann::json checks = nlohmann::json::object();
    for (const auto& [check, count] : m.fault_checks) checks[check] = count;
    nlohmann::json would_stop = nlohmann::json::object();
    for (const auto& [check, count] : m.would_stop_checks) would_stop[check] = count;
    const nlohmann::json scan_checks = !UsesPeriphery(m.mode) ? nlohmann::json(nullptr)
                                       : UsesCellChecks(m.mode) ? nlohmann::json("cell")
                                                                : nlohmann::json("pose-only");
    modes.push_back({{"mode", SimModeName(m.mode)},
                     {"description", SimModeDescription(m.mode)},
                     {"cycles", m.cycles},
                     {"faults", m.faults},
                     {"fault_checks", checks},
                     {"scan_checks", scan_checks},
                     {"would_stop", m.would_stop},
                     {"would_stop_checks", would_stop},
                     {"placed", m.placements},
                     {"within_tolerance", m.within},
                     {"within_fraction", m.placements == 0 ? nlohmann::json(nullptr)
                                                           : nlohmann::json(Round(WithinFraction(m), 1e-6))},
                     {"out_of_tolerance", m.placements - m.within},
                     {"injected_cycles_stopped", m.faults_injected},
                     {"misplaced_in_injected_cycles", m.misplaced_injected},
                     {"error_um", m.placements == 0 ? nlohmann::json(nullptr)
                                                    : nlohmann::json{{"mean", Round(s.mean, 1e-3)},
                                                                     {"p50", Round(s.p50, 1e-3)},
                                                                     {"p95", Round(s.p95, 1e-3)},
                                                                     {"p99", Round(s.p99, 1e-3)},
                                                                     {"max", Round(s.max, 1e-3)}}},
                     {"scan_share", Round(m.scan_share, 1e-6)},
                     {"process", ProcessJson(m, result)}});
  }
  return {{"program", context.program},
          {"cell", context.cell->name},
          {"truth_file", context.truth->path},
          {"truth", DescribeTruth(*context.truth, *context.cell)},
          {"seed", o.seed},
          {"cycles", result.cycles},
          {"cycles_per_statement", o.cycles},
          {"placements_planned", result.placements_planned},
          {"placements_not_simulated", result.unknown_targets},
          {"improved_estimator", result.fixture_estimator},
          {"paper_estimator", result.paper_estimator.empty() ? nlohmann::json(nullptr)
                                                             : nlohmann::json(result.paper_estimator)},
          {"verify_budget_findings", context.verify_findings},
          {"uncalibrated_accuracy_mm", result.uncalibrated_accuracy_mm},
          {"uncalibrated_accuracy_assumed", result.accuracy_assumed},
          {"injected",
           {{"missed_trip", {{"rate", o.missed_trip_rate}, {"cycles", result.injected_missed}}},
            {"dirty_marker",
             {{"rate", o.dirty_marker_rate}, {"cycles", result.injected_dirty}, {"displacement_mm", o.dirty_marker_mm}}},
            {"board_beyond_limits", {{"rate", o.board_beyond_rate}, {"cycles", result.injected_beyond}}},
            {"cycles_with_any", result.injected_cycles}}},
          {"modes", modes}};
}

namespace {

// The note drawn in the panel of a mode that placed nothing: why, with the
// checks that stopped its cycles (the first failed check of each).
std::vector<std::string> NothingPlacedNote(const ModeResult& m) {
  std::vector<std::string> lines;
  if (m.faults == 0) {
    lines.push_back("no placements: the cycles place no part");
    return lines;
  }
  lines.push_back(m.faults == m.cycles ? "no placements: every cycle stopped by"
                                       : fmt::format("no placements: {} of {} cycles stopped by", m.faults, m.cycles));
  for (const auto& [check, count] : m.fault_checks) {
    lines.push_back(fmt::format("{} ({} cycle{})", check, count, count == 1 ? "" : "s"));
  }
  return lines;
}

}  // namespace

std::string SimulateReportSvg(const SimResult& result, const SimulateContext& context) {
  // Panels kPanel square, kLeft and kGap leave room for the y ticks and label,
  // kRowGap for the x ticks and label and the next row's titles.
  constexpr double kPanel = 280, kGap = 90, kRowGap = 90, kLeft = 80, kTop = 115;
  constexpr int kColumns = 3;
  const double tolerance_um = 1000 * (result.tolerance_mm > 0 ? result.tolerance_mm : 0.1);
  const double range_um = 2.5 * tolerance_um;  // scatter: +-range around the required position
  const double scatter_step_um = SvgTickStep(2 * range_um, 5);
  const std::vector<double> scatter_ticks = SvgTicks(-range_um, range_um, scatter_step_um);
  const int rows = static_cast<int>((result.modes.size() + kColumns - 1) / kColumns);
  const double width = kLeft + kColumns * (kPanel + kGap);
  const double hist_top = kTop + rows * (kPanel + kRowGap) + 30, hist_height = 260;
  const std::vector<std::string> truth_lines = [&] {
    std::vector<std::string> lines;
    std::string text = "true world: " + DescribeTruth(*context.truth, *context.cell);
    for (std::size_t at = 0; at != std::string::npos;) {
      const std::size_t next = text.find("; ", at);
      std::string line = text.substr(at, next == std::string::npos ? next : next - at);
      // A line wider than the picture breaks after a comma.
      constexpr std::size_t kMaxChars = 150;
      while (line.size() > kMaxChars && line.rfind(", ", kMaxChars) != std::string::npos) {
        const std::size_t comma = line.rfind(", ", kMaxChars);
        lines.push_back(line.substr(0, comma + 1));
        line = line.substr(comma + 2);
      }
      lines.push_back(line);
      at = next == std::string::npos ? next : next + 2;
    }
    return lines;
  }();
  const double height = hist_top + hist_height + 64 + 16 * static_cast<double>(truth_lines.size());
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0f}\" height=\"{:.0f}\" viewBox=\"0 0 {:.0f} {:.0f}\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      width, height, width, height);
  svg += fmt::format("<text x=\"{}\" y=\"24\" font-size=\"16\" font-weight=\"bold\">Placement error per correction "
                     "mode: {} on cell {} ({} cycles, seed {})</text>\n",
                     kLeft, SvgEscape(std::filesystem::path(context.program).filename().string()),
                     SvgEscape(context.cell->name), result.cycles, result.options.seed);
  svg += fmt::format("<text x=\"{}\" y=\"46\">Each dot: one placed part, where it landed relative to where it "
                     "belongs, x and y error in µm (up to {} per mode, the same parts in every mode).</text>\n",
                     kLeft, result.options.scatter_points);
  svg += fmt::format("<text x=\"{}\" y=\"64\">Dashed circle: the tolerance ±{:.0f} µm. Red: beyond ±{:.0f} µm, "
                     "drawn at the border.</text>\n",
                     kLeft, tolerance_um, range_um);
  for (std::size_t i = 0; i < result.modes.size(); ++i) {
    const ModeResult& m = result.modes[i];
    const double x0 = kLeft + static_cast<double>(i % kColumns) * (kPanel + kGap);
    const double y0 = kTop + static_cast<double>(i / kColumns) * (kPanel + kRowGap);
    const double cx = x0 + kPanel / 2, cy = y0 + kPanel / 2, per_um = kPanel / (2 * range_um);
    const Summary s = Summarize(m.errors_um);
    svg += fmt::format("<!-- panel: {} -->\n", SimModeName(m.mode));
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-weight=\"bold\" fill=\"{}\">{}", x0, y0 - 24,
                       ModeColour(m.mode), SimModeName(m.mode));
    if (UsesPeriphery(m.mode) && !UsesCellChecks(m.mode)) {
      // The paper's modes run without the cell's checks: say so, and what they would have stopped.
      svg += fmt::format("<tspan dx=\"8\" font-weight=\"normal\" fill=\"#444\">no scan checks (the cell's would stop {})"
                         "</tspan>", m.would_stop);
    }
    svg += "</text>\n";
    if (m.placements == 0) {
      // Nothing to scatter: no axes, the reason in the panel.
      svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\">nothing placed, {} of {} cycles stopped</text>\n", x0,
                         y0 - 8, m.faults, m.cycles);
      svg += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.0f}\" height=\"{:.0f}\" fill=\"#f4f4f4\" "
                         "stroke=\"#bbb\" stroke-dasharray=\"4,3\"/>\n", x0, y0, kPanel, kPanel);
      const std::vector<std::string> note = NothingPlacedNote(m);
      double y = cy - 9 * static_cast<double>(note.size() - 1);
      for (std::size_t k = 0; k < note.size(); ++k, y += 18) {
        svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\"{}>{}</text>\n", cx, y,
                           k == 0 ? " font-weight=\"bold\"" : "", SvgEscape(note[k]));
      }
      continue;
    }
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\">{:.2f}% within, p99 {:.0f} µm, {} cycles stopped</text>\n",
                       x0, y0 - 8, 100 * WithinFraction(m), s.p99, m.faults);
    svg += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.0f}\" height=\"{:.0f}\" fill=\"#fafafa\" "
                       "stroke=\"#999\"/>\n", x0, y0, kPanel, kPanel);
    // Grid and ticks at round micrometres; the zero lines darker.
    for (double t : scatter_ticks) {
      const double px = cx + t * per_um, py = cy - t * per_um;
      const char* grid = std::fabs(t) < 1e-9 ? "#ccc" : "#eee";
      svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\"/>\n", px, y0,
                         px, y0 + kPanel, grid);
      svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\"/>\n", x0, py,
                         x0 + kPanel, py, grid);
      svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#666\"/>"
                         "<text x=\"{0:.1f}\" y=\"{3:.1f}\" text-anchor=\"middle\" fill=\"#444\">{4}</text>\n",
                         px, y0 + kPanel, y0 + kPanel + 4, y0 + kPanel + 16, SvgTickText(t, scatter_step_um));
      svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{2:.1f}\" x2=\"{1:.1f}\" y2=\"{2:.1f}\" stroke=\"#666\"/>"
                         "<text x=\"{3:.1f}\" y=\"{4:.1f}\" text-anchor=\"end\" fill=\"#444\">{5}</text>\n",
                         x0 - 4, x0, py, x0 - 6, py + 4, SvgTickText(t, scatter_step_um));
    }
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" fill=\"#444\">x error (µm)</text>\n",
                       cx, y0 + kPanel + 32);
    svg += fmt::format("<text x=\"{0:.1f}\" y=\"{1:.1f}\" text-anchor=\"middle\" fill=\"#444\" "
                       "transform=\"rotate(-90 {0:.1f} {1:.1f})\">y error (µm)</text>\n",
                       x0 - 40, cy);
    svg += fmt::format("<g fill=\"{}\" fill-opacity=\"0.35\">\n", ModeColour(m.mode));
    std::string outside;
    for (const Eigen::Vector2d& e : m.scatter_um) {
      const double scale = std::max({std::abs(e.x()), std::abs(e.y()), range_um}) / range_um;
      const Eigen::Vector2d p = e / scale;
      std::string dot = fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"1.6\"/>\n", cx + p.x() * per_um,
                                    cy - p.y() * per_um);
      (scale > 1 ? outside : svg) += dot;
    }
    svg += "</g>\n";
    if (!outside.empty()) svg += "<g fill=\"#d62728\">\n" + outside + "</g>\n";
    svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{:.1f}\" fill=\"none\" stroke=\"black\" "
                       "stroke-dasharray=\"5,4\"/>\n", cx, cy, tolerance_um * per_um);
  }
  // Histograms of the error lengths: the share of each mode's placed parts
  // per bin, in percent; modes that placed nothing have no curve.
  constexpr int kBins = 60;
  const double hist_max_um = 3 * tolerance_um, bin_um = hist_max_um / kBins;
  const double hx0 = kLeft, hw = width - kLeft - kGap - 170;
  std::vector<std::vector<double>> shares;  // percent
  double top_share = 0;
  for (const ModeResult& m : result.modes) {
    std::vector<double> bins(kBins, 0.0);
    for (double e : m.errors_um) bins[std::min(kBins - 1, static_cast<int>(e / bin_um))] += 1;
    for (double& b : bins) b = m.errors_um.empty() ? 0 : 100 * b / static_cast<double>(m.errors_um.size());
    // The scale is the distribution's, not the last bin's: a mode that lands
    // nearly everything beyond would flatten every other curve.
    top_share = std::max(top_share, *std::max_element(bins.begin(), bins.end() - 1));
    shares.push_back(bins);
  }
  if (top_share <= 0) top_share = 1;
  const double share_step = SvgTickStep(top_share, 5);
  const double share_max = std::ceil(top_share / share_step * (1 - 1e-12)) * share_step;
  svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-weight=\"bold\">Error length histogram (share of each mode's "
                     "placed parts per {:g} µm bin; the last bin holds everything beyond)</text>\n",
                     hx0, hist_top - 14, bin_um);
  svg += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"#fafafa\" "
                     "stroke=\"#999\"/>\n", hx0, hist_top, hw, hist_height);
  for (double t : SvgTicks(0, share_max, share_step)) {
    const double y = hist_top + hist_height * (1 - t / share_max);
    if (t > 0) {
      svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#eee\"/>\n", hx0, y,
                         hx0 + hw, y);
    }
    svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#666\"/>"
                       "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\" fill=\"#444\">{}%</text>\n",
                       hx0 - 4, y, hx0, y, hx0 - 6, y + 4, SvgTickText(t, share_step));
  }
  svg += fmt::format("<text x=\"{0:.1f}\" y=\"{1:.1f}\" text-anchor=\"middle\" fill=\"#444\" "
                     "transform=\"rotate(-90 {0:.1f} {1:.1f})\">share of placed parts (%)</text>\n",
                     hx0 - 46, hist_top + hist_height / 2);
  const double tol_x = hx0 + hw * tolerance_um / hist_max_um;
  svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"black\" "
                     "stroke-dasharray=\"5,4\"/>\n<text x=\"{:.1f}\" y=\"{:.1f}\">tolerance</text>\n",
                     tol_x, hist_top, tol_x, hist_top + hist_height, tol_x + 4, hist_top + 14);
  const double length_step = SvgTickStep(hist_max_um, 6);
  for (double um : SvgTicks(0, hist_max_um, length_step)) {
    const double x = hx0 + hw * um / hist_max_um;
    svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#666\"/>"
                       "<text x=\"{0:.1f}\" y=\"{3:.1f}\" text-anchor=\"middle\" fill=\"#444\">{4}</text>\n",
                       x, hist_top + hist_height, hist_top + hist_height + 4, hist_top + hist_height + 16,
                       SvgTickText(um, length_step));
  }
  svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" fill=\"#444\">error length "
                     "(µm)</text>\n", hx0 + hw / 2, hist_top + hist_height + 34);
  if (std::all_of(result.modes.begin(), result.modes.end(), [](const ModeResult& m) { return m.placements == 0; })) {
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-weight=\"bold\">no mode "
                       "placed a part: nothing to count</text>\n", hx0 + hw / 2, hist_top + hist_height / 2);
  }
  for (std::size_t i = 0; i < shares.size(); ++i) {
    const ModeResult& m = result.modes[i];
    const double ly = hist_top + 14 + 20 * static_cast<double>(i);
    if (m.placements == 0) {
      svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" fill=\"#888\">{} (nothing placed)</text>\n", hx0 + hw + 42,
                         ly, SimModeName(m.mode));
      continue;
    }
    std::string points;
    for (int b = 0; b < kBins; ++b) {
      const double y = hist_top + hist_height * (1 - std::min(shares[i][b], share_max) / share_max);
      points += fmt::format("{:.1f},{:.1f} {:.1f},{:.1f} ", hx0 + hw * b / kBins, y, hx0 + hw * (b + 1) / kBins, y);
    }
    svg += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n", points,
                       ModeColour(m.mode));
    svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" "
                       "stroke-width=\"3\"/><text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n",
                       hx0 + hw + 12, ly - 4, hx0 + hw + 36, ly - 4, ModeColour(m.mode), hx0 + hw + 42, ly,
                       SimModeName(m.mode));
  }
  // The last bins beyond the scale, clipped at its top: their shares written out.
  double beyond_y = hist_top + 32;
  for (std::size_t i = 0; i < shares.size(); ++i) {
    if (result.modes[i].placements == 0 || shares[i].back() <= share_max) continue;
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\" fill=\"{}\">{}: {:.1f}% at {:g} µm or "
                       "more (last bin, clipped)</text>\n",
                       hx0 + hw - 8, beyond_y, ModeColour(result.modes[i].mode), SimModeName(result.modes[i].mode),
                       shares[i].back(), hist_max_um - bin_um);
    beyond_y += 16;
  }
  for (std::size_t i = 0; i < truth_lines.size(); ++i) {
    svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" fill=\"#666\">{}</text>\n", kLeft,
                       hist_top + hist_height + 64 + 16 * static_cast<double>(i), SvgEscape(truth_lines[i]));
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace smtcal
