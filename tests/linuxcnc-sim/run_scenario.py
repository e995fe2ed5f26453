#!/usr/bin/python3
# run_scenario.py - one scenario of the LinuxCNC simulation (README.md): the
# program compiled by smtcal runs on LinuxCNC's real motion controller with
# the simulated marker sensor (marker-sensor.hal), and what the machine did
# is checked against smtcal itself.
#
#   run_scenario.py --smtcal BIN --checker BIN --work DIR SCENARIO
#
# 1. The machine: examples/linuxcnc/paper-cell.ini made headless (DISPLAY =
#    driver.py, no INTRO_GRAPHIC), with the sensor HAL after the example's
#    HAL and the compiled program's subroutines on the path; the example's
#    HAL, tool table and parameter file as shipped.
# 2. `smtcal compile PROGRAM --cell CELL --target linuxcnc`.
# 3. LinuxCNC in its own PID, IPC and mount namespaces (its shutdown kills
#    processes by name and removes shared memory by fixed keys; its lock
#    file is /tmp/linuxcnc.lock: each run gets its own /tmp) under
#    `timeout -k`, as root with RTAPI_UID (rtapi_app's fallback uid) and
#    RTAPI_FIFO_PATH. The driver runs the planned cycles and writes run.json.
# 4. Per cycle, the latched trips as a trip file and `smtcal fixture --json`
#    on them (with --previous: the cycle checks), the verdict the runtime
#    must have reached.
# 5. The checker (check_places.cpp): the trips against the true marker edges,
#    every Place against smtcal's C++ correction from the same trips, and
#    where each part lands through the cell's tables.
# 6. A refused scan: the abort names the fixture, the same check and value
#    as `smtcal fixture`, and the vacuum valve did not change after the scan
#    began.
# 7. The cycle record the runtime wrote (docs/monitor.md): one record per
#    scan, refused ones too, each what `smtcal fixture` made of the latched
#    trips; the monitor scenarios then run `smtcal monitor` on it.
#
# Exit 0: passed; 1: failed; 77: skipped (LinuxCNC or namespaces cannot
# start here; the message says why).
import argparse
import filecmp
import hashlib
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import time
import tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
EXAMPLE = os.path.join(SOURCE, "examples", "linuxcnc")
CELL = os.path.join(SOURCE, "examples", "paper-cell", "paper.cell.toml")
SKIP = 77

# The fixture's nominal pose (paper.cell.toml: origin_mm, angle_deg) and the
# board's centre in its own frame (markers at 0..8 and 182..190 x 0..8 and
# 82..90): boards are turned about it, so both markers move about as much.
NOMINAL = (138.0, 40.0, 0.0)
CENTRE = (95.0, 45.0)


def pose(dx=0.0, dy=0.0, turn_deg=0.0, present=True):
    """The board's true pose: shifted by (dx, dy) and turned about its centre."""
    a = math.radians(NOMINAL[2] + turn_deg)
    cx = NOMINAL[0] + CENTRE[0]
    cy = NOMINAL[1] + CENTRE[1]
    ox = cx - (math.cos(a) * CENTRE[0] - math.sin(a) * CENTRE[1]) + dx
    oy = cy - (math.sin(a) * CENTRE[0] + math.cos(a) * CENTRE[1]) + dy
    return {"x_mm": ox, "y_mm": oy, "angle_deg": NOMINAL[2] + turn_deg, "present": present}


def pose_s1(dx=0.0, dy=0.0, turn_deg=0.0):
    """The board's true pose by its origin S1 (what the fixture's limits
    bound): S1 shifted by (dx, dy), the board turned about it."""
    return {"x_mm": NOMINAL[0] + dx, "y_mm": NOMINAL[1] + dy, "angle_deg": NOMINAL[2] + turn_deg, "present": True}


def limit_corner(turn_deg, towards_deg, fraction=0.99):
    """A board at a corner of the fixture's limits (max_shift_mm = 2,
    max_rotation_deg = 0.5), times `fraction`: S1 shifted in the direction
    `towards_deg` and the board turned about S1."""
    a = math.radians(towards_deg)
    return pose_s1(fraction * 2 * math.cos(a), fraction * 2 * math.sin(a), fraction * turn_deg)


# Where a turn of the board about S1 moves marker 2 (its corner at (190, 90)
# of the board): the shift that adds to it is the worst for the scan.
MARKER2_DRIFT_DEG = math.degrees(math.atan2(190.0, -90.0))

SIM = os.path.join(HERE, "sim.place")
MONITOR = os.path.join(HERE, "monitor.place")
EXAMPLE_PROGRAM = os.path.join(SOURCE, "examples", "paper-cell", "layers.place")
V_PATHS = os.path.join(HERE, "v-paths-fixture.toml")  # the scan before two stages: V paths at 12 mm/s

# expect: "ok" (every cycle places), or the check the last cycle's scan fails.
# The example's scan paths measure every board its limits accept
# (`smtcal cell check` states the capture range): boards at the corners of
# the limits place, boards beyond them are refused by the pose checks.
SCENARIOS = {
    # The first board anywhere; the next two within 0.1 mm and 0.03 deg of
    # it, as a fixture repeats: their scans are latched where the last one
    # predicts (predicted_window_mm).
    "good_boards": {"program": SIM, "expect": "ok",
                    "cycles": [pose(0.3, -0.2, 0.1), pose(0.36, -0.16, 0.12), pose(0.27, -0.25, 0.09)]},
    # The corners of the limits: S1 1.98 mm off, turned 0.495 deg; the first
    # two move marker 2 the most (3.8 mm). A nominal board between two
    # corners: the cycle checks hold the change between two boards to the
    # same limits (two opposite corners are 3.96 mm apart: cycle_shift).
    "limit_corners": {"program": SIM, "expect": "ok",
                      "cycles": [limit_corner(0.5, MARKER2_DRIFT_DEG), pose_s1(),
                                 limit_corner(-0.5, MARKER2_DRIFT_DEG + 180), pose_s1(),
                                 limit_corner(0.5, -45), pose_s1(), limit_corner(-0.5, 135)]},
    "missing_board": {"program": SIM, "expect": "missing_trip", "cycles": [pose(present=False)]},
    "shifted_board": {"program": SIM, "expect": "nominal_shift", "cycles": [pose_s1(1.45, 1.45)]},
    "rotated_board": {"program": SIM, "expect": "nominal_rotation", "cycles": [pose_s1(turn_deg=-0.515)]},
    # The cycle checks: monitor.place (one part a cycle) is enough for the
    # first board.
    "cycle_shift": {"program": MONITOR, "expect": "cycle_shift", "cycles": [pose_s1(-1.0, 0.6), pose_s1(1.0, -0.6)]},
    "cycle_rotation": {"program": MONITOR, "expect": "cycle_rotation",
                       "cycles": [pose(turn_deg=-0.3), pose(turn_deg=0.25)]},
    # The dry-run probe file (compile --dry-run-probe) first on the machine's
    # path by mistake: it must abort before the first move.
    "dry_run_on_machine": {"program": SIM, "expect": "dry_run_refused", "dry_run": True, "cycles": [pose()]},
    # Opt-in (the linuxcnc-sim-full target): the shipped example, 40 parts a
    # cycle, three boards.
    "example_three_boards": {"program": EXAMPLE_PROGRAM, "expect": "ok",
                             "cycles": [pose(0.4, -0.3, 0.15), pose(-0.5, 0.2, -0.25), pose(0.1, 0.3, 0.05)]},
    # Opt-in: the scan before two stages (V paths, every trip latched at 12
    # mm/s) and the example's, on the same boards (within the V paths' narrow
    # capture), side by side: the overhead per cycle and the pose's error.
    # Every scan in full (predicted_window_mm 0), as the designs compared.
    "scan_compare": {"program": SIM, "expect": "ok",
                     "cycles": [pose(0.3, -0.2, 0.1), pose(-0.3, 0.2, -0.15), pose(0.1, 0.3, 0.05),
                                pose(-0.2, -0.3, 0.2)],
                     "variants": [{"name": "v-paths-12", "fixture": V_PATHS, "cell": {"predicted_window_mm": 0},
                                   "what": "today's scan: V paths, one stage at 12 mm/s"},
                                  {"name": "hairpins-40-8", "cell": {"predicted_window_mm": 0},
                                   "what": "the example: two stages, 40 and 8 mm/s"}]},
    # Opt-in: the frontier of time against accuracy: the example's paths at
    # other search and latch speeds, every scan in full.
    "scan_frontier": {"program": SIM, "expect": "ok",
                      "cycles": [pose(0.3, -0.2, 0.1), pose(-0.3, 0.2, -0.15), pose(0.1, 0.3, 0.05),
                                 pose(-0.2, -0.3, 0.2)],
                      "variants": [{"name": f"two-stages-{search}-{latch}", "what": f"search {search}, latch {latch} mm/s",
                                    "cell": {"scan_speed_mm_s": search, "latch_speed_mm_s": latch,
                                             "predicted_window_mm": 0}}
                                   for search, latch in ((25, 4), (40, 4), (40, 8), (40, 12), (60, 8), (100, 12))]
                      + [{"name": "one-stage-12", "what": "one stage at 12 mm/s",
                          "cell": {"scan_speed_mm_s": 12, "latch_speed_mm_s": None, "predicted_window_mm": 0}}]},
}
# The monitor (docs/monitor.md): a board that walks and a robot whose scale
# between the markers drifts (the sensor HAL's gains; the checker lands the
# parts with it), both from cycle `start` on, with a little jitter of the
# board's pose. The log must show both drifts, named, and the alarms must
# come before the cycle at which the drifting scale would put parts at the
# board's far corner out of tolerance. The short one runs with every ctest;
# the long one is opt-in.


def drifting(cycles, start, walk_mm, scale_ppm, seed=30):
    rng = random.Random(seed)
    plan = []
    for c in range(1, cycles + 1):
        steps = max(0, c - start)
        p = pose(rng.uniform(-0.01, 0.01) + steps * walk_mm, rng.uniform(-0.01, 0.01), rng.uniform(-0.003, 0.003))
        p["robot_scale_ppm"] = steps * scale_ppm
        p["robot_scale_about_mm"] = [0.0, 0.0]
        plan.append(p)
    return plan


MONITOR_CELL = {"record_clock_pin": '"smtcal-clock.out"'}
SCENARIOS["monitor_drift"] = {"program": MONITOR, "expect": "ok", "cell_add": MONITOR_CELL,
                              "monitor": {"baseline": 10, "start": 10, "walk_mm": 0.02, "scale_ppm": 25},
                              "cycles": drifting(17, 10, 0.02, 25)}
SCENARIOS["monitor_drift_long"] = {"program": MONITOR, "expect": "ok", "cell_add": MONITOR_CELL,
                                   "monitor": {"baseline": 20, "start": 25, "walk_mm": 0.005, "scale_ppm": 4},
                                   "cycles": drifting(60, 25, 0.005, 4)}

# Opt-in: what writing the record costs on the controller. No board: a
# program of smtcal_data, the nominal trips written into fixture 0's
# parameters, then loops of 200 calls each, timed with the clock HAL pin
# (#<_hal[smtcal-clock.out]>, read when the interpreter gets there): an empty
# loop, smtcal_record alone, smtcal_estimate (which writes its record too).
SCENARIOS["record_overhead"] = {"program": SIM, "expect": "overhead", "cell_add": MONITOR_CELL, "cycles": [],
                                "overhead_calls": 200}

# Boards that repeat within 0.05 mm and 0.02 deg of (0.2, -0.1, 0.05), as a
# fixture repeats: every scan after the first is latched where the last
# one predicts.
def repeating_boards(count, seed):
    rng = random.Random(seed)
    return [pose(0.2 + rng.uniform(-0.05, 0.05), -0.1 + rng.uniform(-0.05, 0.05), 0.05 + rng.uniform(-0.02, 0.02))
            for _ in range(count)]


# Opt-in: the steady state: eight boards that repeat within 0.05 mm and
# 0.02 deg, scanned in full (no predicted_window_mm) and predicted, side by
# side: the overhead per cycle and the pose's error.
SCENARIOS["scan_predicted"] = {"program": SIM, "expect": "ok", "cycles": repeating_boards(8, 46),
                               "variants": [{"name": "in-full", "what": "every scan in full",
                                             "cell": {"predicted_window_mm": 0}},
                                            {"name": "predicted", "what": "the example: predicted, 0.3 mm"}]}
# Opt-in: the trip latency against the speed of one-stage probing (one good board each).
for speed in (6, 12, 25, 50, 100):
    SCENARIOS[f"latency_{speed}mm_s"] = {"program": SIM, "expect": "ok",
                                         "cell": {"scan_speed_mm_s": speed, "latch_speed_mm_s": None},
                                         "cycles": [pose(0.3, -0.2, 0.1)]}


def log(text):
    print(text, flush=True)


def fail(text):
    log("FAILED: " + text)
    sys.exit(1)


def skip(text):
    log("SKIPPED: " + text)
    sys.exit(SKIP)


def run(argv, **kwargs):
    return subprocess.run(argv, capture_output=True, text=True, **kwargs)


# ------------------------------------------------------------------ can it start here?

def check_prerequisites():
    if os.geteuid() != 0:
        skip("LinuxCNC's uspace rtapi_app needs root here (setuid or RTAPI_UID as root); run as root")
    for tool in ("linuxcnc", "halcmd", "rtapi_app", "unshare", "timeout"):
        if shutil.which(tool) is None:
            skip(f"'{tool}' is not installed: install linuxcnc-uspace (tools/install-deps.sh)")
    probe = run(["/usr/bin/python3", "-c", "import linuxcnc, hal"])
    if probe.returncode != 0:
        skip("the Python module 'linuxcnc' is missing for /usr/bin/python3 (package linuxcnc-uspace): "
             + probe.stderr.strip().splitlines()[-1])
    ns = run(["unshare", "--pid", "--fork", "--kill-child", "--mount-proc", "--ipc", "--mount", "--net", "true"])
    if ns.returncode != 0:
        skip("new PID/IPC/mount/network namespaces are not allowed here (unshare: %s); LinuxCNC's shutdown would "
             "kill processes and remove shared memory outside the test" % ns.stderr.strip())


# ------------------------------------------------------------------ the machine

def derive_ini(work, program_dir, dry_run, display="driver.py", extra_hals=("marker-sensor.hal",)):
    """paper-cell.ini made headless, with the sensor HAL, a runtime folder of
    its own (`smtcal compile --ini` writes the runtime there) and then the
    program's own subroutines (a program compiled without --ini, the
    measuring programs; a folder that does not exist is skipped).
    `display`: the DISPLAY program (a file of this folder); `extra_hals`: HAL
    files loaded after the example's, in order (files of this folder, or
    paths of files the scenario wrote into `work`)."""
    lines = open(os.path.join(EXAMPLE, "paper-cell.ini")).read().splitlines()
    out, section = [], ""
    for line in lines:
        stripped = line.strip()
        if stripped.startswith("["):
            section = stripped
        key = stripped.split("=", 1)[0].strip() if "=" in stripped and not stripped.startswith("#") else ""
        if section == "[DISPLAY]" and key == "DISPLAY":
            line = "DISPLAY = " + os.path.join(work, display)
        elif section == "[DISPLAY]" and key in ("INTRO_GRAPHIC", "INTRO_TIME"):
            continue  # popimage needs X
        elif section == "[RS274NGC]" and key == "SUBROUTINE_PATH":
            line = "SUBROUTINE_PATH = " + os.path.join(work, "runtime") + ":" + os.path.join(program_dir, "subroutines")
            if dry_run:
                line = line.replace(" = ", " = " + os.path.join(program_dir, "dry-run") + ":")
            # The cycle record's clock (#<_hal[smtcal-clock.out]>, marker-sensor.hal).
            line += "\nHAL_PIN_VARS = 1"
        out.append(line)
        if section == "[HAL]" and key == "HALFILE":
            for hal in extra_hals:
                out.append("HALFILE = " + os.path.join(work, os.path.basename(hal)))
    ini = os.path.join(work, "sim.ini")
    # LinuxCNC reads nothing outside the scenario's folder (see work_root).
    for name in (display,) + tuple(extra_hals):
        if not os.path.isabs(name) and os.path.exists(os.path.join(HERE, name)):
            shutil.copy(os.path.join(HERE, name), work)
    open(ini, "w").write("\n".join(out) + "\n")
    for name in ("paper-cell.hal", "paper-cell.tbl", "paper-cell.var"):
        shutil.copy(os.path.join(EXAMPLE, name), work)
    return ini


MACHINE_NICE = -10


def start_linuxcnc(work, ini, plan_path, run_path, timeout_s, extra_env=None, modules=None):
    tmp = os.path.join(work, "tmp")
    os.makedirs(tmp, exist_ok=True)
    os.chmod(tmp, 0o1777)  # rtapi_app binds its socket as RTAPI_UID
    home = os.path.join(work, "home")
    os.makedirs(home, exist_ok=True)
    env = dict(os.environ, RTAPI_UID="65534", RTAPI_FIFO_PATH="/tmp/rtapi_fifo", HOME=home,
               SMTCAL_SIM_PLAN=plan_path, SMTCAL_SIM_RUN=run_path)
    env.update(extra_env or {})
    env.pop("DISPLAY", None)  # no X
    # Inside: a private /tmp (LinuxCNC's lock file and temporaries), then LinuxCNC.
    # `modules`: a folder of realtime modules seen as LinuxCNC's own
    # (rtapi_app loads only from /usr/lib/linuxcnc/modules), in this run only.
    inner = 'mount --bind "$0" /tmp && cd "$1" && exec linuxcnc -r "$2"'
    if modules:
        inner = 'mount --bind "$3" /usr/lib/linuxcnc/modules && ' + inner
    # At nice -10 (root): the servo thread runs at the normal priority without
    # a realtime kernel, and the machine's processes, the driver with them,
    # go ahead of a parallel CTest's load together.
    argv = ["timeout", "-k", "10", str(timeout_s + 60), "nice", "-n", str(MACHINE_NICE),
            "unshare", "--pid", "--fork", "--kill-child",
            "--mount-proc", "--ipc", "--mount", "sh", "-c", inner, tmp, work, ini, modules or ""]
    with open(os.path.join(work, "linuxcnc.log"), "w") as log_file:
        return subprocess.run(argv, env=env, stdout=log_file, stderr=subprocess.STDOUT).returncode


# ------------------------------------------------------------------ the example as shipped

# examples/linuxcnc/README.md, "Run it without a screen": the steps a user
# sends to linuxcncrsh (port 5007), homing included.
README_STEPS = ["hello EMC client 1.0", "set enable EMCTOO", "set set_wait done", "set estop off",
                "set machine on", "set mode manual", "set home -1", "set mode auto",
                "set open layers/layers.ngc", "set run"]

CLIENT = """
import socket, sys, time
steps = sys.argv[1].split("|")
for attempt in range(300):
    try:
        s = socket.create_connection(("127.0.0.1", 5007))
        break
    except OSError:
        time.sleep(0.1)
f = s.makefile("rw")
for step in steps:
    f.write(step + "\\r\\n")
    f.flush()
    time.sleep(1.0 if step in ("set home -1", "set run") else 0.2)
s.settimeout(0.5)
out, end = "", time.time() + 60
while time.time() < end and "marker scan" not in out and "Queue is not empty after probing" not in out:
    f.write("get error\\r\\n")
    f.flush()
    time.sleep(0.5)
    try:
        out += s.recv(65536).decode()
    except socket.timeout:
        pass
print(out)
f.write("shutdown\\r\\n")
f.flush()
"""


def run_linuxcnc(work, ini, plan_path, run_path, timeout_s, **kwargs):
    """Runs LinuxCNC with its driver (start_linuxcnc; kwargs go there) and
    returns the driver's record and the seconds LinuxCNC ran. Fails when a
    process of the run outlives it or the driver left no record; skips
    where LinuxCNC could not start."""
    began = time.monotonic()
    code = start_linuxcnc(work, ini, plan_path, run_path, timeout_s, **kwargs)
    machine_s = time.monotonic() - began
    left = leftover_processes("SMTCAL_SIM_PLAN=" + plan_path)
    if left:
        fail("processes of the run outlived it: " + "; ".join(left))
    if not os.path.exists(run_path):
        tail = open(os.path.join(work, "linuxcnc.log")).read()[-3000:]
        if "rtapi" in tail and ("Permission" in tail or "not permitted" in tail):
            skip("LinuxCNC could not start here:\n" + tail)
        fail(f"LinuxCNC ended (exit {code}) without the driver's record; its log:\n{tail}")
    return json.load(open(run_path)), machine_s


# LinuxCNC 2.9's own race (its issue 3650, the fix not released): after a
# probe move the task can read motion's status from before the move was
# queued, let the interpreter read on, and abort the program with this
# error. Without a realtime kernel, where the servo thread can be preempted
# mid-cycle, it came here once in a run whose driver preempted the servo
# thread (SCHED_FIFO), and not in 30 runs of limit_corners (5040 probe
# moves) with the machine at nice -10 (tests/linuxcnc-sim/README.md); it
# aborts the program during the scan, before the cycle places anything. A
# run it aborts says nothing about smtcal's program: the scenario runs the
# machine again, at most twice, and says so. Each run again starts from the
# state the first one started from (run_from_a_clean_slate): the raced run
# has written the cycle record, advanced the record's counters in the
# parameter file LinuxCNC rewrites at exit, and left its log and the
# driver's record; none of that may reach the next run's checks.
LINUXCNC_PROBE_RACE = "Queue is not empty after probing"
LINUXCNC_PROBE_RACE_RUNS = 3
BEFORE_RUN = ".before-run"  # the work folder as the first run found it


def set_aside_a_raced_run(work, run_number):
    """Moves every file the raced run wrote or changed into
    `raced-run<N>/` (kept for a look, read by no check) and puts back the
    files it changed as they were before the first run."""
    pristine = os.path.join(work, BEFORE_RUN)
    aside = os.path.join(work, f"raced-run{run_number}")
    for folder, dirs, files in os.walk(work, topdown=True):
        rel_folder = os.path.relpath(folder, work)
        if rel_folder == ".":
            dirs[:] = [d for d in dirs if d != BEFORE_RUN and not d.startswith("raced-run")]
        for name in files:
            rel = os.path.normpath(os.path.join(rel_folder, name))
            before = os.path.join(pristine, rel)
            if os.path.isfile(before) and filecmp.cmp(before, os.path.join(work, rel), shallow=False):
                continue
            os.renames(os.path.join(work, rel), os.path.join(aside, rel))
            if os.path.isfile(before):
                shutil.copy2(before, os.path.join(work, rel))
    left = [rel for rel in walk_files(pristine) if not os.path.exists(os.path.join(work, rel))]
    for rel in left:  # removed by the raced run
        os.makedirs(os.path.dirname(os.path.join(work, rel)), exist_ok=True)
        shutil.copy2(os.path.join(pristine, rel), os.path.join(work, rel))


def walk_files(root):
    return [os.path.normpath(os.path.join(os.path.relpath(folder, root), name))
            for folder, _, files in os.walk(root) for name in files]


def run_linuxcnc_past_its_probe_race(work, ini, plan_path, run_path, timeout_s):
    """run_linuxcnc, run again from a clean slate when LinuxCNC's own probe
    race aborted it. Fails naming the race when it aborted every run."""
    pristine = os.path.join(work, BEFORE_RUN)
    shutil.rmtree(pristine, ignore_errors=True)
    shutil.copytree(work, pristine, ignore=lambda folder, names: [
        n for n in names if folder == work and (n == BEFORE_RUN or n.startswith("raced-run"))])
    races = []
    for run_number in range(1, LINUXCNC_PROBE_RACE_RUNS + 1):
        record, machine_s = run_linuxcnc(work, ini, plan_path, run_path, timeout_s)
        raced = [m for m in record["messages"] if m["text"].strip() == LINUXCNC_PROBE_RACE]
        if not raced:
            if races:
                log(f"  run {run_number} ran without LinuxCNC's race, after {len(races)} run(s) it aborted "
                    f"({', '.join(races)}); their files are in raced-run*/, read by no check")
            shutil.rmtree(pristine, ignore_errors=True)
            return record, machine_s
        races.append(f"run {run_number} in cycle {raced[0]['cycle'] + 1} after {machine_s:.1f} s")
        set_aside_a_raced_run(work, run_number)
        if run_number == LINUXCNC_PROBE_RACE_RUNS:
            fail(f"LinuxCNC's own race ('{LINUXCNC_PROBE_RACE}', LinuxCNC issue 3650) aborted all "
                 f"{run_number} runs ({'; '.join(races)}): not a finding about smtcal's program, but a race "
                 f"that often is more than its rate here (tests/linuxcnc-sim/README.md); the runs' files are in "
                 f"{work}/raced-run*/")
        log(f"  LinuxCNC's own race ('{LINUXCNC_PROBE_RACE}', LinuxCNC issue 3650) aborted {races[-1]}: "
            f"its files set aside in raced-run{run_number}/, running the machine again from the same start")


def work_root(path):
    """Where the scenarios run. LinuxCNC runs with a private /tmp bound over
    the system's, which hides everything below /tmp: a build under /tmp (a
    clone there) runs its scenarios under /var/tmp instead, in a folder named
    after the build's."""
    path = os.path.abspath(path)
    if path != "/tmp" and not path.startswith("/tmp/"):
        return path
    digest = hashlib.sha1(path.encode()).hexdigest()[:12]
    return os.path.join("/var/tmp", "smtcal-linuxcnc-sim-%d" % os.getuid(), digest)


def headless_example(args):
    """paper-cell-headless.ini as shipped, driven through linuxcncrsh as the README says."""
    if shutil.which("ip") is None or shutil.which("linuxcncrsh") is None:
        skip("'ip' (iproute2) or 'linuxcncrsh' (linuxcnc-uspace) is not installed (tools/install-deps.sh)")
    work = os.path.join(work_root(args.work), args.scenario)
    want = "ERROR smtcal: marker scan of fixture Board failed check missing_trip: 8 trips missing"
    for run_number in range(1, LINUXCNC_PROBE_RACE_RUNS + 1):
        for old in [work] + [f"{work}.raced-run{n}" for n in range(1, LINUXCNC_PROBE_RACE_RUNS + 1)]:
            if run_number == 1 or old == work:
                shutil.rmtree(old, ignore_errors=True)
        result = run_headless_example(args, work)
        if want in result.stdout or LINUXCNC_PROBE_RACE not in result.stdout:
            break
        # LinuxCNC's own race aborted the program before the scan's verdict
        # (run_linuxcnc_past_its_probe_race): the whole folder set aside, the
        # next run made from nothing.
        os.rename(work, f"{work}.raced-run{run_number}")
        if run_number == LINUXCNC_PROBE_RACE_RUNS:
            fail(f"LinuxCNC's own race ('{LINUXCNC_PROBE_RACE}', LinuxCNC issue 3650) aborted all {run_number} "
                 f"runs; their folders are {work}.raced-run*")
        log(f"  LinuxCNC's own race ('{LINUXCNC_PROBE_RACE}', LinuxCNC issue 3650) aborted run {run_number}: "
            f"its folder set aside as {work}.raced-run{run_number}, running it again from nothing")
    if want not in result.stdout:
        log_text = open(os.path.join(work, "linuxcnc.log")).read()[-3000:] if os.path.exists(
            os.path.join(work, "linuxcnc.log")) else ""
        fail(f"expected '{want}' from linuxcncrsh; got:\n{result.stdout[-2000:]}{result.stderr}\n{log_text}")
    log("paper-cell-headless.ini as shipped: linuxcncrsh homed the machine and ran layers.ngc; with no sensor "
        "wired the first scan aborted:\n  " + next(l for l in result.stdout.splitlines() if "marker scan" in l))
    # The refused scan's record, written before the abort.
    begins, records = read_record_log(os.path.join(work, RECORD_FILE))
    if len(begins) != 1 or len(records) != 1 or records[0]["cycle"][1:5] != ["0", "1", "1", "1"] or \
            [t[4:] for t in records[0]["trips"]] != [["-", "-"]] * 8:
        fail(f"expected the record of one scan refused by missing_trip (all 8 trips missing), got {begins} {records}")
    log("  its record: " + " ".join(records[0]["cycle"]) + " (before the abort)")


def run_headless_example(args, work):
    """One run of the headless example in a new folder `work`: linuxcncrsh's output."""
    os.makedirs(work)
    for name in os.listdir(EXAMPLE):
        if name.startswith("paper-cell"):
            shutil.copy(os.path.join(EXAMPLE, name), work)
    # As examples/linuxcnc/README.md says: compiled against the machine's INI,
    # which is checked against the cell; the runtime goes where its
    # SUBROUTINE_PATH says.
    compiled = smtcal(["compile", EXAMPLE_PROGRAM, "--cell", CELL, "--target", "linuxcnc", "--ini",
                       os.path.join(work, "paper-cell-headless.ini"), "-o", os.path.join(work, "layers")],
                      args.smtcal)
    if compiled.returncode != 0:
        fail("smtcal compile: " + compiled.stderr)
    tmp = os.path.join(work, "tmp")
    os.makedirs(tmp)
    os.chmod(tmp, 0o1777)
    env = dict(os.environ, RTAPI_UID="65534", RTAPI_FIFO_PATH="/tmp/rtapi_fifo", HOME=work)
    env.pop("DISPLAY", None)
    # Its own network namespace too: linuxcncrsh listens on port 5007.
    inner = ('mount --bind "$0" /tmp && ip link set lo up && cd "$1" && '
             '{ linuxcnc paper-cell-headless.ini > linuxcnc.log 2>&1 & } && exec /usr/bin/python3 -c "$2" "$3"')
    result = run(["timeout", "-k", "10", "120", "unshare", "--pid", "--fork", "--kill-child", "--mount-proc",
                  "--ipc", "--mount", "--net", "sh", "-c", inner, tmp, work, CLIENT, "|".join(README_STEPS)],
                 env=env)
    return result


def leftover_processes(marker):
    """Processes still running with `marker` in their environment (none: the
    PID namespace took every process of the run with it)."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            if marker.encode() in open(f"/proc/{pid}/environ", "rb").read():
                found.append(pid + " " + open(f"/proc/{pid}/cmdline", "rb").read().replace(b"\0", b" ").decode())
        except OSError:
            pass
    return found


# ------------------------------------------------------------------ smtcal

def smtcal(args, binary, **kwargs):
    return run([binary] + args, **kwargs)


def trip_paths(binary, work):
    """The scan path of each trip T1..Tn, from `smtcal fixture` on a scan with no trips."""
    empty = os.path.join(work, "no-trips.csv")
    open(empty, "w").write("name,x_mm,y_mm,z_mm\n")
    result = smtcal(["fixture", "--cell", CELL, "--fixture", "Board", "--trips", empty, "--json"], binary)
    return [trip["path"] for trip in json.loads(result.stdout)["trips"]]


def scan_path_points(cell_text, fixture="Board"):
    """Each scan path's points in the base frame at the fixture's nominal
    pose (where the runtime drives them), by path name."""
    cell = tomllib.loads(cell_text)
    board = next(f for f in cell["fixture"] if f["name"] == fixture)
    a = math.radians(board.get("angle_deg", 0.0))
    ox, oy = board["origin_mm"]
    return {path["name"]: [(ox + math.cos(a) * x - math.sin(a) * y, oy + math.sin(a) * x + math.cos(a) * y)
                           for x, y in path["points_mm"]] for path in board["scan_path"]}


def trips_from_record(probes, record_trips, observer=""):
    """The trips a scan latched, by index, as the driver saw them: each trip
    the runtime's cycle record names is a probe move's result (the record
    keeps #5061/#5062 to 1e-10 mm, the driver stat.probed_position), the
    trips in the order of the probe moves. For a scan latched where the last
    one predicts (smtcal_probe_predicted.ngc), whose moves between trips and
    whose fallback to the full search make no fixed pattern."""
    trips = {}
    at = 0
    for k, trip in enumerate(record_trips):
        if trip[4:] == ["-", "-"]:
            continue
        x, y = float(trip[4]), float(trip[5])
        j = next((i for i in range(at, len(probes))
                  if abs(probes[i]["x"] - x) < 1e-9 and abs(probes[i]["y"] - y) < 1e-9), None)
        if j is None:
            fail(f"the record's T{k + 1} ({x}, {y}) is none of the probe results the driver saw after the "
                 f"previous trip's{observer}")
        trips[k] = probes[j]
        at = j + 1
    return trips


def trips_of_cycle(probes, paths, two_stage, path_points, observer=""):
    """The trips the runtime latched, by index: its probe moves in order, per
    path until the first move that did not trip (smtcal_probe_trips.ngc).
    With two stages a trip is three probe moves (find the edge, back over
    it, latch it), the last of them the trip.

    Whether a move tripped: the driver reads motion's flag in the status
    poll that shows the move's new result, and on a loaded host that poll
    can come after the next move began and the flag fell back. The runtime
    leaves a path at its first move that does not trip, so a move followed
    by another probe move on the same path (the nearest path's points: the
    markers are far apart) tripped whatever the flag read. `observer`: how
    the driver polled (its longest gap), for a failure."""
    def path_of(probe):
        return min(path_points, key=lambda name: min(math.dist((probe["x"], probe["y"]), point)
                                                     for point in path_points[name]))

    trips = {}
    at = 0
    index = 0
    for name in dict.fromkeys(paths):  # paths in order
        count = paths.count(name)
        for k in range(count):
            moves = probes[at:at + (3 if two_stage else 1)]
            at += len(moves)
            probed_on = at < len(probes) and path_of(probes[at]) == name
            if not moves or not (all(probe["tripped"] for probe in moves) or probed_on):
                break
            trips[index + k] = moves[-1]
        index += count
    if at != len(probes):
        fail(f"{len(probes)} probe moves, but the scan paths explain only {at}{observer}")
    return trips


def scan_overhead(cycle, scan_z):
    """The scan's overhead in a cycle (s), from the driver's position trace:
    from its first move (the first status that shows the machine moving
    after the board was clamped) to the first placement move (the first
    x-y move after the machine last stood at the scan height: the scan's
    final rise, then the estimate and the corrections in the interpreter,
    then the Jump to the first Pick). None without a scan."""
    trace = cycle.get("trace", [])
    if len(trace) < 2 or not cycle["probes"]:
        return None
    moved = next((s for s in trace[1:] if s[1:] != trace[0][1:]), None)
    at_scan = [i for i, s in enumerate(trace) if abs(s[3] - scan_z) < 1e-6]
    if moved is None or not at_scan:
        return None
    last = trace[at_scan[-1]]
    placing = next((s for s in trace[at_scan[-1] + 1:] if s[1:3] != last[1:3]), None)
    return None if placing is None else placing[0] - moved[0]


# The board's corners in its own frame: where the pose's error is measured.
BOARD_CORNERS = [(0.0, 0.0), (190.0, 0.0), (0.0, 90.0), (190.0, 90.0)]


def pose_error(scan, pose):
    """The largest distance between where the scan's FIX and the true pose put
    a corner of the board (mm)."""
    m = scan["fix"]["matrix"]
    a = math.radians(pose["angle_deg"])
    worst = 0.0
    for fx, fy in BOARD_CORNERS:
        estimated = (m[0][0] * fx + m[0][1] * fy + m[0][3], m[1][0] * fx + m[1][1] * fy + m[1][3])
        true = (pose["x_mm"] + math.cos(a) * fx - math.sin(a) * fy, pose["y_mm"] + math.sin(a) * fx + math.cos(a) * fy)
        worst = max(worst, math.dist(estimated, true))
    return worst


def write_trips(path, trips):
    with open(path, "w") as f:
        f.write("# the trips LinuxCNC latched (#5061, #5062, #5063), written by run_scenario.py\n")
        f.write("name,x_mm,y_mm,z_mm\n")
        for index in sorted(trips):
            p = trips[index]
            f.write(f"T{index + 1},{p['x']!r},{p['y']!r},{p['z']!r}\n")


# ------------------------------------------------------------------ the scenario

def cell_copy(work, scenario):
    """The cell a scenario runs: the example's, or a copy of it (and its
    tables, named relative to it) with its fixture replaced ("fixture": a
    file holding a [[fixture]] section), some keys changed ("cell") and some
    added to its last table ("cell_add")."""
    if "cell" not in scenario and "fixture" not in scenario and "cell_add" not in scenario:
        return CELL
    text = open(CELL).read()
    if "fixture" in scenario:
        start, end = text.index("[[fixture]]"), text.index("# --- the feeder banks")
        section = open(scenario["fixture"]).read()
        text = text[:start] + section[section.index("\n[[fixture]]") + 1:] + text[end:]
    for key, value in scenario.get("cell", {}).items():
        if value is None:  # the key removed
            text, n = re.subn(rf"(?m)^{key} = .*\n", "", text)
        else:
            text, n = re.subn(rf"(?m)^{key} = \S+", f"{key} = {value}", text)
        if n == 0 and key in ("latch_speed_mm_s", "predicted_window_mm") and value is not None:  # keys the cell may lack
            text, n = re.subn(r"(?m)^(scan_speed_mm_s = .*)$", rf"\1\n{key} = {value}", text)
        if n != 1:
            fail(f"cannot set {key} in a copy of the cell file")
    for key, value in scenario.get("cell_add", {}).items():  # keys added to its last table ([linuxcnc])
        text += f"{key} = {value}\n"
    cell_dir = os.path.join(work, "cell")
    os.makedirs(cell_dir)
    for name in os.listdir(os.path.dirname(CELL)):
        if name.endswith("-table.csv"):
            shutil.copy(os.path.join(os.path.dirname(CELL), name), cell_dir)
    cell = os.path.join(cell_dir, os.path.basename(CELL))
    open(cell, "w").write(text)
    return cell


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--smtcal", required=True)
    parser.add_argument("--checker", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("scenario", choices=sorted(SCENARIOS) + ["headless_example"])
    args = parser.parse_args()
    check_prerequisites()
    if args.scenario == "headless_example":
        return headless_example(args)
    scenario = SCENARIOS[args.scenario]
    started = time.monotonic()
    work = os.path.join(work_root(args.work), args.scenario)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    if "variants" not in scenario:
        run_machine(args, scenario, work)
        log(f"scenario {args.scenario}: passed in {time.monotonic() - started:.1f} s")
        return
    # Several scans of the same boards, one machine run each, side by side.
    rows = []
    for variant in scenario["variants"]:
        variant_work = os.path.join(work, variant["name"])
        os.makedirs(variant_work)
        log(f"--- {variant['name']}: {variant['what']}")
        run = dict(scenario, **variant)
        measured = run_machine(args, run, variant_work)
        rows.append((variant, measured))
    log(f"scan overhead per cycle (first scan move to first placement move) and board pose error (the largest "
        f"distance of a board corner from where the true pose puts it), {len(scenario['cycles'])} boards each:")
    log(f"  {'scan':<28} {'overhead s (mean, max)':<24} {'pose error mm (mean, max)':<26} verify's scan s")
    for variant, measured in rows:
        overheads = [m["overhead_s"] for m in measured["cycles"] if m["overhead_s"] is not None]
        errors = [m["pose_error_mm"] for m in measured["cycles"]]
        log(f"  {variant['name']:<28} {sum(overheads) / len(overheads):6.3f} {max(overheads):6.3f}"
            f"{'':11} {sum(errors) / len(errors):7.4f} {max(errors):7.4f}{'':11} {measured['verify_scan_s']:.3f}")
    log(f"scenario {args.scenario}: passed in {time.monotonic() - started:.1f} s")


def verify_scan_seconds(args, program, cell):
    """verify's estimate of the scan's time in the program's cycle."""
    return verify_scan(args, program, cell).get("scan_s", float("nan"))


def verify_scan(args, program, cell):
    """verify's figures of the scan in the program's cycle: scan_s (every
    cycle after the first), first_scan_s, scan_floor_s."""
    report = smtcal(["verify", program, "--cell", cell, "--json"], args.smtcal)
    cycles = json.loads(report.stdout).get("cycles", []) if report.stdout else []
    return cycles[0] if cycles else {}


def predicted_probe_moves(args, cell):
    """The probe moves of a scan latched where the last one predicts, every
    trip in its window (`smtcal scan report`'s model of the runtime), or
    None when the fixture predicts nothing (predicted_window_mm 0)."""
    report = smtcal(["scan", "report", "--cell", cell, "--json"], args.smtcal)
    if report.returncode != 0:
        fail("smtcal scan report: " + report.stderr)
    predicted = json.loads(report.stdout)["time"]["predicted"]
    return predicted["probe_moves"] if predicted["window_mm"] > 0 else None


def run_machine(args, scenario, work):
    """One run of LinuxCNC on the scenario's boards, checked; what it measured."""
    cell = cell_copy(work, scenario)
    program_dir = os.path.join(work, "program")
    ini = derive_ini(work, program_dir, False)
    # Compiled against the machine's INI: it and its HAL files are checked
    # against the cell, and the runtime goes where its SUBROUTINE_PATH says.
    compiled = smtcal(["compile", scenario["program"], "--cell", cell, "--target", "linuxcnc", "--ini", ini,
                       "-o", program_dir] + (["--dry-run-probe"] if scenario.get("dry_run") else []), args.smtcal)
    if compiled.returncode != 0:
        fail("smtcal compile: " + compiled.stderr)
    if scenario.get("dry_run"):
        # The mistake this scenario makes: the dry-run folder put first on
        # the machine's path after compiling (compiled against that path,
        # smtcal would write the runtime into the dry-run folder).
        ini = derive_ini(work, program_dir, True)
    stem = os.path.splitext(os.path.basename(scenario["program"]))[0]
    # Where the robot really puts the sensor around each marker (the cell's tables there, affine).
    model = run([args.checker, "--cell", cell, "--sensor-model"])
    if model.returncode != 0:
        fail("the checker's sensor model: " + model.stderr)
    sensor_models = json.loads(model.stdout)
    if sorted(m["marker"] for m in sensor_models) != [1, 2]:
        fail(f"the sensor HAL has two markers, one scan path each; the cell's paths scan {sensor_models}")
    sensor_models.sort(key=lambda m: m["marker"])  # the HAL's units: marker 1's, then marker 2's
    plan = {"program": os.path.join(program_dir, stem + ".ngc"), "cycles": scenario["cycles"],
            "sensor_models": sensor_models, "timeout_s": 120 + 100 * len(scenario["cycles"])}
    if scenario["expect"] == "overhead":
        plan["program"] = write_overhead_program(args, work, cell, scenario["overhead_calls"])
    plan_path = os.path.join(work, "plan.json")
    json.dump(plan, open(plan_path, "w"), indent=1)
    run_path = os.path.join(work, "run.json")
    record, machine_s = run_linuxcnc_past_its_probe_race(work, ini, plan_path, run_path, plan["timeout_s"])
    log(f"  {os.path.basename(scenario['program'])}, {len(record['cycles'])} cycle(s), "
        f"LinuxCNC ran {machine_s:.1f} s (ready after {record['times'].get('ready_s', 0):.1f} s), "
        f"run ended: {record['end']}")
    if record["end"].startswith("timeout"):
        fail(record["end"])

    if scenario["expect"] == "dry_run_refused":
        check_dry_run_refused(record)
        return {"cycles": []}
    if scenario["expect"] == "overhead":
        report_overhead(record, work, scenario["overhead_calls"])
        return {"cycles": []}

    # Per cycle: the latched trips, smtcal fixture's verdict on them.
    paths = trip_paths(args.smtcal, work)
    cell_text = open(cell).read()
    two_stage = re.search(r"(?m)^latch_speed_mm_s = ", cell_text) is not None
    scan_z = float(re.search(r"(?m)^scan_z_mm = (\S+)", cell_text).group(1))
    path_points = scan_path_points(cell_text)
    predicted_moves = predicted_probe_moves(args, cell)
    records = read_record_log(os.path.join(work, RECORD_FILE))[1] if predicted_moves else []
    measured = []
    previous = None
    verdicts = []
    check_cycles = []
    latched = []
    for n, cycle in enumerate(record["cycles"]):
        gap_ms = cycle.get("poll_gap_max_s", float("nan")) * 1000
        observer = (f" (the driver's longest gap between two status polls in this cycle {gap_ms:.1f} ms: a probe "
                    f"result can show for as little as 15 ms)")
        # Every scan after the first accepted one is latched where that one
        # predicts (the cell's predicted_window_mm): its trips are the
        # record's, found among the probe results.
        predicted = predicted_moves is not None and n > 0
        if predicted:
            if n >= len(records):
                fail(f"cycle {n + 1}: the runtime recorded {len(records)} scans")
            trips = trips_from_record(cycle["probes"], records[n]["trips"], observer)
        else:
            trips = trips_of_cycle(cycle["probes"], paths, two_stage, path_points, observer)
        trips_csv = os.path.join(work, f"cycle{n + 1}-trips.csv")
        write_trips(trips_csv, trips)
        scan_json = os.path.join(work, f"cycle{n + 1}-scan.json")
        argv = ["fixture", "--cell", cell, "--fixture", "Board", "--trips", trips_csv, "--json"]
        if previous:
            argv += ["--previous", previous]
        scan = smtcal(argv, args.smtcal)
        if scan.returncode not in (0, 1) or not scan.stdout:
            fail(f"smtcal fixture on cycle {n + 1}: exit {scan.returncode}\n{scan.stderr}")
        open(scan_json, "w").write(scan.stdout)
        verdict = json.loads(scan.stdout)
        verdicts.append(verdict)
        if verdict["ok"]:
            previous = scan_json
        overhead = scan_overhead(cycle, scan_z)
        if verdict["ok"]:
            error = pose_error(verdict, cycle["pose"])
            moves = len(cycle["probes"])
            search = ("searched in full" if not predicted else "latched where the last scan predicts"
                      if moves == predicted_moves else "a path searched in full after its prediction failed")
            log(f"  cycle {n + 1}: scan overhead {overhead if overhead is None else round(overhead, 3)} s, "
                f"board pose error {error:.4f} mm, {moves} probe moves ({search}), driver's longest poll gap "
                f"{gap_ms:.1f} ms")
            measured.append({"overhead_s": overhead, "pose_error_mm": error, "probe_moves": moves,
                             "predicted": predicted and moves == predicted_moves})
        places = [e for e in record["vacuum"] if e["cycle"] == n and not e["on"]]
        check_cycles.append({"pose": cycle["pose"], "trips": {str(k): [p["x"], p["y"]] for k, p in trips.items()},
                             "scan": scan_json, "places": [e["position"] + [e["velocity"]] for e in places],
                             "robot_scale_ppm": cycle["pose"].get("robot_scale_ppm", 0.0),
                             "robot_scale_about_mm": cycle["pose"].get("robot_scale_about_mm", [0.0, 0.0])})
        latched.append(trips)
    check_input = os.path.join(work, "check.json")
    json.dump({"cycles": check_cycles}, open(check_input, "w"), indent=1)

    # The machine against smtcal's C++: trips, places, landing.
    servo_period_s = int(re.search(r"(?m)^SERVO_PERIOD = (\d+)", open(ini).read()).group(1)) * 1e-9
    checked = run([args.checker, "--program", scenario["program"], "--cell", cell, "--run", check_input,
                   "--servo-period-s", repr(servo_period_s)])
    log(checked.stdout.rstrip())
    if checked.returncode != 0:
        fail("the checker found differences:\n" + checked.stderr)

    # The verdicts: every cycle but a refused last one ok, and the runtime agreed.
    aborts = [m for m in record["messages"] if "marker scan of fixture" in m["text"]]
    for n, verdict in enumerate(verdicts[:-1]):
        if not verdict["ok"]:
            fail(f"cycle {n + 1}: smtcal fixture refused the scan ({verdict['fault']}) but the runtime went on")
    last = verdicts[-1] if verdicts else None
    if scenario["expect"] == "ok":
        if last is None or not last["ok"] or aborts:
            fail(f"expected every scan to pass; last verdict {last and last['fault']}, aborts {aborts}")
        if len(record["cycles"]) != len(scenario["cycles"]):
            fail(f"{len(record['cycles'])} cycles ran of {len(scenario['cycles'])}")
    else:
        check_refusal(scenario, record, last, aborts)
    check_record_log(os.path.join(work, RECORD_FILE), latched, verdicts, "monitor" in scenario)
    if "monitor" in scenario:
        check_monitor(args, scenario, cell, os.path.join(work, RECORD_FILE))
    verify = verify_scan(args, scenario["program"], cell)
    report_steady_state(measured, verify)
    return {"cycles": measured, "verify_scan_s": verify.get("scan_s", float("nan")), "verify": verify}


def report_steady_state(measured, verify):
    """The scans latched where predicted against those searched in full and
    against the floor verify states for the program's cycle."""
    floor = verify.get("scan_floor_s")
    for kind, rows in (("latched where predicted", [m for m in measured if m.get("predicted")]),
                       ("searched in full", [m for m in measured if not m.get("predicted")])):
        overheads = [m["overhead_s"] for m in rows if m["overhead_s"] is not None]
        if not overheads:
            continue
        mean = sum(overheads) / len(overheads)
        ratio = f", {mean / floor:.2f} x the floor of {floor:.3f} s (verify)" if floor else ""
        log(f"  {kind}: {len(overheads)} scan(s), overhead mean {mean:.3f} s, max {max(overheads):.3f} s{ratio}; "
            f"pose error max {max(m['pose_error_mm'] for m in rows):.4f} mm")


# ------------------------------------------------------------------ the cycle record

RECORD_FILE = "paper-cell-cycles.log"  # paper.cell.toml's [linuxcnc] record_file, in the folder LinuxCNC runs in
CHECKS = ["missing_trip", "trip_window", "degenerate", "length_l1", "length_l2", "squareness", "line_residual",
          "nominal_shift", "nominal_rotation", "cycle_shift", "cycle_rotation"]


def read_record_log(path):
    """The records of a log (docs/monitor.md), as lists of fields: a record
    is its cycle line, its checks line and its trip lines."""
    begins, records = [], []
    for line in open(path):
        fields = line.split()
        if not fields:
            continue
        if fields[0] == "smtcal-record":
            begins.append(fields)
        elif fields[0] == "cycle":
            records.append({"cycle": fields, "checks": None, "trips": []})
        elif fields[0] == "checks" and records:
            records[-1]["checks"] = fields
        elif fields[0] == "trip" and records:
            records[-1]["trips"].append(fields)
        else:
            fail(f"{path}: a line of no record: {line!r}")
    return begins, records


def check_record_log(path, latched, verdicts, clock):
    """One record per scan, each what `smtcal fixture` made of the trips
    LinuxCNC latched: the trips to 1e-9 mm (the runtime writes millionths
    and e-6, since LinuxCNC prints a number below 1e-4 as 0), the verdict,
    S1..S3 and every check's value (to the 6 decimals smtcal fixture --json
    prints: a small value recorded as 0 would differ)."""
    if not os.path.exists(path):
        fail(f"the runtime wrote no cycle record ({path})")
    begins, records = read_record_log(path)
    if len(begins) != 1 or begins[0][1] != "2" or "fixtures=Board:8" not in begins[0]:
        fail(f"expected one begin line of format 2 naming Board:8, got {begins}")
    if len(records) != len(verdicts):
        fail(f"{len(records)} records for {len(verdicts)} scans")
    worst = 0.0
    for n, (rec, verdict, trips) in enumerate(zip(records, verdicts, latched)):
        c = rec["cycle"]
        status = 0 if verdict["ok"] else CHECKS.index(verdict["fault"]) + 1
        if c[1:4] != ["0", str(n + 1), str(status)] or rec["checks"] is None or len(rec["trips"]) != 8:
            fail(f"record {n + 1}: {c} (want fixture 0, cycle {n + 1}, status {status}), {len(rec['trips'])} trips")
        if (c[5] == "-") == clock:
            fail(f"record {n + 1}: time {c[5]}, the clock {'was' if clock else 'was not'} configured")
        for k, trip in enumerate(rec["trips"]):
            if k not in trips:
                if trip[4:] != ["-", "-"]:
                    fail(f"record {n + 1}: T{k + 1} was not latched but is recorded at {trip[4:]}")
                continue
            worst = max(worst, abs(float(trip[4]) - trips[k]["x"]), abs(float(trip[5]) - trips[k]["y"]))
        if verdict["s_mm"] is None:
            if c[6:] != ["-"] * 6:
                fail(f"record {n + 1}: S1..S3 {c[6:]} for a scan without a pose")
        else:
            got = [float(v) for v in c[6:]]
            want = [v for s in verdict["s_mm"] for v in s]
            if max(abs(a - b) for a, b in zip(got, want)) > 2e-6:  # smtcal fixture --json: 6 decimals
                fail(f"record {n + 1}: S1..S3 {got}, smtcal fixture {want}")
        for k, check in enumerate(verdict["checks"]):
            value = rec["checks"][3 + k]
            if not check["evaluated"]:
                if value != "-":
                    fail(f"record {n + 1}: check {check['name']} did not run but is recorded as {value}")
            elif value == "-" or abs(float(value) - check["value"]) > 2e-6:
                fail(f"record {n + 1}: check {check['name']} recorded {value}, smtcal fixture {check['value']}")
    if worst > 1e-9:
        fail(f"a recorded trip is {worst} mm from what LinuxCNC latched (the record keeps 1e-10)")
    log(f"  cycle record: {len(records)} records, one per scan, each smtcal fixture's verdict and values; trips "
        f"within {worst:.1e} mm of what LinuxCNC latched ({os.path.getsize(path)} bytes)")


def check_monitor(args, scenario, cell, log_path):
    """`smtcal monitor` on the run's log finds both drifts, names them, and
    alarms before the drifting scale puts the far corner's parts out of
    tolerance."""
    m = scenario["monitor"]
    result = smtcal(["monitor", log_path, "--cell", cell, "--baseline", str(m["baseline"]), "--json"], args.smtcal)
    if result.returncode != 4:
        fail(f"smtcal monitor: exit {result.returncode}, expected 4 (out of control)\n{result.stdout}{result.stderr}")
    report = json.loads(result.stdout)
    board = report["fixtures"][0]
    findings = {f["kind"]: f for f in board["findings"]}
    for kind in ("fixture_moving", "robot_scale"):
        if kind not in findings:
            fail(f"smtcal monitor did not find {kind}: {[f['kind'] for f in board['findings']]}")
    corner = board["far_corner"]
    margin_um = corner["tolerance_um"] - corner["budget_um"]
    # The true scale error reaches the far corner's margin at this cycle.
    true_out = m["start"] + margin_um / (corner["um_per_ppm"] * m["scale_ppm"])
    scale = findings["robot_scale"]
    walk = findings["fixture_moving"]
    predicted = board["scans"] + scale["scans_to_limit"] if scale["scans_to_limit"] is not None else None
    log(f"  smtcal monitor: out of control; fixture_moving alarm at scan {walk['alarm_scan']} (drift from cycle "
        f"{m['start'] + 1}, began about scan {walk['change_scan']}); robot_scale alarm at scan "
        f"{scale['alarm_scan']} (began about scan {scale['change_scan']}), far corner "
        f"({corner['x_mm']}, {corner['y_mm']}) in {corner['region']}: {scale['now_um']} µm now of a "
        f"{margin_um:.1f} µm margin, out of tolerance at scan {predicted and round(predicted, 1)} predicted, "
        f"{true_out:.1f} true")
    for line in scale["explanation"] + walk["explanation"]:
        log("    " + line)
    if scale["alarm_scan"] >= true_out:
        fail(f"the robot_scale alarm (scan {scale['alarm_scan']}) came after the parts at the far corner left "
             f"tolerance (scan {true_out:.1f})")
    if predicted is None or predicted <= scale["alarm_scan"]:
        fail(f"the predicted scan at which parts leave tolerance ({predicted}) is not after the alarm")


def write_overhead_program(args, work, cell, calls):
    """The timing program of record_overhead (SCENARIOS)."""
    empty = os.path.join(work, "no-trips.csv")
    open(empty, "w").write("name,x_mm,y_mm\n")
    scan = json.loads(smtcal(["fixture", "--cell", cell, "--fixture", "Board", "--trips", empty, "--json"],
                             args.smtcal).stdout)
    lines = ["G21 G90 G17 G94", "o<smtcal_data> call", "#37 = 1 (a failed check is recorded, no abort)"]
    for i, trip in enumerate(scan["trips"]):
        x, y = trip["nominal_mm"]
        lines += [f"#[#[#[#35 + 0] + 30] + {2 * i}] = {x!r}", f"#[#[#[#35 + 0] + 30] + {2 * i + 1}] = {y!r}",
                  f"#[#[#[#35 + 0] + 31] + {i}] = 1"]
    lines.append("o<smtcal_estimate> call [0]")
    clock = "#<_hal[smtcal-clock.out]>"
    for n, body in enumerate(["", "o<smtcal_record> call [0]", "o<smtcal_estimate> call [0]"]):
        lines += [f"#<t{n}> = {clock}", "#<n> = 0", f"o{900 + n} while [#<n> LT {calls}]"]
        if body:
            lines.append("  " + body)
        lines += ["  #<n> = [#<n> + 1]", f"o{900 + n} endwhile"]
    lines += [f"#<t3> = {clock}",
              "(DEBUG,overhead %.6f#<t0> %.6f#<t1> %.6f#<t2> %.6f#<t3>)", "M2"]
    path = os.path.join(work, "overhead.ngc")
    open(path, "w").write("\n".join(lines) + "\n")
    return path


def report_overhead(record, work, calls):
    """The seconds each loop took, per call: the record alone, the scan's
    estimate with its record."""
    found = [m["text"] for m in record["messages"] if m["text"].startswith("overhead ")]
    if not found:
        fail(f"the timing program printed nothing; messages {record['messages']}")
    t = [float(v) for v in found[0].split()[1:]]
    loop, rec, estimate = ((t[k + 1] - t[k]) / calls for k in range(3))
    lines = sum(1 for _ in open(os.path.join(work, RECORD_FILE)))
    log(f"  per call on LinuxCNC's task (the clock's resolution is one servo period, 1 ms, over {calls} calls): "
        f"empty loop {loop * 1e3:.3f} ms, smtcal_record {(rec - loop) * 1e3:.3f} ms, smtcal_estimate with its "
        f"record {(estimate - loop) * 1e3:.3f} ms ({lines} lines logged)")


def check_dry_run_refused(record):
    texts = [m["text"] for m in record["messages"]]
    wanted = "smtcal: the dry-run probe file is on this machine's subroutine path"
    if not any(t.startswith(wanted) for t in texts):
        fail(f"expected the dry-run probe file to abort on the machine; messages: {texts}")
    probes = sum(len(c["probes"]) for c in record["cycles"])
    if probes or record["vacuum"]:
        fail(f"the machine moved the sensor ({probes} probe moves) or the valve ({record['vacuum']})")
    log(f"  refused: {texts[0]}")


def check_refusal(scenario, record, verdict, aborts):
    expect = scenario["expect"]
    if verdict is None or verdict["ok"]:
        fail(f"expected the last scan to fail {expect}; smtcal fixture accepted it")
    if verdict["fault"] != expect:
        fail(f"expected the last scan to fail {expect}; smtcal fixture says {verdict['fault']}")
    if len(aborts) != 1:
        fail(f"expected one abort, got {aborts}")
    text = aborts[0]["text"]
    if not text.startswith("smtcal: marker scan of fixture Board failed check " + expect + ":"):
        fail(f"the abort does not name the fixture and the check {expect} (or has a leading space): {text!r}")
    check = next(c for c in verdict["checks"] if c["name"] == expect)
    if expect == "missing_trip":
        value = f"{round(check['value'])} trips missing, the first {check['trip']},"
    else:
        value = f"{check['value']:.4f}"
    if value not in text:
        fail(f"the abort's value differs from smtcal fixture's ({value}): {text!r}")
    log(f"  refused: {text}")
    log(f"  smtcal fixture: {verdict['message']}")
    # Nothing of the refused cycle was placed: the valve did not change after its scan began.
    refused = len(record["cycles"]) - 1
    probes = record["cycles"][refused]["probes"]
    scan_began = record["cycles"][refused]["clamped_s"]
    late = [e for e in record["vacuum"] if e["t"] >= scan_began]
    if late:
        fail(f"the vacuum valve changed after the refused scan began (at {scan_began} s): {late}")
    if record["final_dout"]["8"]:
        fail("the vacuum valve is still on after the abort")
    log(f"  {len(probes)} probe moves in the refused scan; no vacuum change after it began; valve off")


if __name__ == "__main__":
    main()
