// Reports of `smtcal monitor` (backend/reports/monitor_report.h).
#include "backend/reports/monitor_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "backend/reports/svg_text.h"
#include "base/csv_field.h"
#include "base/field_text.h"
#include "base/number_range.h"

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

// The decimals every quantity is shown with (µm, mdeg, ppm).
constexpr int kDecimals = 1;

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
std::vector<std::string> Explain(const Finding& finding, const FixtureMonitor& f, const cell::Cell& cell) {
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
      for (const Finding& other : f.findings) {
        if (other.kind != FindingKind::kRobotScale) continue;
        for (const ExplainedDrift& e : other.explains) {
          lines.push_back(fmt::format(
              "Part of it is the robot's scale (finding 1): of the {}'s {} µm per 100 scans it explains {}; "
              "corrected for it the chart still alarms, so the board moves as well.",
              QuantityTitle(e.quantity), Signed(e.observed_per_100, 1), Signed(e.explained_per_100, 1)));
        }
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
      for (const ExplainedDrift& e : finding.explains) {
        lines.push_back(fmt::format(
            "The {} walks with it ({} µm per 100 scans; alarm at scan {}): a robot whose scale changes about its "
            "origin moves the board's measured origin too, through the {} estimator by ({}, {}) µm per ppm of the "
            "marker distance, here {} µm per 100 scans. {}",
            QuantityTitle(e.quantity), Signed(e.observed_per_100, 1),
            static_cast<long>(SeriesOf(f, e.quantity).scan[*SeriesOf(f, e.quantity).chart.alarm]),
            cell::EstimatorName(fixture.estimator), Signed(f.origin_um_per_ppm->x(), 3),
            Signed(f.origin_um_per_ppm->y(), 3), Signed(e.explained_per_100, 1),
            e.alarms_without ? "Corrected for the scale, that chart still alarms: the board moves as well (below)."
                             : "Corrected for the scale, that chart does not alarm: the board itself is not moving, "
                               "look at the robot first."));
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
        if (r.check == finding.check) refusal = &r;
      }
      if (refusal == nullptr) break;
      const std::string name = finding.check ? std::string(ScanCheckName(*finding.check)) : std::string("the checks");
      const BernoulliCusumDesign& d = refusal->design;
      lines.push_back(fmt::format(
          "Scans are refused more often: {} refused {} of {} scans ({}%), against {} of the baseline's {}; the "
          "refusals' CUSUM, designed for {}% ({}{}) and to catch {}%, alarmed at scan {}; the rise began about scan {}.",
          name, refusal->count, f.scans, Fixed(100.0 * static_cast<double>(refusal->count) / static_cast<double>(f.scans), 1),
          refusal->baseline_count, refusal->baseline_scans, Fixed(100 * d.p0, 1),
          d.p0 == kRefusalRateFloor ? "the floor: at most 1 % of good scans refused" : "the baseline's rate",
          fmt::format(", in control once in {} scans", Fixed(d.arl0, 0)), Fixed(100 * d.p1, 1), finding.alarm_scan,
          finding.change_scan));
      for (const RefusalResult& r : f.refusals) {
        if (!r.check && finding.check && r.alarm_scan) {
          lines.push_back(fmt::format("The chart of every refusal together ({} of {} scans) alarmed at scan {}.",
                                      r.count, f.scans, *r.alarm_scan));
        }
      }
      lines.push_back(fmt::format(
          "Every refused cycle stops the line. What to do: see what the check means in docs/periphery.md "
          "(\"Checks and fault codes\") and run `smtcal fixture --cell {} --fixture {} --trips ...` on a refused "
          "scan's trips{}.",
          cell.path.empty() ? "CELL" : cell.path, fixture.name,
          f.findings.size() > 1 && f.findings.front().kind != FindingKind::kRefusals
              ? "; a drift found above makes scans fail their checks too: see to it first"
              : ""));
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
      return fmt::format("scans are refused more often: {}", finding.check ? ScanCheckName(*finding.check) : "all checks");
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


// "a.log:2 to :492", "a.log:2 to b.log:10".
std::string RecordRange(const std::string& first, const std::string& last) {
  const std::size_t a = first.rfind(':'), b = last.rfind(':');
  if (a != std::string::npos && b != std::string::npos && first.substr(0, a) == last.substr(0, b)) {
    return fmt::format("{} to {}", first, last.substr(b));
  }
  return fmt::format("{} to {}", first, last);
}

std::string BaselineText(const FixtureMonitor& f, const MonitorContext& context) {
  const FixtureBaseline& b = f.baseline;
  std::string refusals = fmt::format("{} of its {} scans refused", b.refused_any, b.scans);
  if (f.baseline_stored) {
    return fmt::format("stored in {}: scans {} to {} ({}) of the logs it came from; {}", context.baseline_in,
                       b.first_scan, b.last_scan, RecordRange(b.first_record, b.last_record), refusals);
  }
  return fmt::format("scans {} to {} ({}), the first {} accepted from scan {} on; {}", b.first_scan, b.last_scan,
                     RecordRange(b.first_record, b.last_record), context.options.baseline,
                     context.options.baseline_from, refusals);
}

std::string RefusalName(const RefusalResult& r) {
  return r.check ? std::string(ScanCheckName(*r.check)) : std::string("all refusals");
}

}  // namespace

std::string MonitorReportText(const MonitorResult& result, const MonitorContext& context) {
  std::string out;
  out += fmt::format("smtcal monitor: {} ({} record{}), cell '{}'\n", LogsText(context), context.records,
                     context.records == 1 ? "" : "s", context.cell->name);
  std::size_t findings = 0;
  for (const FixtureMonitor& f : result.fixtures) findings += f.findings.size();
  out += result.in_control
             ? "verdict: IN CONTROL (exit 0): no drift, no rise in refusals\n"
             : fmt::format("verdict: OUT OF CONTROL (exit 4): {} finding{}\n", findings, findings == 1 ? "" : "s");
  for (const FixtureMonitor& f : result.fixtures) {
    out += fmt::format("\nfixture {}: {} scans, {} accepted", f.name, f.scans, f.accepted);
    if (f.seconds_per_scan) out += fmt::format(", one every {} s", Fixed(*f.seconds_per_scan, 1));
    if (!f.restarts.empty()) {
      std::string list;
      for (std::size_t i = 0; i < f.restarts.size() && i < 8; ++i) list += (i == 0 ? "" : ", ") + std::to_string(f.restarts[i]);
      if (f.restarts.size() > 8) list += fmt::format(" and {} more", f.restarts.size() - 8);
      out += fmt::format("; the program started again at scan{} {}", f.restarts.size() == 1 ? "" : "s", list);
    }
    out += "\n";
    out += fmt::format("  baseline: {}\n", BaselineText(f, context));
    int n = 0;
    for (const Finding& finding : f.findings) {
      const std::vector<std::string> lines = Explain(finding, f, *context.cell);
      out += fmt::format("  {}. {}\n", ++n, lines.front());
      for (std::size_t i = 1; i < lines.size(); ++i) out += fmt::format("     {}\n", lines[i]);
    }
    out += fmt::format("\n  {:<18} {:>5} {:>9} {:>8} {:>9} {:>9} {:>7}  {}\n", "chart", "unit", "centre", "sigma",
                       "last", "trend/100", "alarm", "rules that fired (Nelson's numbers; scans)");
    for (const SeriesResult& series : f.series) {
      if (!series.charted) continue;
      std::string rules;
      std::map<ChartRule, int> runs;
      for (const RuleRun& run : series.chart.runs) ++runs[run.rule];
      for (const auto& [rule, count] : runs) rules += fmt::format("{}{} x{}", rules.empty() ? "" : ", ", ChartRuleName(rule), count);
      out += fmt::format("  {:<18} {:>5} {:>9} {:>8} {:>9} {:>9} {:>7}  {}\n", QuantityTitle(series.quantity),
                         QuantityUnit(series.quantity), Fixed(series.chart.center, kDecimals),
                         Fixed(series.chart.sigma, kDecimals + 1), Fixed(series.values.back(), kDecimals),
                         series.trend ? Signed(series.trend->slope * 100, kDecimals) : "-",
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
    out += "\n  refusals (a Bernoulli CUSUM each, designed for the baseline's rate, at least 1 %, to catch 3 times it):\n";
    for (const RefusalResult& r : f.refusals) {
      out += fmt::format("  {:<18} {:>5} ({:>4}%)  baseline {} of {}  designed for {}%: in control once in {} scans, "
                         "at {}% after {}{}\n",
                         RefusalName(r), r.count,
                         Fixed(100.0 * static_cast<double>(r.count) / static_cast<double>(std::max<long>(f.scans, 1)), 1),
                         r.baseline_count, r.baseline_scans, Fixed(100 * r.design.p0, 1), Fixed(r.design.arl0, 0),
                         Fixed(100 * r.design.p1, 1), Fixed(r.design.arl1, 0),
                         r.alarm_scan ? fmt::format("; alarm at scan {}", *r.alarm_scan) : "");
    }
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
      std::string cmk = p->cmk ? fmt::format("  Cmk {} against {}", IntervalText(*p->cmk, 2),
                                             LimitText(series.quantity, *f.fixture))
                               : "";
      out += fmt::format("  {:<18} n {}  mean {} {}  σ {}{}\n", QuantityTitle(series.quantity), p->n,
                         IntervalText(p->mean, kDecimals), QuantityUnit(series.quantity),
                         IntervalText(p->sigma, kDecimals + 1), cmk);
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
  json["baseline"] = context.baseline_in.empty()
                         ? ordered_json{{"scans", context.options.baseline}, {"from_scan", context.options.baseline_from}}
                         : ordered_json{{"stored", context.baseline_in}};
  json["cusum"] = {{"k", context.options.cusum_k}, {"h", context.options.cusum_h}, {"clip", context.options.cusum_clip}};
  json["ewma"] = {{"lambda", context.options.ewma_lambda}, {"L", context.options.ewma_l}};
  json["in_control"] = result.in_control;
  json["exit"] = result.in_control ? 0 : 4;
  ordered_json fixtures = ordered_json::array();
  for (const FixtureMonitor& f : result.fixtures) {
    ordered_json fj;
    fj["fixture"] = f.name;
    fj["scans"] = f.scans;
    fj["accepted"] = f.accepted;
    fj["seconds_per_scan"] = f.seconds_per_scan ? ordered_json(Rounded(*f.seconds_per_scan, 3)) : ordered_json();
    fj["restarts"] = f.restarts;
    fj["charted"] = f.charted;
    fj["in_control"] = f.in_control;
    const FixtureBaseline& b = f.baseline;
    fj["baseline"] = {{"stored", f.baseline_stored}, {"first_scan", b.first_scan}, {"last_scan", b.last_scan},
                      {"first_record", b.first_record}, {"last_record", b.last_record}, {"scans", b.scans},
                      {"refused", b.refused_any}};
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
      } else {
        j["check"] = finding.check ? ordered_json(std::string(ScanCheckName(*finding.check))) : ordered_json("all");
      }
      if (finding.kind == FindingKind::kRobotScale) {
        ordered_json stale = ordered_json::array();
        for (const StaleRegion& r : finding.stale) {
          stale.push_back({{"region", r.region}, {"drift_um", Rounded(r.drift_um, 3)}, {"noise_um", Rounded(r.noise_um, 3)}});
        }
        j["stale_regions"] = stale;
        ordered_json explains = ordered_json::array();
        for (const ExplainedDrift& e : finding.explains) {
          explains.push_back({{"chart", QuantityName(e.quantity)},
                              {"observed_per_100_scans", Rounded(e.observed_per_100, 3)},
                              {"explained_per_100_scans", Rounded(e.explained_per_100, 3)},
                              {"alarms_without", e.alarms_without}});
        }
        j["explains"] = explains;
      }
      ordered_json words = ordered_json::array();
      for (const std::string& line : Explain(finding, f, *context.cell)) words.push_back(line);
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
      if (series.charted) {
        c["center"] = Rounded(series.chart.center, 4);
        c["sigma"] = Rounded(series.chart.sigma, 4);
        c["baseline_n"] = series.chart.baseline;
        c["baseline_outliers"] = series.outliers;
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
        const int d = kDecimals + 2;
        ordered_json pj = {{"n", p->n}, {"mean", IntervalJson(p->mean, d)}, {"sigma", IntervalJson(p->sigma, d)}};
        pj["cmk"] = p->cmk ? IntervalJson(*p->cmk, 3) : ordered_json();
        c["process"] = pj;
      }
      charts[std::string(QuantityName(series.quantity))] = c;
    }
    fj["charts"] = charts;
    ordered_json refusals = ordered_json::object();
    for (const RefusalResult& r : f.refusals) {
      refusals[r.check ? std::string(ScanCheckName(*r.check)) : std::string("all")] = {
          {"count", r.count},
          {"baseline_count", r.baseline_count},
          {"baseline_scans", r.baseline_scans},
          {"p0", Rounded(r.design.p0, 6)},
          {"p1", Rounded(r.design.p1, 6)},
          {"up", r.design.up},
          {"limit", r.design.limit},
          {"in_control_scans", Rounded(r.design.arl0, 1)},
          {"scans_at_p1", Rounded(r.design.arl1, 1)},
          {"alarm_scan", r.alarm_scan ? ordered_json(*r.alarm_scan) : ordered_json()},
          {"change_scan", r.alarm_scan ? ordered_json(r.change_scan) : ordered_json()}};
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

std::string MonitorReportCsv(const MonitorResult& result, const MonitorContext& context) {
  std::string out = "fixture,scan,log,line,run,cycle,time_s,status";
  for (std::size_t q = 0; q < kQuantities; ++q) {
    const auto quantity = static_cast<Quantity>(q);
    std::string unit(QuantityUnit(quantity));
    if (unit == "µm") unit = "um";
    out += fmt::format(",{}_{}", QuantityName(quantity), unit);
  }
  out += "\n";
  for (const FixtureMonitor& f : result.fixtures) {
    // Each chart's value at each scan (the charts hold accepted scans only).
    std::vector<std::array<std::optional<double>, kQuantities>> values(static_cast<std::size_t>(f.scans));
    for (std::size_t q = 0; q < kQuantities; ++q) {
      const SeriesResult& series = f.series[q];
      for (std::size_t i = 0; i < series.values.size(); ++i) {
        values[static_cast<std::size_t>(series.scan[i]) - 1][q] = series.values[i];
      }
    }
    for (long scan = 1; scan <= f.scans; ++scan) {
      const MonitoredCycle& cycle = (*context.cycles)[f.records[static_cast<std::size_t>(scan - 1)]];
      const std::string log = cycle.where.begin.file != 0 && context.sources != nullptr
                                  ? context.sources->File(cycle.where.begin.file).name
                                  : "";
      const std::optional<ScanCheck> failed = cycle.record.failed();
      out += fmt::format("{},{},{},{},{},{},{},{}", CsvField(f.name), scan, CsvField(log), cycle.where.begin.line,
                         cycle.run + 1, cycle.record.cycle,
                         cycle.record.time_s ? NumberText(*cycle.record.time_s) : "",
                         failed ? ScanCheckName(*failed) : "ok");
      for (std::size_t q = 0; q < kQuantities; ++q) {
        const auto& v = values[static_cast<std::size_t>(scan - 1)][q];
        out += "," + (v ? NumberText(Rounded(*v, 4)) : std::string());
      }
      out += "\n";
    }
  }
  return out;
}

namespace {

// The picture's layout: the plots kPlotWidth wide with room left of them for
// the y ticks and right of them for the figures; a chart is three panels.
constexpr double kLeft = 90, kPlotWidth = 760, kRight = 260;
constexpr double kWidth = kLeft + kPlotWidth + kRight;
constexpr double kValuesHeight = 110, kDecisionHeight = 60, kRangeHeight = 40, kPanelGap = 10;
// Values drawn one by one up to this many a panel; beyond it, per column of
// the plot the range of the values (and points beyond 3 sigma, up to
// kMostMarks) — the picture's size does not grow with the logs.
constexpr std::size_t kMostPoints = 1500, kColumns = 380, kMostMarks = 400;

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
  Plot(double top, double height, Axis x, Axis y) : top_(top), height_(height), x_(x), y_(y) {}
  double X(double v) const { return kLeft + (v - x_.lo) / (x_.hi - x_.lo) * kPlotWidth; }
  double Y(double v) const {
    return top_ + height_ - (std::clamp(v, y_.lo, y_.hi) - y_.lo) / (y_.hi - y_.lo) * height_;
  }
  double top() const { return top_; }
  double bottom() const { return top_ + height_; }
  const Axis& x() const { return x_; }
  const Axis& y() const { return y_; }

  // The frame, the grid and the y ticks; the x ticks when `x_ticks`.
  std::string Frame(std::string_view y_label, bool x_ticks, int y_ticks_every = 1) const {
    std::string svg = fmt::format(
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#fafafa\" stroke=\"#999\"/>\n", kLeft, SvgNum(top_),
        kPlotWidth, SvgNum(height_));
    int k = 0;
    for (double t : SvgTicks(y_.lo, y_.hi, y_.step)) {
      svg += fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#eee\"/>", kLeft, SvgNum(Y(t)),
                         kLeft + kPlotWidth, SvgNum(Y(t)));
      if (k++ % y_ticks_every == 0) {
        svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"end\" font-size=\"10\">{}</text>", kLeft - 5,
                           SvgNum(Y(t) + 3.5), SvgTickText(t, y_.step));
      }
      svg += "\n";
    }
    for (double t : SvgTicks(x_.lo, x_.hi, x_.step)) {
      svg += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"#666\"/>", SvgNum(X(t)),
                         SvgNum(bottom()), SvgNum(bottom() + 3));
      if (x_ticks) {
        svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"10\">{}</text>", SvgNum(X(t)),
                           SvgNum(bottom() + 14), SvgTickText(t, x_.step));
      }
      svg += "\n";
    }
    svg += fmt::format("<text x=\"{0}\" y=\"{1}\" text-anchor=\"middle\" font-size=\"10\" fill=\"#444\" "
                       "transform=\"rotate(-90 {0} {1})\">{2}</text>\n",
                       kLeft - 48, SvgNum(top_ + height_ / 2), SvgEscape(y_label));
    return svg;
  }

  std::string HLine(double y, std::string_view style) const {
    if (y < y_.lo || y > y_.hi) return "";
    return fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" {}/>\n", kLeft, SvgNum(Y(y)), kLeft + kPlotWidth,
                       SvgNum(Y(y)), style);
  }
  std::string VLine(double x, std::string_view style) const {
    return fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" {3}/>\n", SvgNum(X(x)), SvgNum(top_),
                       SvgNum(bottom()), style);
  }

  // A series against x: a line through every point when few, else per
  // column of the plot the range of the values (one path).
  std::string Series(const std::vector<double>& x, const std::vector<double>& y, std::string_view colour,
                     double width) const {
    if (x.empty()) return "";
    if (x.size() <= kMostPoints) {
      std::string points;
      for (std::size_t i = 0; i < x.size(); ++i) {
        points += fmt::format("{}{},{}", i == 0 ? "" : " ", SvgNum(X(x[i])), SvgNum(Y(y[i])));
      }
      return fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"/>\n", points, colour,
                         SvgNum(width));
    }
    std::vector<double> lo(kColumns, std::numeric_limits<double>::infinity()),
        hi(kColumns, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double f = (X(x[i]) - kLeft) / kPlotWidth;
      const auto c = std::min(kColumns - 1, static_cast<std::size_t>(std::max(0.0, f) * static_cast<double>(kColumns)));
      lo[c] = std::min(lo[c], y[i]);
      hi[c] = std::max(hi[c], y[i]);
    }
    std::string path;
    for (std::size_t c = 0; c < kColumns; ++c) {
      if (!(hi[c] >= lo[c])) continue;
      const double px = kLeft + (static_cast<double>(c) + 0.5) * kPlotWidth / static_cast<double>(kColumns);
      path += fmt::format("M{} {}V{}", SvgNum(px), SvgNum(Y(lo[c]) + 0.5), SvgNum(Y(hi[c]) - 0.5));
    }
    return fmt::format("<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"/>\n", path, colour,
                       SvgNum(kPlotWidth / static_cast<double>(kColumns)));
  }

 private:
  double top_, height_;
  Axis x_, y_;
};

// The restarts (the program started again) as grey lines, labelled once.
std::string Restarts(const Plot& plot, const FixtureMonitor& f, bool label) {
  std::string svg;
  for (long scan : f.restarts) {
    svg += plot.VLine(static_cast<double>(scan) - 0.5, "stroke=\"#888\" stroke-dasharray=\"2 2\"");
    if (label && f.restarts.size() <= 12) {
      svg += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"9\" fill=\"#666\">restart</text>\n",
                         SvgNum(plot.X(static_cast<double>(scan) - 0.5) + 2), SvgNum(plot.top() + 9));
    }
  }
  return svg;
}

std::string FiguresBeside(double top, const std::vector<std::pair<std::string, bool>>& lines) {
  std::string svg;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    svg += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"11\"{}>{}</text>\n", kLeft + kPlotWidth + 12,
                       SvgNum(top + 12 + 15 * static_cast<double>(i)),
                       lines[i].second ? " fill=\"#d62728\" font-weight=\"bold\"" : "", SvgEscape(lines[i].first));
  }
  return svg;
}

// One quantity's chart: its values (the centre line, 3 sigma, the baseline
// shaded, points beyond 3 sigma red, the alarm, the drift's start and
// trend), the statistic that decides (the CUSUMs over h and the EWMA over
// its limit: the verdict is the first to reach 1) and the moving range.
std::string ChartSvg(const SeriesResult& series, const FixtureMonitor& f, double top, const Axis& scans,
                     const MonitorContext& context) {
  const ChartResult& chart = series.chart;
  const bool upward = chart.options.direction == Direction::kUp;
  std::string svg = fmt::format("<!-- chart: {} -->\n", QuantityName(series.quantity));
  svg += fmt::format("<text x=\"{}\" y=\"{}\" font-weight=\"bold\" font-size=\"13\">{} ({}){}</text>\n", kLeft,
                     SvgNum(top - 6), QuantityTitle(series.quantity), QuantityUnit(series.quantity),
                     series.gates ? "" : " — shown, not judged: it follows the trip scatter");
  // Values.
  double lo = upward ? chart.center - 1.5 * chart.sigma : chart.center - 3.5 * chart.sigma;
  double hi = chart.center + 3.5 * chart.sigma;
  for (double v : series.values) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  const Plot values(top, kValuesHeight, scans, AxisOver(lo, hi, 4));
  if (!f.baseline_stored) {
    svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#e8eef7\"/>\n",
                       SvgNum(values.X(static_cast<double>(f.baseline.first_scan) - 0.5)), SvgNum(top),
                       SvgNum(values.X(static_cast<double>(f.baseline.last_scan) + 0.5) -
                              values.X(static_cast<double>(f.baseline.first_scan) - 0.5)),
                       kValuesHeight);
  }
  svg += values.Frame(QuantityUnit(series.quantity), false);
  if (!f.baseline_stored) {
    svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#e8eef7\" fill-opacity=\"0.6\"/>\n",
                       SvgNum(values.X(static_cast<double>(f.baseline.first_scan) - 0.5)), SvgNum(top + 0.5),
                       SvgNum(values.X(static_cast<double>(f.baseline.last_scan) + 0.5) -
                              values.X(static_cast<double>(f.baseline.first_scan) - 0.5)),
                       kValuesHeight - 1);
  }
  svg += Restarts(values, f, true);
  svg += values.HLine(chart.center, "stroke=\"#1f77b4\"");
  svg += values.HLine(chart.center + 3 * chart.sigma, "stroke=\"#d62728\" stroke-dasharray=\"5 3\"");
  if (!upward) svg += values.HLine(chart.center - 3 * chart.sigma, "stroke=\"#d62728\" stroke-dasharray=\"5 3\"");
  svg += values.Series(series.scan, series.values, "#555", 0.8);
  // The points: every one when few; beyond 3 sigma red — when many, the
  // farthest of each column of the plot, so they cover the whole range.
  const bool dots = series.values.size() <= kMostPoints / 2;
  std::string black, red;
  std::vector<std::optional<std::size_t>> farthest(kColumns);
  std::size_t beyond_count = 0;
  auto z_of = [&](std::size_t i) { return chart.sigma > 0 ? (series.values[i] - chart.center) / chart.sigma : 0.0; };
  for (std::size_t i = 0; i < series.values.size(); ++i) {
    const double z = z_of(i);
    const bool beyond = upward ? z > 3 : std::abs(z) > 3;
    if (beyond) {
      ++beyond_count;
      const auto c = std::min(kColumns - 1, static_cast<std::size_t>(std::max(0.0, (values.X(series.scan[i]) - kLeft) /
                                                                                        kPlotWidth * kColumns)));
      if (!farthest[c] || std::abs(z) > std::abs(z_of(*farthest[c]))) farthest[c] = i;
    }
    if (!dots && !beyond) continue;
    if (beyond && beyond_count > kMostMarks) continue;
    (beyond ? red : black) += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"{}\"/>", SvgNum(values.X(series.scan[i])),
                                          SvgNum(values.Y(series.values[i])), beyond ? "2.5" : "1.5");
  }
  if (beyond_count > kMostMarks) {
    red.clear();
    for (const std::optional<std::size_t>& i : farthest) {
      if (!i) continue;
      red += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"2.5\"/>", SvgNum(values.X(series.scan[*i])),
                         SvgNum(values.Y(series.values[*i])));
    }
  }
  if (!black.empty()) svg += "<g fill=\"#333\">" + black + "</g>\n";
  if (!red.empty()) svg += "<g fill=\"#d62728\">" + red + "</g>\n";
  std::vector<std::pair<std::string, bool>> lines = {
      {fmt::format("centre {} {}", Fixed(chart.center, kDecimals), QuantityUnit(series.quantity)), false},
      {fmt::format("σ {} (guarded {})", Fixed(chart.sigma_estimate, kDecimals + 1), Fixed(chart.sigma, kDecimals + 1)),
       false},
      {fmt::format("last {}", Fixed(series.values.back(), kDecimals)), false}};
  if (series.trend) lines.push_back({fmt::format("trend {} per 100 scans", Signed(series.trend->slope * 100, kDecimals)), false});
  if (chart.alarm) {
    const double alarm = series.scan[*chart.alarm], change = series.scan[chart.change_point];
    svg += values.VLine(change, "stroke=\"#ff7f0e\" stroke-dasharray=\"4 3\"");
    svg += values.VLine(alarm, "stroke=\"#d62728\" stroke-width=\"2\"");
    if (series.trend) {
      const Trend& t = *series.trend;
      const double y0 = t.at_end - t.slope * (t.end_x - change);
      svg += fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#ff7f0e\" stroke-width=\"2\"/>\n",
                         SvgNum(values.X(change)), SvgNum(values.Y(y0)), SvgNum(values.X(t.end_x)),
                         SvgNum(values.Y(t.at_end)));
    }
    bool explained = false;
    for (const Finding& finding : f.findings) {
      for (const ExplainedDrift& e : finding.explains) explained = explained || (e.quantity == series.quantity && !e.alarms_without);
    }
    lines.push_back({fmt::format("{} alarm at scan {}{}", ChartRuleName(chart.alarm_rule), static_cast<long>(alarm),
                                 series.shift_confirmed ? "" : " (no shift)"),
                     series.gates && series.shift_confirmed});
    if (explained) lines.push_back({"the robot's scale explains it", true});
    lines.push_back({fmt::format("the drift began about scan {}", static_cast<long>(change)), false});
  }
  svg += FiguresBeside(top, lines);

  // The statistic that decides, as a fraction of its limit.
  const ChartTrace trace = TraceChart(series.values, chart);
  const double decision_top = top + kValuesHeight + kPanelGap;
  const Plot decision(decision_top, kDecisionHeight, scans, Axis{upward ? 0.0 : -1.5, 1.5, 0.5});
  svg += decision.Frame("of limit", false, 2);
  svg += Restarts(decision, f, false);
  svg += decision.HLine(1, "stroke=\"#d62728\"");
  if (!upward) svg += decision.HLine(-1, "stroke=\"#d62728\"");
  svg += decision.HLine(0, "stroke=\"#bbb\"");
  std::vector<double> up(trace.cusum_up.size()), down(trace.cusum_down.size()), ewma(trace.ewma.size());
  for (std::size_t i = 0; i < up.size(); ++i) {
    up[i] = trace.cusum_up[i] / chart.options.cusum_h;
    down[i] = -trace.cusum_down[i] / chart.options.cusum_h;
    ewma[i] = trace.ewma_limit[i] > 0 ? trace.ewma[i] / trace.ewma_limit[i] : 0;
  }
  svg += decision.Series(series.scan, up, "#1f77b4", 1.2);
  if (!upward) svg += decision.Series(series.scan, down, "#1f77b4", 1.2);
  svg += decision.Series(series.scan, ewma, "#2ca02c", 1.2);
  if (chart.alarm) svg += decision.VLine(series.scan[*chart.alarm], "stroke=\"#d62728\" stroke-width=\"2\"");
  svg += FiguresBeside(decision_top, {{"blue: CUSUM / h (up; down below 0)", false},
                                      {fmt::format("green: EWMA / its limit (L {})", NumberText(chart.options.ewma_l)), false},
                                      {"red line: the limit; reached: alarm", false}});

  // The moving range.
  const double range_top = decision_top + kDecisionHeight + kPanelGap;
  double most = chart.mr_mean * 3.267;
  for (double r : trace.moving_range) most = std::max(most, r);
  const Plot range(range_top, kRangeHeight, scans, AxisOver(0, most, 2));
  svg += range.Frame("MR", true);
  svg += Restarts(range, f, false);
  svg += range.HLine(chart.mr_mean, "stroke=\"#1f77b4\"");
  svg += range.HLine(chart.mr_mean * 3.267, "stroke=\"#d62728\" stroke-dasharray=\"5 3\"");
  svg += range.Series(series.scan, trace.moving_range, "#777", 0.8);
  svg += FiguresBeside(range_top, {{fmt::format("moving range: mean {}, limit {}", Fixed(chart.mr_mean, kDecimals + 1),
                                                Fixed(chart.mr_mean * 3.267, kDecimals + 1)),
                                    false}});
  (void)context;
  return svg;
}

// The refusals: each chart's sum over its limit (1: alarm), each refusal a
// tick below.
std::string RefusalsSvg(const FixtureMonitor& f, double top, const Axis& scans) {
  const double height = kValuesHeight;
  const Plot plot(top, height, scans, Axis{0, 1.25, 0.25});
  std::string svg = "<!-- chart: refusals -->\n";
  svg += fmt::format("<text x=\"{}\" y=\"{}\" font-weight=\"bold\" font-size=\"13\">refusals: each Bernoulli CUSUM "
                     "over its limit, and every refused scan (ticks)</text>\n",
                     kLeft, SvgNum(top - 6));
  svg += plot.Frame("of limit", false, 2);
  svg += Restarts(plot, f, true);
  svg += plot.HLine(1, "stroke=\"#d62728\"");
  constexpr std::array<const char*, 6> kColours = {"#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22"};
  std::vector<std::pair<std::string, bool>> lines;
  std::vector<double> x(static_cast<std::size_t>(f.scans));
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i + 1);
  for (std::size_t r = 0; r < f.refusals.size() && r < kColours.size(); ++r) {
    const RefusalResult& refusal = f.refusals[r];
    const char* colour = r == 0 ? "#333" : kColours[(r - 1) % kColours.size()];
    std::vector<double> y(refusal.run.sum.size());
    for (std::size_t i = 0; i < y.size(); ++i) y[i] = static_cast<double>(refusal.run.sum[i]) / refusal.design.limit;
    svg += plot.Series(x, y, colour, 1.2);
    std::string ticks;
    for (std::size_t i = 0; i < refusal.at_scans.size() && i < kMostMarks; ++i) {
      const double px = plot.X(static_cast<double>(refusal.at_scans[i]));
      ticks += fmt::format("M{} {}V{}", SvgNum(px), SvgNum(plot.bottom() - 2 - 5 * static_cast<double>(r)),
                           SvgNum(plot.bottom() - 6 - 5 * static_cast<double>(r)));
    }
    if (!ticks.empty()) svg += fmt::format("<path d=\"{}\" stroke=\"{}\"/>\n", ticks, colour);
    if (refusal.alarm_scan) {
      svg += plot.VLine(static_cast<double>(*refusal.alarm_scan), fmt::format("stroke=\"{}\" stroke-width=\"2\"", colour));
    }
    lines.push_back({fmt::format("{}: {}{}", RefusalName(refusal), refusal.count,
                                 refusal.alarm_scan ? fmt::format(", alarm at scan {}", *refusal.alarm_scan) : ""),
                     refusal.alarm_scan.has_value()});
  }
  if (f.refusals.size() > kColours.size()) lines.push_back({fmt::format("({} more checks: see the report)", f.refusals.size() - kColours.size()), false});
  lines.push_back({"each designed for its baseline rate", false});
  lines.push_back({"(at least 1 %), to catch 3 times it", false});
  svg += FiguresBeside(top, lines);
  // The scan axis under the last panel.
  for (double t : SvgTicks(scans.lo, scans.hi, scans.step)) {
    svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"10\">{}</text>\n",
                       SvgNum(plot.X(t)), SvgNum(plot.bottom() + 14), SvgTickText(t, scans.step));
  }
  svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" font-size=\"11\" fill=\"#444\">scan (in the order "
                     "of the logs; dashed grey: the program started again)</text>\n",
                     kLeft + kPlotWidth / 2, SvgNum(plot.bottom() + 30));
  return svg;
}

constexpr double kChartHeight = kValuesHeight + kDecisionHeight + kRangeHeight + 2 * kPanelGap + 50;

}  // namespace

std::string MonitorReportSvg(const MonitorResult& result, const MonitorContext& context) {
  std::string body;
  std::string header;
  header += fmt::format("<text x=\"{}\" y=\"24\" font-size=\"16\" font-weight=\"bold\">Control charts of the cycle "
                        "records: {}, cell {}</text>\n",
                        kLeft, SvgEscape(LogsText(context)), SvgEscape(context.cell->name));
  header += fmt::format("<text x=\"{}\" y=\"48\" font-size=\"15\" font-weight=\"bold\" fill=\"{}\">{}</text>\n", kLeft,
                        result.in_control ? "#2ca02c" : "#d62728",
                        result.in_control ? "IN CONTROL (exit 0)" : "OUT OF CONTROL (exit 4)");
  double y = 58;
  // The findings first, alarms before everything else.
  for (const FixtureMonitor& f : result.fixtures) {
    for (const Finding& finding : f.findings) {
      header += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"13\" fill=\"#d62728\">• {}: {} (alarm at scan {}, "
                            "began about scan {})</text>\n",
                            kLeft, SvgNum(y + 12), SvgEscape(f.name), SvgEscape(FindingTitle(finding)),
                            finding.alarm_scan, finding.change_scan);
      y += 17;
    }
  }
  const std::vector<std::string> legend = {
      "Per chart, three panels against the scan number: the values (each an accepted scan; many scans: their range "
      "per column), the centre line (blue)",
      "and 3 sigma (dashed red; guarded: the upper 95 % bound of the baseline's sigma), the baseline shaded; then the "
      "statistic that decides, the CUSUM",
      fmt::format("(k = {} sigma plus the centre's uncertainty, h = {} sigma) and the EWMA (lambda {}, {} of its "
                  "sigmas) each over its limit: an alarm when one reaches 1;",
                  NumberText(context.options.cusum_k), NumberText(context.options.cusum_h),
                  NumberText(context.options.ewma_lambda), NumberText(context.options.ewma_l)),
      "then the moving range. Red line: the alarm; dashed orange: where the drift began; orange line: its trend. "
      "Alarmed charts first."};
  y += 8;
  for (const std::string& line : legend) {
    header += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"11\" fill=\"#333\">{}</text>\n", kLeft, SvgNum(y + 11),
                          SvgEscape(line));
    y += 14;
  }
  y += 16;
  for (const FixtureMonitor& f : result.fixtures) {
    body += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"15\" font-weight=\"bold\">fixture {}: {} scans, {} "
                        "accepted{}</text>\n",
                        kLeft, SvgNum(y + 12), SvgEscape(f.name), f.scans, f.accepted,
                        f.restarts.empty() ? "" : fmt::format(", {} restart{}", f.restarts.size(), f.restarts.size() == 1 ? "" : "s"));
    y += 18;
    if (!f.charted) {
      body += fmt::format("<text x=\"{}\" y=\"{}\">no baseline: not judged</text>\n", kLeft, SvgNum(y + 12));
      y += 30;
      continue;
    }
    body += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"11\">baseline: {}</text>\n", kLeft, SvgNum(y + 12),
                        SvgEscape(BaselineText(f, context)));
    y += 40;
    // The scans, from the first to the last (ticks at round numbers inside).
    const double last_scan = static_cast<double>(std::max<long>(f.scans, 2));
    const Axis scans{0.5, last_scan + 0.5, std::max(1.0, SvgTickStep(last_scan, 10))};
    // The charts of the findings first (in their order), then the others.
    std::vector<Quantity> order;
    bool refusals_alarmed = false;
    for (const Finding& finding : f.findings) {
      for (Quantity q : finding.charts) {
        if (std::find(order.begin(), order.end(), q) == order.end()) order.push_back(q);
      }
      for (const ExplainedDrift& e : finding.explains) {
        if (std::find(order.begin(), order.end(), e.quantity) == order.end()) order.push_back(e.quantity);
      }
      refusals_alarmed = refusals_alarmed || finding.kind == FindingKind::kRefusals;
    }
    for (std::size_t q = 0; q < kQuantities; ++q) {
      if (std::find(order.begin(), order.end(), static_cast<Quantity>(q)) == order.end()) order.push_back(static_cast<Quantity>(q));
    }
    auto refusals = [&] {
      body += RefusalsSvg(f, y, scans);
      y += kValuesHeight + 58;
    };
    if (refusals_alarmed) refusals();
    for (Quantity q : order) {
      const SeriesResult& series = f.series[static_cast<std::size_t>(q)];
      if (!series.charted) continue;
      body += ChartSvg(series, f, y, scans, context);
      y += kChartHeight;
    }
    if (!refusals_alarmed) refusals();
  }
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0:.0f}\" height=\"{1:.0f}\" viewBox=\"0 0 {0:.0f} {1:.0f}\" "
      "font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      kWidth, y);
  return svg + header + body + "</svg>\n";
}

}  // namespace smtcal
