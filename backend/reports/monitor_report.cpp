// Reports of `smtcal monitor` (backend/reports/monitor_report.h).
#include "backend/reports/monitor_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "backend/reports/svg_text.h"
#include "base/field_text.h"

namespace smtcal {
namespace {

using nlohmann::ordered_json;

// Fixed decimals, never "-0.0".
std::string Fixed(double value, int decimals) {
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos && text.front() == '-') text.erase(0, 1);
  return text;
}

std::string Signed(double value, int decimals) {
  const std::string text = Fixed(value, decimals);
  return text.front() == '-' || text.find_first_not_of("0.") == std::string::npos ? text : "+" + text;
}

// Decimals that show a quantity's unit sensibly.
int DecimalsOf(Quantity q) {
  switch (q) {
    case Quantity::kPoseX:
    case Quantity::kPoseY:
    case Quantity::kPoseAngle:
    case Quantity::kMarkerScale:
    case Quantity::kSensorThreshold:
    case Quantity::kResidualRms:
    case Quantity::kResidualMax: return 1;
  }
  return 1;
}

double Rounded(double value, int decimals) { return RoundedToDecimals(value, decimals); }

std::string ChartList(const std::vector<Quantity>& charts) {
  std::string text;
  for (std::size_t i = 0; i < charts.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == charts.size() ? " and " : ", ") + std::string(QuantityTitle(charts[i]));
  }
  return text;
}

// "about 12 scans (3.4 h)".
std::string ScansText(double scans, const std::optional<double>& seconds_per_scan) {
  std::string text = fmt::format("about {} scan{}", Fixed(std::ceil(scans), 0), std::ceil(scans) == 1 ? "" : "s");
  if (seconds_per_scan) {
    const double hours = scans * *seconds_per_scan / 3600;
    text += hours < 1 ? fmt::format(" ({} min)", Fixed(hours * 60, 0)) : fmt::format(" ({} h)", Fixed(hours, 1));
  }
  return text;
}

const SeriesResult& SeriesOf(const FixtureMonitor& f, Quantity q) { return f.series[static_cast<std::size_t>(q)]; }

// The finding in words: what it means, how soon it reaches its limit, what to do.
std::vector<std::string> Explain(const Finding& finding, const FixtureMonitor& f, const cell::Cell& cell,
                                 std::size_t baseline) {
  std::vector<std::string> lines;
  const cell::Fixture& fixture = *f.fixture;
  auto soon = [&](std::string_view what) {
    if (!finding.scans_to_limit) return fmt::format("it does not approach {}", what);
    if (*finding.scans_to_limit <= 0) return fmt::format("it has reached {}", what);
    return fmt::format("at this rate it reaches {} in {}", what, ScansText(*finding.scans_to_limit, f.seconds_per_scan));
  };
  std::string rules;
  for (Quantity q : finding.charts) {
    const SeriesResult& series = SeriesOf(f, q);
    const std::string name(series.chart.alarm ? ChartRuleName(series.chart.alarm_rule) : "?");
    if (rules.find(name) == std::string::npos) rules += (rules.empty() ? "" : ", ") + name;
  }
  const std::string alarm = fmt::format("{} alarmed at scan {} ({}); the drift began about scan {}",
                                        ChartList(finding.charts), finding.alarm_scan, rules, finding.change_scan);
  switch (finding.kind) {
    case FindingKind::kFixtureMoving:
      lines.push_back(fmt::format("The fixture is moving: the board's pose walks. {}.", alarm));
      lines.push_back(fmt::format(
          "The board's origin is {} µm from its nominal position and moves {} µm per 100 scans {} it; {}.",
          Fixed(finding.now, 0), Fixed(std::abs(finding.per_scan) * 100, 1),
          finding.per_scan >= 0 ? "away from" : "towards",
          soon(fmt::format("the fixture's limit (max_shift_mm = {} mm)", fixture.max_shift_mm))));
      lines.push_back(
          "The scan re-registers the board every cycle, so parts still land where they must; a board beyond the "
          "limit is refused (nominal_shift) and the line stops, and one far off may leave the scan paths' capture "
          "range sooner.");
      if (const SeriesResult& scale = SeriesOf(f, Quantity::kMarkerScale); scale.chart.alarm && scale.trend) {
        // A robot whose scale changes about its origin moves the board's
        // measured position as well: by the change times its distance.
        const double change_ppm = scale.trend->at_end - scale.chart.center;
        lines.push_back(fmt::format(
            "The marker distance drifts too: a robot whose scale changes about its origin (where a Cartesian axis "
            "commonly grows from) moves the board's measured position by the change times the board's distance "
            "from it, here about {} µm for the {} ppm since the baseline at ({}, {}) mm: that much of this walk may "
            "be the robot's, not the fixture's.",
            Fixed(std::abs(change_ppm) * 1e-6 * f.trip_centre.norm() * 1000, 0), Signed(change_ppm, 0),
            Fixed(f.trip_centre.x(), 0), Fixed(f.trip_centre.y(), 0)));
      }
      lines.push_back(
          "What to do: look for wear or a loose part in the fixture's locating pins, stops and clamps, and for dirt "
          "under the board.");
      break;
    case FindingKind::kRobotScale: {
      const SeriesResult& scale = SeriesOf(f, Quantity::kMarkerScale);
      const double now_ppm = scale.trend ? scale.trend->at_end : scale.values.back();
      const double per_100 = scale.trend ? scale.trend->slope * 100 : 0;
      std::string teach = f.teach_scale_ppm ? fmt::format(", the teach scan {} ppm", Signed(*f.teach_scale_ppm, 1)) : "";
      lines.push_back(fmt::format("The robot's scale between the markers is changing (the robot warming?). {}.", alarm));
      lines.push_back(fmt::format(
          "The markers are measured {} ppm against L1 and L2 ({} µm over L1 = {} mm{}; baseline {} ppm{}), "
          "changing {} ppm per 100 scans.",
          Signed(now_ppm, 1), Signed(now_ppm * fixture.l1_mm / 1000, 1), fixture.l1_mm,
          fmt::format(", {} µm over L2 = {} mm", Signed(now_ppm * fixture.l2_mm / 1000, 1), fixture.l2_mm),
          Signed(scale.chart.center, 1), teach, Signed(per_100, 1)));
      if (f.far_corner && f.far_corner->um_per_ppm > 1e-6) {
        const FarCorner& corner = *f.far_corner;
        lines.push_back(fmt::format(
            "The tables were measured with the robot in another state and do not know this. Through the {} "
            "estimator it moves the parts at the board's far corner, ({}, {}) mm in region {}, by {} µm ({} µm a "
            "ppm); the budget there is {} µm at 4σ of its ±{} µm, which leaves {} µm: {}.",
            cell::EstimatorName(fixture.estimator), Fixed(corner.in_base.x(), 1), Fixed(corner.in_base.y(), 1),
            corner.region, Fixed(finding.now, 1), Fixed(corner.um_per_ppm, 3), Fixed(corner.budget_mm * 1000, 1),
            Fixed(corner.tolerance_mm * 1000, 0), Fixed(corner.MarginMm() * 1000, 1),
            soon("the tolerance there")));
      } else {
        lines.push_back(fmt::format(
            "The {} estimator takes a uniform scale change as the board's, so the parts on the board keep their "
            "place; targets off the board (the feeders) are still moved by it.",
            cell::EstimatorName(fixture.estimator)));
      }
      if (!finding.stale.empty()) {
        std::string list;
        for (const StaleRegion& r : finding.stale) {
          list += fmt::format("{}{} (moved by up to {} µm, noise {} µm)", list.empty() ? "" : ", ", r.region,
                              Fixed(r.drift_um, 1), Fixed(r.noise_um, 1));
        }
        lines.push_back(fmt::format(
            "Tables that no longer describe the robot by more than their stated noise (4 standard errors of their "
            "nodes), if the change is the robot's and uniform: {}.",
            list));
      }
      lines.push_back(
          "What to do: let the robot reach its working temperature before production and measure its tables "
          "warm; re-measure the regions named above; check that the board itself did not grow (a warm board reads "
          "the same).");
      if (!f.threshold_identifiable) {
        lines.push_back(
            "This cell's marker layout cannot tell a robot scale change from a sensor that sees the markers smaller "
            "or larger (each marker moves as a whole either way): if the change stays after the tables are "
            "measured warm, clean the sensor and the markers.");
      }
      break;
    }
    case FindingKind::kSensor: {
      lines.push_back(fmt::format("The marker sensor has changed. {}.", alarm));
      const SeriesResult& threshold = SeriesOf(f, Quantity::kSensorThreshold);
      const SeriesResult& scatter = SeriesOf(f, Quantity::kResidualRms);
      std::string what;
      if (!threshold.values.empty()) {
        const double now = threshold.trend ? threshold.trend->at_end : threshold.values.back();
        what += fmt::format("the markers appear {} µm {} than drawn (baseline {} µm): the sensor trips {} entering a "
                            "marker and {} leaving it",
                            Fixed(std::abs(now), 1), now >= 0 ? "smaller" : "larger", Signed(threshold.chart.center, 1),
                            now >= 0 ? "later" : "earlier", now >= 0 ? "earlier" : "later");
      }
      if (!scatter.values.empty()) {
        const double now = scatter.trend ? scatter.trend->at_end : scatter.values.back();
        what += fmt::format("{}the trips scatter {} µm rms about the marker edges (baseline {} µm)",
                            what.empty() ? "" : "; ", Fixed(now, 1), Fixed(scatter.chart.center, 1));
      }
      lines.push_back(fmt::format("Now {}.", what));
      lines.push_back(fmt::format("The largest residual is {} µm and grows {} µm per 100 scans; {}.",
                                  Fixed(finding.now, 1), Signed(finding.per_scan * 100, 1),
                                  soon(fmt::format("the check's limit (max_line_residual_mm = {} mm), where scans are "
                                                   "refused",
                                                   fixture.max_line_residual_mm))));
      lines.push_back(
          "What to do: clean the sensor's lens and the markers; check the sensor's mounting, cable and supply; if "
          "the threshold keeps moving, replace the sensor.");
      break;
    }
    case FindingKind::kRefusals: {
      const RefusalResult* refusal = nullptr;
      for (const RefusalResult& r : f.refusals) {
        if (finding.check && r.check == *finding.check) refusal = &r;
      }
      const std::string name(ScanCheckName(*finding.check));
      lines.push_back(fmt::format(
          "Scans are refused more often: {} refused {} of {} scans, {} of the first {}; its CUSUM (refusals at "
          "{}% or more) alarmed at scan {}.",
          name, refusal ? refusal->count : 0, f.scans, refusal ? refusal->baseline_count : 0,
          std::min<long>(f.scans, static_cast<long>(baseline)), refusal ? Fixed(400 * refusal->p0, 1) : "?",
          finding.alarm_scan));
      lines.push_back(fmt::format(
          "Every refused cycle stops the line. What to do: see what the check means in docs/periphery.md "
          "(\"Checks and fault codes\") and run `smtcal fixture --cell {} --fixture {} --trips ...` on a refused "
          "scan's trips.",
          cell.path.empty() ? "CELL" : cell.path, fixture.name));
      break;
    }
  }
  return lines;
}

// A finding in a few words (the picture's list).
std::string FindingTitle(const Finding& finding) {
  switch (finding.kind) {
    case FindingKind::kFixtureMoving: return "the fixture is moving: the board's pose walks";
    case FindingKind::kRobotScale: return "the robot's scale between the markers is changing";
    case FindingKind::kSensor: return "the marker sensor has changed";
    case FindingKind::kRefusals:
      return fmt::format("scans are refused more often: {}", finding.check ? ScanCheckName(*finding.check) : "?");
  }
  return "?";
}

// "nelson-2 (9 points ...) 3 times, first at scan 120".
std::vector<std::string> RuleLines(const SeriesResult& series) {
  std::map<ChartRule, std::pair<int, long>> count;  // runs, first scan
  for (const RuleRun& run : series.chart.runs) {
    auto& [runs, first] = count[run.rule];
    if (runs++ == 0) first = static_cast<long>(series.scan[run.first]);
  }
  std::vector<std::string> lines;
  for (const auto& [rule, entry] : count) {
    lines.push_back(fmt::format("{} ({}): {}, first at scan {}", ChartRuleName(rule), ChartRuleDescription(rule),
                                entry.first == 1 ? std::string("once") : fmt::format("{} times", entry.first),
                                entry.second));
  }
  return lines;
}

std::string LimitText(Quantity q, const cell::Fixture& fixture) {
  switch (q) {
    case Quantity::kPoseX:
    case Quantity::kPoseY: return fmt::format("±{} µm (max_shift_mm)", Fixed(fixture.max_shift_mm * 1000, 0));
    case Quantity::kPoseAngle: return fmt::format("±{} mdeg (max_rotation_deg)", Fixed(fixture.max_rotation_deg * 1000, 0));
    case Quantity::kMarkerScale:
      return fmt::format("±{} ppm (length_tolerance_mm over max(L1, L2))",
                         Fixed(fixture.length_tolerance_mm / std::max(fixture.l1_mm, fixture.l2_mm) * 1e6, 0));
    case Quantity::kResidualMax: return fmt::format("{} µm (max_line_residual_mm)", Fixed(fixture.max_line_residual_mm * 1000, 0));
    case Quantity::kSensorThreshold:
    case Quantity::kResidualRms: return "";
  }
  return "";
}

std::string IntervalText(const Interval& i, int decimals) {
  return fmt::format("{} [{}, {}]", Fixed(i.value, decimals), Fixed(i.lo, decimals), Fixed(i.hi, decimals));
}

ordered_json IntervalJson(const Interval& i, int decimals) {
  return {{"value", Rounded(i.value, decimals)}, {"lo", Rounded(i.lo, decimals)}, {"hi", Rounded(i.hi, decimals)}};
}

std::string_view FindingName(FindingKind kind) {
  switch (kind) {
    case FindingKind::kFixtureMoving: return "fixture_moving";
    case FindingKind::kRobotScale: return "robot_scale";
    case FindingKind::kSensor: return "sensor";
    case FindingKind::kRefusals: return "refusals";
  }
  return "?";
}

std::string LogsText(const MonitorContext& context) {
  std::string text;
  for (std::size_t i = 0; i < context.logs.size(); ++i) text += (i == 0 ? "" : ", ") + context.logs[i];
  return text;
}

}  // namespace

std::string MonitorReportText(const MonitorResult& result, const MonitorContext& context) {
  std::string out;
  out += fmt::format("smtcal monitor: {} ({} record{}), cell '{}', baseline {} accepted scans per fixture\n",
                     LogsText(context), context.records, context.records == 1 ? "" : "s", context.cell->name,
                     context.options.baseline);
  std::size_t findings = 0;
  for (const FixtureMonitor& f : result.fixtures) findings += f.findings.size();
  out += result.in_control
             ? "verdict: IN CONTROL (exit 0): no drift, no rise in refusals\n"
             : fmt::format("verdict: OUT OF CONTROL (exit 1): {} finding{}\n", findings, findings == 1 ? "" : "s");
  for (const FixtureMonitor& f : result.fixtures) {
    out += fmt::format("\nfixture {}: {} scans, {} accepted", f.name, f.scans, f.accepted);
    if (f.seconds_per_scan) out += fmt::format(", one every {} s", Fixed(*f.seconds_per_scan, 1));
    out += "\n";
    if (!f.charted) {
      out += "  too few accepted scans to chart\n";
      continue;
    }
    int n = 0;
    for (const Finding& finding : f.findings) {
      const std::vector<std::string> lines = Explain(finding, f, *context.cell, context.options.baseline);
      out += fmt::format("  {}. {}\n", ++n, lines.front());
      for (std::size_t i = 1; i < lines.size(); ++i) out += fmt::format("     {}\n", lines[i]);
    }
    out += fmt::format("\n  {:<18} {:>5} {:>9} {:>8} {:>9} {:>9} {:>7}  {}\n", "chart", "unit", "centre", "sigma",
                       "last", "trend/100", "alarm", "rules that fired (Nelson's numbers; scans)");
    for (const SeriesResult& series : f.series) {
      if (series.values.size() <= context.options.baseline) continue;
      const int d = DecimalsOf(series.quantity);
      std::string rules;
      std::map<ChartRule, int> runs;
      for (const RuleRun& run : series.chart.runs) ++runs[run.rule];
      for (const auto& [rule, count] : runs) rules += fmt::format("{}{} x{}", rules.empty() ? "" : ", ", ChartRuleName(rule), count);
      out += fmt::format("  {:<18} {:>5} {:>9} {:>8} {:>9} {:>9} {:>7}  {}\n", QuantityTitle(series.quantity),
                         QuantityUnit(series.quantity), Fixed(series.chart.center, d), Fixed(series.chart.sigma, d + 1),
                         Fixed(series.values.back(), d), series.trend ? Signed(series.trend->slope * 100, d) : "-",
                         series.chart.alarm ? fmt::format("{}{}", series.scan[*series.chart.alarm],
                                                          series.shift_confirmed ? "" : "*")
                                            : "-",
                         rules.empty() ? "-" : rules);
    }
    for (const SeriesResult& series : f.series) {
      if (series.chart.alarm && !series.shift_confirmed) {
        out += fmt::format("  * {}: its CUSUM alarm is no shift of the mean (the mean since scan {} is within {} "
                           "standard errors of the centre line): its values spread more, as a noisier sensor makes them\n",
                           QuantityTitle(series.quantity), series.scan[series.chart.change_point], kShiftConfirmed);
      }
    }
    if (!f.threshold_identifiable) {
      out += "  (this layout of trips cannot tell the sensor's threshold from the pose and the scale: no threshold chart)\n";
    }
    out += "\n  refusals per check:";
    if (f.refusals.empty()) out += " none";
    for (const RefusalResult& r : f.refusals) {
      out += fmt::format(" {} {} ({}%{})", ScanCheckName(r.check), r.count,
                         Fixed(100.0 * static_cast<double>(r.count) / static_cast<double>(f.scans), 1),
                         r.alarm_scan ? fmt::format(", alarm at scan {}", *r.alarm_scan) : "");
    }
    out += "\n";
    if (f.teach_scale_ppm) {
      out += fmt::format("  teach scan: marker distance {} ppm{}\n", Signed(*f.teach_scale_ppm, 1),
                         f.teach_threshold_um ? fmt::format(", sensor threshold {} µm", Signed(*f.teach_threshold_um, 1))
                                              : "");
    }
    if (f.far_corner) {
      const FarCorner& c = *f.far_corner;
      out += fmt::format("  far corner: ({}, {}) mm in {}, {} µm per ppm of scale, budget {} µm of ±{} µm\n",
                         Fixed(c.in_base.x(), 1), Fixed(c.in_base.y(), 1), c.region, Fixed(c.um_per_ppm, 3),
                         Fixed(c.budget_mm * 1000, 1), Fixed(c.tolerance_mm * 1000, 0));
    }
    if (f.disagreements > 0) {
      out += fmt::format("  {} scans recompute differently with this cell (largest pose difference {} µm)\n",
                         f.disagreements, Fixed(f.worst_disagreement_mm * 1000, 3));
    }
    out += fmt::format("\n  process figures of the accepted scans ({}% confidence intervals):\n",
                       Fixed(context.options.confidence * 100, 0));
    for (const SeriesResult& series : f.series) {
      const auto& p = f.process[static_cast<std::size_t>(series.quantity)];
      if (!p || p->n < 2) continue;
      const int d = DecimalsOf(series.quantity);
      std::string cmk = p->cmk ? fmt::format("  Cmk {} against {}", IntervalText(*p->cmk, 2),
                                             LimitText(series.quantity, *f.fixture))
                               : "";
      out += fmt::format("  {:<18} n {}  mean {} {}  σ {}{}\n", QuantityTitle(series.quantity), p->n,
                         IntervalText(p->mean, d), QuantityUnit(series.quantity), IntervalText(p->sigma, d + 1), cmk);
    }
    bool any_rules = false;
    for (const SeriesResult& series : f.series) {
      const std::vector<std::string> lines = RuleLines(series);
      if (lines.empty()) continue;
      if (!any_rules) out += "\n  rules that fired (signals to look at; the verdict is the CUSUMs' and the EWMAs'):\n";
      any_rules = true;
      out += fmt::format("  {}:\n", QuantityTitle(series.quantity));
      for (const std::string& line : lines) out += fmt::format("    {}\n", line);
    }
  }
  return out;
}

ordered_json MonitorReportJson(const MonitorResult& result, const MonitorContext& context) {
  ordered_json json;
  json["logs"] = context.logs;
  json["cell"] = context.cell->name;
  json["records"] = context.records;
  json["baseline"] = context.options.baseline;
  json["cusum"] = {{"k", context.options.cusum_k}, {"h", context.options.cusum_h}, {"clip", context.options.cusum_clip}};
  json["ewma"] = {{"lambda", context.options.ewma_lambda}, {"L", context.options.ewma_l}};
  json["in_control"] = result.in_control;
  ordered_json fixtures = ordered_json::array();
  for (const FixtureMonitor& f : result.fixtures) {
    ordered_json fj;
    fj["fixture"] = f.name;
    fj["scans"] = f.scans;
    fj["accepted"] = f.accepted;
    fj["seconds_per_scan"] = f.seconds_per_scan ? ordered_json(Rounded(*f.seconds_per_scan, 3)) : ordered_json();
    fj["charted"] = f.charted;
    fj["in_control"] = f.in_control;
    ordered_json findings = ordered_json::array();
    for (const Finding& finding : f.findings) {
      ordered_json j;
      j["kind"] = FindingName(finding.kind);
      ordered_json charts = ordered_json::array();
      for (Quantity q : finding.charts) charts.push_back(QuantityName(q));
      j["charts"] = charts;
      j["alarm_scan"] = finding.alarm_scan;
      j["change_scan"] = finding.change_scan;
      if (finding.kind != FindingKind::kRefusals) {
        j["now_um"] = Rounded(finding.now, 3);
        j["per_scan_um"] = Rounded(finding.per_scan, 4);
        j["limit_um"] = Rounded(finding.limit, 3);
        j["scans_to_limit"] = finding.scans_to_limit ? ordered_json(Rounded(*finding.scans_to_limit, 1)) : ordered_json();
      }
      if (finding.check) j["check"] = ScanCheckName(*finding.check);
      if (finding.kind == FindingKind::kRobotScale) {
        ordered_json stale = ordered_json::array();
        for (const StaleRegion& r : finding.stale) {
          stale.push_back({{"region", r.region}, {"drift_um", Rounded(r.drift_um, 3)}, {"noise_um", Rounded(r.noise_um, 3)}});
        }
        j["stale_regions"] = stale;
      }
      ordered_json words = ordered_json::array();
      for (const std::string& line : Explain(finding, f, *context.cell, context.options.baseline)) words.push_back(line);
      j["explanation"] = words;
      findings.push_back(j);
    }
    fj["findings"] = findings;
    ordered_json charts = ordered_json::object();
    for (const SeriesResult& series : f.series) {
      if (series.values.empty()) continue;
      ordered_json c;
      c["unit"] = QuantityUnit(series.quantity);
      c["gates"] = series.gates;
      c["values"] = series.values.size();
      if (series.values.size() > context.options.baseline && f.charted) {
        c["center"] = Rounded(series.chart.center, 4);
        c["sigma"] = Rounded(series.chart.sigma, 4);
        c["alarm_scan"] = series.chart.alarm ? ordered_json(static_cast<long>(series.scan[*series.chart.alarm]))
                                             : ordered_json();
        c["alarm_rule"] = series.chart.alarm ? ordered_json(std::string(ChartRuleName(series.chart.alarm_rule)))
                                             : ordered_json();
        c["change_scan"] = series.chart.alarm ? ordered_json(static_cast<long>(series.scan[series.chart.change_point]))
                                              : ordered_json();
        c["shift_confirmed"] = series.chart.alarm ? ordered_json(series.shift_confirmed) : ordered_json();
        c["trend_per_100_scans"] = series.trend ? ordered_json(Rounded(series.trend->slope * 100, 4)) : ordered_json();
        ordered_json rules = ordered_json::array();
        for (const RuleRun& run : series.chart.runs) {
          rules.push_back({{"rule", ChartRuleName(run.rule)},
                           {"first_scan", static_cast<long>(series.scan[run.first])},
                           {"last_scan", static_cast<long>(series.scan[run.last])}});
        }
        c["rules"] = rules;
      }
      if (const auto& p = f.process[static_cast<std::size_t>(series.quantity)]; p && p->n >= 2) {
        const int d = DecimalsOf(series.quantity) + 2;
        ordered_json pj = {{"n", p->n}, {"mean", IntervalJson(p->mean, d)}, {"sigma", IntervalJson(p->sigma, d)}};
        pj["cmk"] = p->cmk ? IntervalJson(*p->cmk, 3) : ordered_json();
        c["process"] = pj;
      }
      charts[std::string(QuantityName(series.quantity))] = c;
    }
    fj["charts"] = charts;
    ordered_json refusals = ordered_json::object();
    for (const RefusalResult& r : f.refusals) {
      refusals[std::string(ScanCheckName(r.check))] = {
          {"count", r.count}, {"baseline_count", r.baseline_count}, {"p0", Rounded(r.p0, 6)},
          {"alarm_scan", r.alarm_scan ? ordered_json(*r.alarm_scan) : ordered_json()}};
    }
    fj["refusals"] = refusals;
    fj["teach_scale_ppm"] = f.teach_scale_ppm ? ordered_json(Rounded(*f.teach_scale_ppm, 3)) : ordered_json();
    if (f.far_corner) {
      const FarCorner& c = *f.far_corner;
      fj["far_corner"] = {{"x_mm", Rounded(c.in_base.x(), 3)}, {"y_mm", Rounded(c.in_base.y(), 3)},
                          {"region", c.region},           {"um_per_ppm", Rounded(c.um_per_ppm, 5)},
                          {"budget_um", Rounded(c.budget_mm * 1000, 3)}, {"tolerance_um", Rounded(c.tolerance_mm * 1000, 3)}};
    } else {
      fj["far_corner"] = nullptr;
    }
    fj["disagreements"] = f.disagreements;
    fixtures.push_back(fj);
  }
  json["fixtures"] = fixtures;
  return json;
}

namespace {

// The picture's layout: one row per chart, the plot kPlotWidth x kPlotHeight
// with room left of it for the y ticks and right of it for the figures.
constexpr double kLeft = 90, kPlotWidth = 760, kPlotHeight = 120, kRowHeight = 175, kRight = 250;
constexpr double kWidth = kLeft + kPlotWidth + kRight;

struct Axis {
  double lo = 0, hi = 1, step = 1;
};

Axis AxisOver(double lo, double hi, int ticks, double min_step = 0) {
  if (!(hi > lo)) {
    const double pad = std::max(1e-3, std::abs(lo) * 0.1);
    lo -= pad;
    hi += pad;
  }
  Axis axis;
  axis.step = std::max(SvgTickStep(hi - lo, ticks), min_step);
  axis.lo = std::floor(lo / axis.step) * axis.step;
  axis.hi = std::ceil(hi / axis.step) * axis.step;
  return axis;
}

class Plot {
 public:
  Plot(double top, Axis x, Axis y) : top_(top), x_(x), y_(y) {}
  double X(double v) const { return kLeft + (v - x_.lo) / (x_.hi - x_.lo) * kPlotWidth; }
  double Y(double v) const { return top_ + kPlotHeight - (v - y_.lo) / (y_.hi - y_.lo) * kPlotHeight; }
  double top() const { return top_; }
  const Axis& x() const { return x_; }
  const Axis& y() const { return y_; }

  // The frame, the grid and both axes' ticks.
  std::string Frame(std::string_view y_label, std::string_view x_label) const {
    std::string svg = fmt::format(
        "<rect x=\"{}\" y=\"{:.1f}\" width=\"{}\" height=\"{}\" fill=\"#fafafa\" stroke=\"#999\"/>\n", kLeft, top_,
        kPlotWidth, kPlotHeight);
    for (double t : SvgTicks(y_.lo, y_.hi, y_.step)) {
      svg += fmt::format("<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" stroke=\"#eee\"/>"
                         "<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\" font-size=\"11\">{}</text>\n",
                         kLeft, Y(t), kLeft + kPlotWidth, Y(t), kLeft - 5, Y(t) + 4, SvgTickText(t, y_.step));
    }
    for (double t : SvgTicks(x_.lo, x_.hi, x_.step)) {
      svg += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#666\"/>"
                         "<text x=\"{0:.1f}\" y=\"{3:.1f}\" text-anchor=\"middle\" font-size=\"11\">{4}</text>\n",
                         X(t), top_ + kPlotHeight, top_ + kPlotHeight + 4, top_ + kPlotHeight + 16,
                         SvgTickText(t, x_.step));
    }
    svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"11\" fill=\"#444\" "
                       "transform=\"rotate(-90 {} {:.1f})\">{}</text>\n",
                       kLeft - 55, top_ + kPlotHeight / 2, kLeft - 55, top_ + kPlotHeight / 2, SvgEscape(y_label));
    if (!x_label.empty()) {
      svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"11\" fill=\"#444\">{}</text>\n",
                         kLeft + kPlotWidth / 2, top_ + kPlotHeight + 30, SvgEscape(x_label));
    }
    return svg;
  }

  std::string HLine(double y, std::string_view style) const {
    if (y < y_.lo || y > y_.hi) return "";
    return fmt::format("<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" {}/>\n", kLeft, Y(y), kLeft + kPlotWidth,
                       Y(y), style);
  }
  std::string VLine(double x, std::string_view style) const {
    return fmt::format("<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" {3}/>\n", X(x), top_, top_ + kPlotHeight,
                       style);
  }

 private:
  double top_;
  Axis x_, y_;
};

// One quantity's chart: the values, the centre line and the 3 sigma
// limits, the baseline shaded, rule 1's points red, the CUSUM alarm and the
// drift's start, the trend after it.
std::string ChartSvg(const SeriesResult& series, const FixtureMonitor& f, double top, const Axis& scans) {
  const ChartResult& chart = series.chart;
  const bool upward = series.quantity == Quantity::kResidualRms || series.quantity == Quantity::kResidualMax;
  double lo = upward ? chart.center : chart.center - 3.5 * chart.sigma, hi = chart.center + 3.5 * chart.sigma;
  for (double v : series.values) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  const Plot plot(top, scans, AxisOver(lo, hi, 4));
  std::string svg = fmt::format("<!-- chart: {} -->\n", QuantityName(series.quantity));
  svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-weight=\"bold\">{} ({}){}</text>\n", kLeft, top - 8,
                     QuantityTitle(series.quantity), QuantityUnit(series.quantity),
                     series.gates ? "" : " — shown, not judged: it follows the trip scatter");
  const double baseline_end = series.scan[std::min(chart.baseline, series.scan.size()) - 1];
  svg += fmt::format("<rect x=\"{}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{}\" fill=\"#e8eef7\"/>\n", kLeft, top,
                     plot.X(baseline_end) - kLeft, kPlotHeight);
  svg += plot.Frame(QuantityUnit(series.quantity), "");
  svg += fmt::format("<rect x=\"{}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{}\" fill=\"#e8eef7\" fill-opacity=\"0.6\"/>\n",
                     kLeft + 0.5, top + 0.5, std::max(0.0, plot.X(baseline_end) - kLeft - 0.5), kPlotHeight - 1);
  svg += plot.HLine(chart.center, "stroke=\"#1f77b4\"");
  svg += plot.HLine(chart.center + 3 * chart.sigma, "stroke=\"#d62728\" stroke-dasharray=\"5 3\"");
  // A chart of upward drifts only (the scatter, the residuals) has no lower limit.
  const bool both = series.quantity != Quantity::kResidualRms && series.quantity != Quantity::kResidualMax;
  if (both) svg += plot.HLine(chart.center - 3 * chart.sigma, "stroke=\"#d62728\" stroke-dasharray=\"5 3\"");
  std::string points;
  for (std::size_t i = 0; i < series.values.size(); ++i) {
    points += fmt::format("{}{:.1f},{:.1f}", i == 0 ? "" : " ", plot.X(series.scan[i]), plot.Y(series.values[i]));
  }
  svg += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"#555\" stroke-width=\"0.8\"/>\n", points);
  const bool dots = series.values.size() <= 800;
  std::string red;
  for (std::size_t i = 0; i < series.values.size(); ++i) {
    const double z = chart.sigma > 0 ? (series.values[i] - chart.center) / chart.sigma : 0;
    const bool beyond = std::abs(z) > 3;
    if (!dots && !beyond) continue;
    const std::string dot = fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{}\"/>", plot.X(series.scan[i]),
                                        plot.Y(series.values[i]), beyond ? 2.5 : 1.6);
    if (beyond) {
      red += dot;
    } else {
      svg += fmt::format("<g fill=\"#333\">{}</g>", dot);
    }
  }
  if (!red.empty()) svg += "<g fill=\"#d62728\">" + red + "</g>\n";
  std::string note;
  if (chart.alarm) {
    const double alarm = series.scan[*chart.alarm], change = series.scan[chart.change_point];
    svg += plot.VLine(change, "stroke=\"#ff7f0e\" stroke-dasharray=\"4 3\"");
    svg += plot.VLine(alarm, "stroke=\"#d62728\" stroke-width=\"2\"");
    if (series.trend) {
      const Trend& t = *series.trend;
      const double y0 = t.at_end - t.slope * (t.end_x - change);
      svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#ff7f0e\" "
                         "stroke-width=\"2\"/>\n",
                         plot.X(change), plot.Y(std::clamp(y0, plot.y().lo, plot.y().hi)), plot.X(t.end_x),
                         plot.Y(std::clamp(t.at_end, plot.y().lo, plot.y().hi)));
    }
    note = fmt::format("{} alarm at scan {}", ChartRuleName(chart.alarm_rule), static_cast<long>(alarm));
  }
  // The figures beside the plot.
  const int d = DecimalsOf(series.quantity);
  std::vector<std::string> lines = {
      fmt::format("centre {} {}", Fixed(chart.center, d), QuantityUnit(series.quantity)),
      fmt::format("σ {} (baseline; guarded {})", Fixed(chart.sigma_estimate, d + 1), Fixed(chart.sigma, d + 1)),
      fmt::format("last {}", Fixed(series.values.back(), d))};
  if (series.trend) lines.push_back(fmt::format("trend {} per 100 scans", Signed(series.trend->slope * 100, d)));
  if (!note.empty()) lines.push_back(note);
  (void)f;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const bool alarm_line = !note.empty() && i + 1 == lines.size();
    svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-size=\"12\"{}>{}</text>\n", kLeft + kPlotWidth + 12,
                       top + 14 + 17 * static_cast<double>(i), alarm_line ? " fill=\"#d62728\" font-weight=\"bold\"" : "",
                       SvgEscape(lines[i]));
  }
  return svg;
}

// The refusals per check: how many so far, against the scan number.
std::string RefusalsSvg(const FixtureMonitor& f, double top, const Axis& scans) {
  long most = 1;
  for (const RefusalResult& refusal : f.refusals) most = std::max<long>(most, refusal.count);
  const Plot plot(top, scans, AxisOver(0, static_cast<double>(most), 4, 1));  // whole scans
  std::string svg = "<!-- chart: refusals -->\n";
  svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-weight=\"bold\">refused scans per check (so far)</text>\n",
                     kLeft, top - 8);
  svg += plot.Frame("scans refused", "scan (in the order of the log)");
  constexpr std::array<const char*, 6> kColours = {"#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22"};
  int shown = 0;
  for (std::size_t r = 0; r < f.refusals.size(); ++r) {
    const RefusalResult& refusal = f.refusals[r];
    const char* colour = kColours[r % kColours.size()];
    std::string points = fmt::format("{:.1f},{:.1f}", plot.X(1), plot.Y(0));
    long count = 0;
    for (long at : refusal.at_scans) {
      points += fmt::format(" {:.1f},{:.1f} {:.1f},{:.1f}", plot.X(static_cast<double>(at)), plot.Y(static_cast<double>(count)),
                            plot.X(static_cast<double>(at)), plot.Y(static_cast<double>(count + 1)));
      ++count;
    }
    points += fmt::format(" {:.1f},{:.1f}", plot.X(static_cast<double>(f.scans)), plot.Y(static_cast<double>(count)));
    svg += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.5\"/>\n", points, colour);
    if (refusal.alarm_scan) svg += plot.VLine(static_cast<double>(*refusal.alarm_scan), fmt::format("stroke=\"{}\" stroke-width=\"2\"", colour));
    svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-size=\"12\" fill=\"{}\">{} {}{}</text>\n", kLeft + kPlotWidth + 12,
                       top + 14 + 17 * shown, colour, ScanCheckName(refusal.check), refusal.count,
                       refusal.alarm_scan ? fmt::format(", alarm at scan {}", *refusal.alarm_scan) : "");
    ++shown;
  }
  if (f.refusals.empty()) {
    svg += fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-size=\"12\">no scan refused</text>\n", kLeft + kPlotWidth + 12,
                       top + 14);
  }
  return svg;
}

}  // namespace

std::string MonitorReportSvg(const MonitorResult& result, const MonitorContext& context) {
  std::string body;
  double y = 0;
  std::string header;
  header += fmt::format("<text x=\"{}\" y=\"26\" font-size=\"16\" font-weight=\"bold\">Control charts of the cycle "
                        "records: {}, cell {}</text>\n",
                        kLeft, SvgEscape(LogsText(context)), SvgEscape(context.cell->name));
  const std::vector<std::string> legend = {
      fmt::format("Each point: one accepted scan, against its number in the log. Blue band: the baseline (the first {} "
                  "accepted scans),", context.options.baseline),
      "which sets the centre line (blue) and sigma; dashed red: 3 sigma (guarded: the upper 95 % bound of the "
      "baseline's sigma); red dot: beyond it.",
      fmt::format("Red line: the verdict, the first alarm of the CUSUM (k = {} sigma plus the centre's uncertainty, "
                  "h = {} sigma)",
                  context.options.cusum_k, context.options.cusum_h),
      fmt::format("or of the EWMA (lambda {}, {} of its sigmas); dashed orange: where the drift began; orange line: "
                  "its trend.",
                  context.options.ewma_lambda, context.options.ewma_l)};
  for (std::size_t i = 0; i < legend.size(); ++i) {
    header += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"12\">{}</text>\n", kLeft, 46 + 16 * i,
                          SvgEscape(legend[i]));
  }
  header += fmt::format("<text x=\"{}\" y=\"128\" font-size=\"14\" font-weight=\"bold\" fill=\"{}\">{}</text>\n", kLeft,
                        result.in_control ? "#2ca02c" : "#d62728",
                        result.in_control ? "IN CONTROL" : "OUT OF CONTROL");
  y = 144;
  for (const FixtureMonitor& f : result.fixtures) {
    body += fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-size=\"15\" font-weight=\"bold\">fixture {}: {} scans, {} "
                        "accepted</text>\n",
                        kLeft, y + 12, SvgEscape(f.name), f.scans, f.accepted);
    y += 22;
    for (const Finding& finding : f.findings) {
      body += fmt::format("<text x=\"{}\" y=\"{:.1f}\" font-size=\"13\" fill=\"#d62728\">• {} (alarm at scan {})</text>\n",
                          kLeft, y + 12, SvgEscape(FindingTitle(finding)), finding.alarm_scan);
      y += 18;
    }
    y += 30;
    if (!f.charted) {
      body += fmt::format("<text x=\"{}\" y=\"{:.1f}\">too few accepted scans to chart</text>\n", kLeft, y);
      y += 30;
      continue;
    }
    const Axis scans = AxisOver(1, static_cast<double>(std::max<long>(f.scans, 2)), 10);
    for (const SeriesResult& series : f.series) {
      if (series.values.size() <= context.options.baseline) continue;
      body += ChartSvg(series, f, y, scans);
      y += kRowHeight;
    }
    body += RefusalsSvg(f, y, scans);
    y += kRowHeight + 20;
  }
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0:.0f}\" height=\"{1:.0f}\" viewBox=\"0 0 {0:.0f} {1:.0f}\" "
      "font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      kWidth, y);
  return svg + header + body + "</svg>\n";
}

}  // namespace smtcal
