// The files of `smtcal measure` (backend/reports/measurement_csv.h).
#include "backend/reports/measurement_csv.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace smtcal {
namespace {

// Lengths as the shortest decimal that reads back, to the micrometre.
std::string Mm(double mm) { return fmt::format("{}", std::round(mm * 1000) / 1000 + 0.0); }

std::string Lines(const std::vector<double>& lines) {
  return fmt::format("{}..{} mm ({} lines)", Mm(lines.front()), Mm(lines.back()), lines.size());
}

}  // namespace

std::string FormatDuration(double seconds) {
  const long total = std::lround(seconds);
  const long hours = total / 3600, minutes = (total % 3600) / 60, secs = total % 60;
  if (hours > 0) return fmt::format("{} h {:02} min", hours, minutes);
  if (minutes > 0) return fmt::format("{} min {:02} s", minutes, secs);
  return fmt::format("{} s", secs);
}

std::vector<std::string> PlanSummary(const measure::Plan& plan, std::string_view cell_path) {
  std::vector<std::string> lines;
  lines.push_back(fmt::format("smtcal measurement plan for cell '{}' ({}): device {}, final approach ({}, {}) mm",
                              plan.cell_name, cell_path,
                              cell::kMeasureDeviceNames[static_cast<std::size_t>(plan.device)],
                              Mm(plan.approach_mm.x()), Mm(plan.approach_mm.y())));
  long readings = 0;
  for (const measure::Visit& visit : plan.visits) readings += visit.repetitions;
  for (const measure::PlanRegion& region : plan.regions) {
    lines.push_back(fmt::format("region {}{}: bounds x {}..{}, y {}..{} mm, tolerance ±{} mm", region.name,
                                region.proposed ? " (proposed: not in the cell)" : "", Mm(region.x_mm.lo),
                                Mm(region.x_mm.hi), Mm(region.y_mm.lo), Mm(region.y_mm.hi), Mm(region.tolerance_mm)));
    lines.push_back(fmt::format("  grid x {}, y {}: {} nodes, {} check point{}{}", Lines(region.xs), Lines(region.ys),
                                region.nodes, region.check_points, region.check_points == 1 ? "" : "s",
                                plan.device == cell::MeasureDevice::kTransducer ? " per axis" : ""));
    lines.push_back(fmt::format("  pitch {} mm {}", Mm(region.pitch_mm), region.pitch_reason));
    lines.push_back(fmt::format("  {} set{} x {} repetition{}{}; {}", region.sets, region.sets == 1 ? "" : "s",
                                region.repetitions, region.repetitions == 1 ? "" : "s",
                                plan.device == cell::MeasureDevice::kTransducer
                                    ? fmt::format(", x and y measured apart, on {} placement{} of the plate",
                                                  region.stations, region.stations == 1 ? "" : "s")
                                    : "",
                                FormatDuration(region.time_s)));
  }
  for (const measure::PlanStation& station : plan.stations) {
    std::string regions;
    for (std::size_t r : station.regions) regions += (regions.empty() ? "" : ", ") + plan.regions[r].name;
    if (regions.empty()) regions = "ties only";
    std::string ties;
    if (!station.tied_to.empty()) {
      std::string with;
      for (int t : station.tied_to) with += (with.empty() ? "" : ", ") + std::to_string(t);
      ties = fmt::format("; tied to station{} {}{}", station.tied_to.size() == 1 ? "" : "s", with,
                         station.ties > 0 ? fmt::format(" ({} tie point{} measured here)", station.ties,
                                                        station.ties == 1 ? "" : "s")
                                          : "");
    }
    const std::string reference = plan.device == cell::MeasureDevice::kProbe        ? "the plate's corner hole"
                                  : plan.device == cell::MeasureDevice::kTransducer ? "the plate's first groove node"
                                                                                    : "nothing (no artefact)";
    lines.push_back(fmt::format("station {}{}: {}; {} at ({}, {}), reaching to ({}, {}){}", station.number,
                                station.axes == measure::MeasuredAxes::kXY
                                    ? ""
                                    : fmt::format(" ({})", measure::MeasuredAxesName(station.axes)),
                                regions, reference, Mm(station.origin.x()), Mm(station.origin.y()), Mm(station.far.x()),
                                Mm(station.far.y()), ties));
  }
  if (plan.device == cell::MeasureDevice::kProbe && plan.probe_reach_mm > 0) {
    lines.push_back(fmt::format("probing: a wall may lie up to {} mm from where a probe move expects it (the robot's "
                                "error, the plate's placement and turn); every probe move starts farther than that "
                                "from it and runs at the probing feed",
                                Mm(plan.probe_reach_mm)));
  }
  for (const std::string& note : plan.notes) lines.push_back("note: " + note);
  lines.push_back(fmt::format("{} visits, {} readings: {} at the cell's speeds (moves, dwell and the device's "
                              "reading time; the controller's own time per move comes on top)",
                              plan.visits.size(), readings, FormatDuration(plan.time_s)));
  return lines;
}

std::string FormatPlanCsv(const measure::Plan& plan, std::string_view cell_path) {
  std::string out;
  for (const std::string& line : PlanSummary(plan, cell_path)) out += fmt::format("# {}\n", line);
  out += "# Make the measuring programs: smtcal measure program THIS_FILE --cell CELL -o DIR\n";
  const bool both = std::any_of(plan.visits.begin(), plan.visits.end(),
                                [](const measure::Visit& v) { return v.direction < 0; });
  out += both ? "visit,region,axes,station,kind,node,x_mm,y_mm,set,repetitions,approach\n"
              : "visit,region,axes,station,kind,node,x_mm,y_mm,set,repetitions\n";
  for (const measure::Visit& v : plan.visits) {
    out += fmt::format("{},{},{},{},{},{},{},{},{},{}{}\n", v.number, plan.regions[v.region].name,
                       measure::MeasuredAxesName(v.axes), v.station, measure::VisitKindName(v.kind), v.node,
                       Mm(v.at.x()), Mm(v.at.y()), v.set, v.repetitions,
                       both ? (v.direction < 0 ? ",-" : ",+") : "");
  }
  return out;
}

std::string FormatRawCsv(const std::vector<RawMeasurement>& rows, const std::vector<bool>& checks,
                         const std::vector<std::string>& comment) {
  std::string out;
  for (const std::string& line : comment) out += fmt::format("# {}\n", line);
  const bool kinds = std::find(checks.begin(), checks.end(), true) != checks.end();
  const bool uncertain = std::any_of(rows.begin(), rows.end(), [](const RawMeasurement& m) { return m.u_mm.has_value(); });
  const bool both = std::any_of(rows.begin(), rows.end(), [](const RawMeasurement& m) { return m.reverse; });
  out += "axis,x_mm,y_mm,set,repetition,error_mm";
  out += uncertain ? ",u_mm" : "";
  out += both ? ",approach" : "";
  out += kinds ? ",kind\n" : "\n";
  auto six = [](double v) {
    v = std::round(v * 1e6) / 1e6;
    return v == 0 ? 0.0 : v;  // never "-0.000000"
  };
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const RawMeasurement& m = rows[k];
    out += fmt::format("{},{},{},{},{},{:.6f}", AxisName(m.axis), Mm(m.x_mm), Mm(m.y_mm), m.set, m.repetition,
                       six(m.error_mm));
    if (uncertain) out += m.u_mm ? fmt::format(",{:.6f}", six(*m.u_mm)) : ",";
    if (both) out += m.reverse ? ",-" : ",+";
    out += kinds ? (checks[k] ? ",check\n" : ",node\n") : "\n";
  }
  return out;
}

}  // namespace smtcal
