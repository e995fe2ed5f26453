// The LinuxCNC machine's configuration against the cell, and a machine
// written from it (linuxcnc_machine.h). Assumes a loaded cell with a
// [linuxcnc] table; guarantees that a configuration EmitLinuxCncMachine
// wrote passes CheckLinuxCncMachine.
#include "backend/linuxcnc/linuxcnc_machine.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "backend/linuxcnc/linuxcnc_dry_run.h"
#include "base/check.h"
#include "calibration/limits.h"

namespace smtcal {
namespace fs = std::filesystem;

namespace {

// Numbers as the cell writes them: the shortest form that reads back.
std::string Num(double value) { return fmt::format("{}", value); }

std::optional<double> ParseNumber(std::string_view text) {
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

bool Same(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max({1.0, std::abs(a), std::abs(b)}); }

// One axis of the machine: its letter, joint, and what the cell says of it.
struct AxisSpec {
  char letter;
  int joint;
  cell::Interval limits;
  double speed, accel;
  std::string limit_key, speed_key, accel_key;  // the cell's keys, for messages
};

std::vector<AxisSpec> Axes(const cell::Cell& cell) {
  const cell::Robot& r = cell.robot;
  const char rotation = cell.linuxcnc ? cell.linuxcnc->rotation_axis : 'C';
  return {{'X', 0, r.limits[0], r.xy_speed_mm_s, r.xy_accel_mm_s2, "robot.x_mm", "robot.xy_speed_mm_s",
           "robot.xy_accel_mm_s2"},
          {'Y', 1, r.limits[1], r.xy_speed_mm_s, r.xy_accel_mm_s2, "robot.y_mm", "robot.xy_speed_mm_s",
           "robot.xy_accel_mm_s2"},
          {'Z', 2, r.limits[2], r.z_speed_mm_s, r.z_accel_mm_s2, "robot.z_mm", "robot.z_speed_mm_s",
           "robot.z_accel_mm_s2"},
          {rotation, 3, r.limits[3], r.u_speed_deg_s, r.u_accel_deg_s2, "robot.u_deg", "robot.u_speed_deg_s",
           "robot.u_accel_deg_s2"}};
}

std::string Letters(const cell::Cell& cell) {
  std::string letters;
  for (const AxisSpec& axis : Axes(cell)) letters += axis.letter;
  return letters;
}

// The longest task cycle the cell's probe_turnaround_s allows: each probe
// move costs LinuxCNC's task about three cycles (measured: 0.025 s a probe
// move at CYCLE_TIME 0.001, 0.052 s at 0.010). Necessary, not sufficient:
// the rest is the controller's own.
double MostTaskCycle(const cell::Robot& robot) { return robot.probe_turnaround_s / 3; }
// What a machine smtcal writes runs at: the cycle probe_turnaround_s's
// default was measured with.
constexpr double kWrittenTaskCycleS = 0.001;

long ServoPeriodNs(const cell::Robot& robot) { return std::lround(robot.servo_period_s * 1e9); }

class Checker {
 public:
  Checker(const cell::Cell& cell, const IniFile& ini, SourceManager& sources, Diagnostics& diags)
      : cell_(cell), ini_(ini), sources_(sources), diags_(diags) {}

  void Run(const std::vector<LinuxCncIoUse>& io, const HalConfig& hal) {
    CheckKinematics();
    for (const AxisSpec& axis : Axes(cell_)) CheckAxis(axis);
    const cell::Robot& robot = cell_.robot;
    CheckNumber("TRAJ", "MAX_LINEAR_VELOCITY", robot.xy_speed_mm_s, "robot.xy_speed_mm_s", robot.range);
    CheckNumber("TRAJ", "MAX_LINEAR_ACCELERATION", robot.xy_accel_mm_s2, "robot.xy_accel_mm_s2", robot.range);
    CheckNumber("EMCMOT", "SERVO_PERIOD", static_cast<double>(ServoPeriodNs(robot)), "robot.servo_period_s",
                robot.servo_period_range, Num(robot.servo_period_s));
    CheckTaskCycle();
    CheckSignals(io, hal);
    CheckWorkOffsets();
  }

 private:
  // The INI's value of a key that must be a number; null (and an error)
  // when it is missing or not one.
  std::optional<double> Value(std::string_view section, std::string_view key, std::string_view needs,
                              std::string_view cell_key, std::string_view cell_value) {
    const IniEntry* entry = ini_.Find(section, key);
    if (entry == nullptr) {
      diags_.Report(DiagKind::LinuxCncMachineKeyMissing, ini_.range, fmt::format("[{}]{}", section, key),
                    fmt::format("{} = {}", key, needs), cell_key, cell_value);
      return std::nullopt;
    }
    std::optional<double> value = ParseNumber(entry->value);
    if (!value) {
      diags_.Report(DiagKind::LinuxCncMachineDisagrees, entry->range, fmt::format("[{}]{}", section, key),
                    entry->value, cell_key, cell_value, fmt::format("{} = {}", key, needs));
    }
    return value;
  }

  void CheckNumber(std::string_view section, std::string_view key, double wanted, std::string_view cell_key,
                   SourceRange cell_range, std::string cell_value = "") {
    if (cell_value.empty()) cell_value = Num(wanted);
    const std::optional<double> value = Value(section, key, Num(wanted), cell_key, cell_value);
    if (!value || Same(*value, wanted)) return;
    const IniEntry* entry = ini_.Find(section, key);
    Diagnostic* diag = diags_.Report(DiagKind::LinuxCncMachineDisagrees, entry->range,
                                     fmt::format("[{}]{}", section, key), entry->value, cell_key, cell_value,
                                     fmt::format("{} = {}", key, Num(wanted)));
    Diagnostics::AddNote(diag, cell_range, fmt::format("{} is set here", cell_key));
  }

  void CheckKinematics() {
    const std::string letters = Letters(cell_);
    const std::string kinematics = fmt::format("trivkins coordinates={}", letters);
    const IniEntry* kins = ini_.Find("KINS", "KINEMATICS");
    const std::string reason = fmt::format("the robot's axes x, y, z and u on {}", letters.back());
    if (kins == nullptr) {
      diags_.Report(DiagKind::LinuxCncMachineKeyMissing, ini_.range, "[KINS]KINEMATICS",
                    fmt::format("KINEMATICS = {}", kinematics), "linuxcnc.rotation_axis", reason);
    } else if (kins->value != kinematics) {
      diags_.Report(DiagKind::LinuxCncMachineDisagrees, kins->range, "[KINS]KINEMATICS", kins->value,
                    "linuxcnc.rotation_axis", reason, fmt::format("KINEMATICS = {}", kinematics));
    }
    CheckNumber("KINS", "JOINTS", 4, "the robot's axes", cell_.robot.range, "x, y, z, u");
    std::string coordinates;
    for (char c : letters) coordinates += fmt::format("{}{}", coordinates.empty() ? "" : " ", c);
    CheckText("TRAJ", "COORDINATES", {coordinates}, coordinates, "the robot's axes", reason);
    CheckText("TRAJ", "LINEAR_UNITS", {"mm", "metric"}, "mm", "the cell's lengths", "mm");
    CheckText("TRAJ", "ANGULAR_UNITS", {"degree", "deg", "degrees"}, "degree", "the cell's angles", "degrees");
  }

  void CheckText(std::string_view section, std::string_view key, const std::vector<std::string>& accepted,
                 const std::string& wanted, std::string_view cell_key, std::string_view cell_value) {
    const IniEntry* entry = ini_.Find(section, key);
    if (entry == nullptr) {
      diags_.Report(DiagKind::LinuxCncMachineKeyMissing, ini_.range, fmt::format("[{}]{}", section, key),
                    fmt::format("{} = {}", key, wanted), cell_key, cell_value);
      return;
    }
    if (std::find(accepted.begin(), accepted.end(), entry->value) != accepted.end()) return;
    diags_.Report(DiagKind::LinuxCncMachineDisagrees, entry->range, fmt::format("[{}]{}", section, key),
                  entry->value, cell_key, cell_value, fmt::format("{} = {}", key, wanted));
  }

  void CheckAxis(const AxisSpec& axis) {
    const cell::Robot& robot = cell_.robot;
    const SourceRange limit_range = robot.limit_keys[static_cast<std::size_t>(axis.joint)];
    for (const std::string& section : {fmt::format("AXIS_{}", axis.letter), fmt::format("JOINT_{}", axis.joint)}) {
      CheckNumber(section, "MIN_LIMIT", axis.limits.lo, axis.limit_key, limit_range,
                  fmt::format("[{}, {}]", Num(axis.limits.lo), Num(axis.limits.hi)));
      CheckNumber(section, "MAX_LIMIT", axis.limits.hi, axis.limit_key, limit_range,
                  fmt::format("[{}, {}]", Num(axis.limits.lo), Num(axis.limits.hi)));
      CheckNumber(section, "MAX_VELOCITY", axis.speed, axis.speed_key, robot.range);
      CheckNumber(section, "MAX_ACCELERATION", axis.accel, axis.accel_key, robot.range);
    }
  }

  void CheckTaskCycle() {
    const cell::Robot& robot = cell_.robot;
    const double most = MostTaskCycle(robot);
    const std::string needs = fmt::format("{:.4g} or less (and more than 0)", most);
    const std::optional<double> cycle =
        Value("TASK", "CYCLE_TIME", needs, "robot.probe_turnaround_s", Num(robot.probe_turnaround_s));
    // The task's period: a time, so more than 0 (LinuxCNC would run its task
    // loop without a pause, or not at all).
    if (!cycle || (*cycle > 0 && *cycle <= most * (1 + 1e-9))) return;
    const IniEntry* entry = ini_.Find("TASK", "CYCLE_TIME");
    Diagnostic* diag = diags_.Report(
        DiagKind::LinuxCncMachineDisagrees, entry->range, "[TASK]CYCLE_TIME", entry->value,
        "robot.probe_turnaround_s", Num(robot.probe_turnaround_s),
        fmt::format("CYCLE_TIME = {} (each probe move of the scan costs the task about three cycles)", needs));
    Diagnostics::AddNote(diag, robot.range, "the scan's time (smtcal verify, smtcal scan report) assumes it");
  }

  void CheckSignals(const std::vector<LinuxCncIoUse>& io, const HalConfig& hal) {
    const std::string ini_name = fs::path(ini_.path).filename().string();
    const SourceRange at = ini_.Find("HAL", "HALFILE") != nullptr ? ini_.Find("HAL", "HALFILE")->range : ini_.range;
    if (!cell_.fixtures.empty() && !hal.connected.contains("motion.probe-input")) {
      diags_.Report(DiagKind::LinuxCncPinNotConnected, at, "motion.probe-input",
                    fmt::format("the marker sensor of fixture '{}': the scan probes with G38.3/G38.5",
                                cell_.fixtures.front().name),
                    ini_name);
    }
    std::map<std::pair<bool, int>, const LinuxCncIoUse*> seen;
    for (const LinuxCncIoUse& use : io) {
      if (!seen.emplace(std::make_pair(use.output, use.bit), &use).second) continue;
      const std::string pin = fmt::format("motion.digital-{}-{:02}", use.output ? "out" : "in", use.bit);
      if (use.bit >= hal.num_dio) {
        Diagnostic* diag =
            diags_.Report(DiagKind::LinuxCncDioTooFew, hal.motmod_found ? hal.motmod : at, hal.num_dio, use.what,
                          use.bit, use.output ? "out" : "in", use.bit, use.bit + 1);
        Diagnostics::AddNote(diag, use.range, fmt::format("{} {} is used here", use.what, use.bit));
        continue;
      }
      if (hal.connected.contains(pin)) continue;
      Diagnostic* diag = diags_.Report(DiagKind::LinuxCncPinNotConnected, at, pin,
                                       fmt::format("{} {}", use.what, use.bit), ini_name);
      Diagnostics::AddNote(diag, use.range, fmt::format("{} {} is used here", use.what, use.bit));
    }
  }

  // The parameter file: G54 (#5221..#5229) and G92 (#5211..#5219) offsets
  // 0, G92 off (#5210), G54 the active system (#5220 = 1).
  void CheckWorkOffsets() {
    const IniEntry* file = ini_.Find("RS274NGC", "PARAMETER_FILE");
    if (file == nullptr) return;  // LinuxCNC starts from a fresh one: all zero
    const fs::path path = fs::path(file->value).is_absolute() ? fs::path(file->value) : ini_.directory / file->value;
    std::error_code error;
    if (!fs::exists(path, error)) return;  // LinuxCNC creates it, all zero
    Result<std::uint32_t> loaded = sources_.Load(path.string());
    if (!loaded) {
      diags_.Report(DiagKind::LinuxCncConfigFileMissing, file->range, "PARAMETER_FILE", file->value,
                    loaded.error().message);
      return;
    }
    const SourceFile& text = sources_.File(loaded.value());
    for (std::uint32_t n = 1; n <= text.line_starts.size(); ++n) {
      const std::string_view line = text.Line(n);
      const std::size_t tab = line.find_first_of(" \t");
      if (tab == std::string_view::npos) continue;
      const std::optional<double> number = ParseNumber(line.substr(0, tab));
      std::string_view rest = line.substr(tab);
      while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t')) rest.remove_prefix(1);
      const std::optional<double> value = ParseNumber(rest);
      if (!number || !value) continue;
      const int parameter = static_cast<int>(*number);
      const bool offset = (parameter >= 5211 && parameter <= 5219) || (parameter >= 5221 && parameter <= 5229);
      const char* what = parameter == 5210 ? "G92 offsets applied"
                         : parameter == 5220 ? "the active coordinate system, 1 = G54"
                         : parameter <= 5219 ? "a G92 offset"
                                             : "a G54 offset";
      const double wanted = parameter == 5220 ? 1 : 0;
      if ((offset || parameter == 5210 || parameter == 5220) && *value != wanted) {
        diags_.Report(DiagKind::LinuxCncWorkOffset, SourceRange(SourceLoc{loaded.value(), n, 1}, tab), parameter,
                      what, Num(*value));
      }
    }
  }

  const cell::Cell& cell_;
  const IniFile& ini_;
  SourceManager& sources_;
  Diagnostics& diags_;
};

std::string MachineIni(const cell::Cell& cell, const std::string& stem) {
  const cell::Robot& r = cell.robot;
  const std::string letters = Letters(cell);
  std::string coordinates;
  for (char c : letters) coordinates += fmt::format("{}{}", coordinates.empty() ? "" : " ", c);
  std::string out = fmt::format(
      "# {stem}.ini - a LinuxCNC machine for cell '{cell}', written by smtcal {version}\n"
      "# (smtcal compile --target linuxcnc) with the program {stem}.ngc. What the cell and the\n"
      "# program decide is filled in from them (docs/linuxcnc.md, \"The machine's configuration\"):\n"
      "# the robot's limits, speeds and accelerations, the servo period, the task's cycle, the\n"
      "# signals, the subroutine path. The joints are looped back in {stem}.hal (a simulator);\n"
      "# for the real cell replace them with your drives and check the INI with\n"
      "#   smtcal compile PROGRAM --cell CELL --target linuxcnc --ini YOUR.ini -o JOB\n"
      "#   linuxcnc {stem}.ini\n\n"
      "[EMC]\nMACHINE = smtcal-{cell}\nVERSION = 1.1\nDEBUG = 0\n\n"
      "[DISPLAY]\nDISPLAY = axis\nOPEN_FILE = {stem}.ngc\nPOSITION_OFFSET = RELATIVE\n"
      "POSITION_FEEDBACK = ACTUAL\nMAX_FEED_OVERRIDE = 1.0\nPROGRAM_PREFIX = .\n\n"
      "[TASK]\nTASK = milltask\n"
      "# Each probe move of the marker scan costs the task about three cycles: the\n"
      "# cell's robot.probe_turnaround_s = {turnaround} s was measured at this cycle.\n"
      "CYCLE_TIME = {task}\n\n"
      "[RS274NGC]\nPARAMETER_FILE = {stem}.var\n"
      "# smtcal's runtime and the cell's data, beside this file.\n"
      "SUBROUTINE_PATH = subroutines\n\n"
      "[EMCMOT]\nEMCMOT = motmod\n"
      "# Seconds the task waits for the motion controller; 1 is too short without a realtime kernel.\n"
      "COMM_TIMEOUT = 30\n"
      "# robot.servo_period_s = {period} s: the motion controller latches the marker sensor this often.\n"
      "SERVO_PERIOD = {period_ns}\n\n"
      "[EMCIO]\nEMCIO = io\nCYCLE_TIME = 0.100\nTOOL_TABLE = {stem}.tbl\n\n"
      "[HAL]\nHALFILE = {stem}.hal\nHALUI = halui\n\n"
      "[KINS]\nKINEMATICS = trivkins coordinates={letters}\nJOINTS = 4\n\n"
      "[TRAJ]\nCOORDINATES = {coordinates}\nLINEAR_UNITS = mm\nANGULAR_UNITS = degree\n"
      "# x and y move together and the slower decides (the cell's motion model).\n"
      "DEFAULT_LINEAR_VELOCITY = {xy_speed}\nMAX_LINEAR_VELOCITY = {xy_speed}\n"
      "MAX_LINEAR_ACCELERATION = {xy_accel}\n"
      "DEFAULT_ANGULAR_VELOCITY = {u_speed}\nMAX_ANGULAR_VELOCITY = {u_speed}\n",
      fmt::arg("stem", stem), fmt::arg("cell", cell.name), fmt::arg("version", SMTCAL_VERSION),
      fmt::arg("turnaround", Num(r.probe_turnaround_s)), fmt::arg("task", Num(kWrittenTaskCycleS)),
      fmt::arg("period", Num(r.servo_period_s)), fmt::arg("period_ns", ServoPeriodNs(r)),
      fmt::arg("letters", letters), fmt::arg("coordinates", coordinates), fmt::arg("xy_speed", Num(r.xy_speed_mm_s)),
      fmt::arg("xy_accel", Num(r.xy_accel_mm_s2)), fmt::arg("u_speed", Num(r.u_speed_deg_s)));
  for (const AxisSpec& axis : Axes(cell)) {
    const std::string numbers = fmt::format("MIN_LIMIT = {}\nMAX_LIMIT = {}\nMAX_VELOCITY = {}\nMAX_ACCELERATION = {}\n",
                                            Num(axis.limits.lo), Num(axis.limits.hi), Num(axis.speed),
                                            Num(axis.accel));
    out += fmt::format("\n# {}, {}, {}\n[AXIS_{}]\n{}\n", axis.limit_key, axis.speed_key, axis.accel_key,
                       axis.letter, numbers);
    // No home switches: every joint homes where it stands, z first.
    out += fmt::format("[JOINT_{}]\nTYPE = {}\n{}HOME_SEQUENCE = {}\n", axis.joint,
                       axis.joint == 3 ? "ANGULAR" : "LINEAR", numbers, axis.joint == 2 ? 0 : 1);
  }
  return out;
}

std::string MachineHal(const cell::Cell& cell, const std::vector<LinuxCncIoUse>& io, const std::string& stem) {
  int num_dio = 4;
  for (const LinuxCncIoUse& use : io) num_dio = std::max(num_dio, use.bit + 1);
  std::string out = fmt::format(
      "# {stem}.hal - HAL for {stem}.ini (cell '{cell}'), written by smtcal {version}: the motion\n"
      "# controller, the joints looped back (a simulator: replace that part with your drives) and\n"
      "# the signals the cell and the program use, each on a net of its own. On the real cell add\n"
      "# each signal's pin to its net, e.g. `net marker-sensor hm2_7i96.0.gpio.010.in`.\n\n"
      "loadrt [KINS]KINEMATICS\n"
      "loadrt [EMCMOT]EMCMOT servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS num_dio={num_dio}\n"
      "addf motion-command-handler servo-thread\naddf motion-controller servo-thread\n\n"
      "# --- joints: looped back (simulation)\n",
      fmt::arg("stem", stem), fmt::arg("cell", cell.name), fmt::arg("version", SMTCAL_VERSION),
      fmt::arg("num_dio", num_dio));
  const std::array<const char*, 4> joint_names = {"x", "y", "z", "u"};
  for (int j = 0; j < 4; ++j) {
    out += fmt::format("net {}-pos joint.{}.motor-pos-cmd => joint.{}.motor-pos-fb\n", joint_names[j], j, j);
  }
  out += "\n# --- the cell's and the program's signals\n";
  if (!cell.fixtures.empty()) {
    out += fmt::format("# the marker sensor of fixture '{}' (the scan probes with G38.3/G38.5); nothing drives\n"
                       "# it here, so the first scan aborts with missing_trip, as on a cell without markers\n"
                       "net marker-sensor => motion.probe-input\n",
                       cell.fixtures.front().name);
  }
  std::map<std::pair<bool, int>, std::string> nets;  // (output, bit) -> what uses it
  for (const LinuxCncIoUse& use : io) nets.emplace(std::make_pair(use.output, use.bit), use.what);
  // The simulated vacuum switch follows the first vacuum valve, so a Pick or
  // Place does not time out: its input is on the valve's net.
  const int switch_bit = cell.linuxcnc ? cell.linuxcnc->vacuum_sensor_input : -1;
  int valve = -1;
  for (const LinuxCncIoUse& use : io) {
    if (use.output && use.what == "vacuum output") {
      valve = use.bit;
      break;
    }
  }
  for (const auto& [key, what] : nets) {
    const auto [output, bit] = key;
    if (!output && bit == switch_bit && valve >= 0) continue;  // on the valve's net below
    out += fmt::format("# {} {}\n", what, bit);
    if (output && bit == valve && switch_bit >= 0) {
      out += fmt::format("# ... and the vacuum switch, which follows it in this simulator\n"
                         "net out-{0:02} motion.digital-out-{0:02} => motion.digital-in-{1:02}\n",
                         bit, switch_bit);
    } else if (output) {
      out += fmt::format("net out-{0:02} motion.digital-out-{0:02}\n", bit);
    } else {
      out += fmt::format("net in-{0:02} => motion.digital-in-{0:02}\n", bit);
    }
  }
  out += "\n# --- machine on, tool changes: loopbacks\n"
         "net estop-loop iocontrol.0.user-enable-out => iocontrol.0.emc-enable-in\n"
         "net tool-prep-loop iocontrol.0.tool-prepare => iocontrol.0.tool-prepared\n"
         "net tool-change-loop iocontrol.0.tool-change => iocontrol.0.tool-changed\n";
  return out;
}

}  // namespace

void CheckLinuxCncMachine(const cell::Cell& cell, const std::vector<LinuxCncIoUse>& io, const IniFile& ini,
                          const HalConfig& hal, SourceManager& sources, Diagnostics& diags) {
  Checker(cell, ini, sources, diags).Run(io, hal);
}

Result<fs::path> LinuxCncRuntimeFolder(const IniFile& ini) {
  const IniEntry* path = ini.Find("RS274NGC", "SUBROUTINE_PATH");
  if (path == nullptr || path->value.empty()) {
    return Error{fmt::format("'{}' has no [RS274NGC]SUBROUTINE_PATH: name the folder smtcal writes its runtime "
                             "into (e.g. SUBROUTINE_PATH = smtcal-runtime)",
                             ini.path)};
  }
  const std::string first = path->value.substr(0, path->value.find(':'));
  const fs::path folder = fs::path(first).is_absolute() ? fs::path(first) : ini.directory / first;
  return folder.lexically_normal();
}

std::vector<LinuxCncMachineFile> EmitLinuxCncMachine(const cell::Cell& cell, const std::vector<LinuxCncIoUse>& io,
                                                     const std::string& stem) {
  std::vector<LinuxCncMachineFile> files;
  files.push_back({stem + ".ini", MachineIni(cell, stem)});
  files.push_back({stem + ".hal", MachineHal(cell, io, stem)});
  files.push_back({stem + ".tbl", "T1 P1 ;nozzle\n"});
  files.push_back({stem + ".var", LinuxCncZeroOffsets()});
  return files;
}

}  // namespace smtcal
