// The measuring programs for LinuxCNC (backend/linuxcnc/linuxcnc_measure.h).
#include "backend/linuxcnc/linuxcnc_measure.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "backend/linuxcnc/linuxcnc_data.h"
#include "base/check.h"

namespace smtcal {
namespace {

std::string Num(double value) { return LinuxCncNumber(value); }

// Region names in file names and comments: letters, digits, '_', '-', '.'.
std::string Safe(std::string_view name) {
  std::string out;
  for (char c : name) {
    out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'
               ? static_cast<char>(std::tolower(static_cast<unsigned char>(c)))
               : '_';
  }
  return out;
}

// measure_s<station>[_<axis>]: one program per placement of the artefact.
std::string ProgramStem(const measure::VisitGroup& group) {
  std::string stem = fmt::format("measure_s{}", group.station);
  if (group.axes != measure::MeasuredAxes::kXY) stem += "_" + std::string(measure::MeasuredAxesName(group.axes));
  return stem;
}

// The settings a reading's meaning depends on, as "; key value" items of
// the log's header: `measure read` refuses a log measured with others than
// the cell's.
std::string LoggedSettings(const cell::Cell& cell) {
  const cell::Measure& m = *cell.measure;
  const Eigen::Vector2d approach = *cell.robot.final_approach_mm;
  std::string out = fmt::format("; approach {} {}", Num(approach.x()), Num(approach.y()));
  if (m.device == cell::MeasureDevice::kProbe) {
    out += fmt::format("; hole_diameter_mm {}; stylus_diameter_mm {}; overtravel_mm {}", Num(m.probe.hole_diameter_mm),
                       Num(m.probe.stylus_diameter_mm), Num(m.probe.overtravel_mm));
  } else if (m.device == cell::MeasureDevice::kTransducer) {
    out += fmt::format("; slope {}; zero_mm {}", Num(m.transducer.slope), Num(m.transducer.zero_mm));
  }
  return out;
}

// The device's settings as the runtime's globals.
std::string DeviceGlobals(const cell::Cell& cell) {
  const cell::Measure& m = *cell.measure;
  const Eigen::Vector2d approach = *cell.robot.final_approach_mm;
  std::string out;
  auto set = [&](std::string_view name, double value, std::string_view comment) {
    out += fmt::format("#<_smtcal_m_{}> = {} ({})\n", name, Num(value), comment);
  };
  set("safe_z", std::max(cell.robot.safe_limz_mm, m.clear_z_mm),
      "robot.safe_limz_mm: each program first rises to it where the head stands, never lowering it");
  set("u", m.u_deg, "measure.u_deg: the nozzle angle the device reads at");
  set("clear_z", m.clear_z_mm, "measure.clear_z_mm: the z between nodes");
  set("z", m.z_mm, "measure.z_mm: the z at which the device reads");
  set("ax", approach.x(), "robot.final_approach_mm x: the last move onto every node");
  set("ay", approach.y(), "robot.final_approach_mm y");
  set("dwell", m.dwell_s, "measure.dwell_s: settle before a reading");
  set("timeout", m.timeout_s, "measure.timeout_s");
  set("ready", m.ready_input ? *m.ready_input : -1, "measure.ready_input: motion.digital-in-NN; -1 none");
  switch (m.device) {
    case cell::MeasureDevice::kTransducer:
      set("input", m.transducer.input, "measure.transducer.input: motion.analog-in-NN on the groove's flank");
      set("reference", m.transducer.reference_input, "measure.transducer.reference_input: the z reference");
      set("lo", m.transducer.range_mm.lo, "measure.transducer.range_mm: a reading outside it aborts");
      set("hi", m.transducer.range_mm.hi, "");
      break;
    case cell::MeasureDevice::kProbe:
      set("radius", measure::ProbeContactRadiusMm(m.probe), "hole minus stylus diameter; halved");
      set("over", m.probe.overtravel_mm, "measure.probe.overtravel_mm");
      set("feed", 60 * m.probe.speed_mm_s, "measure.probe.speed_mm_s in mm/min");
      set("sx", approach.x() < 0 ? -1 : 1, "probe along x in the approach's direction");
      set("sy", approach.y() < 0 ? -1 : 1, "probe along y in the approach's direction");
      break;
    case cell::MeasureDevice::kExternal:
      set("trigger", m.external.trigger_output, "measure.external.trigger_output: motion.digital-out-NN");
      set("done", m.external.done_input, "measure.external.done_input: motion.digital-in-NN");
      set("node_out", m.external.node_output, "measure.external.node_output: node; set and repetition next");
      break;
  }
  // The "( ... )" comment of an empty text is left out.
  std::string cleaned;
  for (std::size_t at = 0; at < out.size();) {
    std::size_t end = out.find('\n', at);
    std::string line = out.substr(at, end - at);
    if (line.ends_with(" ()")) line.resize(line.size() - 3);
    cleaned += line + "\n";
    at = end + 1;
  }
  return cleaned;
}

}  // namespace

MeasuringPrograms EmitMeasuringPrograms(const measure::LoadedPlan& loaded, const cell::Cell& cell, int start,
                                        const std::string& log_dir) {
  SMTCAL_CHECK(cell.measure && cell.robot.final_approach_mm, "a measuring program needs the device and the approach");
  const measure::Plan& plan = loaded.plan;
  SMTCAL_CHECK(start >= 1 && start <= static_cast<int>(plan.visits.size()), "the start visit is one of the plan's");
  const std::string device(cell::kMeasureDeviceNames[static_cast<std::size_t>(cell.measure->device)]);
  const std::string globals = DeviceGlobals(cell);
  const std::string plan_name = Safe(std::filesystem::path(loaded.name).filename().string());
  MeasuringPrograms out;
  const std::vector<measure::VisitGroup> groups = measure::GroupVisits(plan.visits);
  const char rotation = cell.linuxcnc ? cell.linuxcnc->rotation_axis : 'C';
  for (const measure::VisitGroup& group : groups) {
    const int last = plan.visits[group.first + group.count - 1].number;
    if (last < start) continue;
    const int first = std::max(start, plan.visits[group.first].number);
    const bool resumed = first != plan.visits[group.first].number;
    const std::string stem = ProgramStem(group);
    const std::string log = (log_dir.empty() ? "" : log_dir + "/") + stem + ".log";
    std::string regions;
    for (std::size_t k = group.first; k < group.first + group.count; ++k) {
      const std::string name = Safe(plan.regions[plan.visits[k].region].name);
      if ((" " + regions + " ").find(" " + name + " ") == std::string::npos) regions += (regions.empty() ? "" : " ") + name;
    }
    std::string text;
    text += fmt::format("(smtcal measuring program: station {} - regions {} - axes {} - device {})\n", group.station,
                        regions, measure::MeasuredAxesName(group.axes), device);
    text += fmt::format("(from the plan {} - digest {} - visits {} to {}{} - for cell {})\n", plan_name,
                        loaded.digest, first, last, resumed ? " - resumed" : "", Safe(cell.name));
    text += "(docs/measure.md: put the artefact down as the plan says - mount the device - home the machine - run;"
            " the log goes to " + log + ")\n";
    text += "G21 G90 G17 G94\n";
    text += globals;
    text += "#<_smtcal_m_visit> = 0 (the visit being measured, for o<smtcal_measure_on_abort>)\n";
    text += "#<_smtcal_m_rep> = 0\n";
    text += fmt::format("({},{})\n", resumed ? "LOGAPPEND" : "LOGOPEN", log);
    text += fmt::format(
        "(LOG,# smtcal measuring log: plan {} digest {}; program {}; station {}; regions {}; axes {}; device {}{}; "
        "visits {}..{})\n",
        plan_name, loaded.digest, stem, group.station, regions, measure::MeasuredAxesName(group.axes), device,
        LoggedSettings(cell), first, last);
    text += "(LOG,visit,node,set,repetition,x_mm,y_mm,a_mm,b_mm)\n";
    text += fmt::format("o<smtcal_measure_start> call (rise where the head stands, then turn {} to the device's angle)\n",
                        rotation);
    text += fmt::format("G0 {}#<_smtcal_m_u>\n", rotation);
    for (std::size_t k = group.first; k < group.first + group.count; ++k) {
      const measure::Visit& v = plan.visits[k];
      if (v.number < first) continue;
      text += fmt::format("o<smtcal_measure_{}> call [{}] [{}] [{}] [{}] [{}] [{}] [{}] ({} {} set {}{})\n", device,
                          v.number, v.node, v.set, v.repetitions, Num(v.at.x()), Num(v.at.y()), v.direction,
                          measure::VisitKindName(v.kind), v.node, v.set, v.direction < 0 ? " against the approach" : "");
    }
    text += "#<_smtcal_m_visit> = 0\n";
    text += "(LOG,# end)\n(LOGCLOSE)\n";
    text += "G0 Z#<_smtcal_m_safe_z>\nM2\n";
    out.programs.push_back({stem + ".ngc", std::move(text)});
    out.logs.push_back(log);
  }
  for (const EmbeddedFile& file : LinuxCncMeasureFiles()) {
    out.subroutines.push_back(file);
  }
  return out;
}

}  // namespace smtcal
