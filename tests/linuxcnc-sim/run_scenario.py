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
#
# Exit 0: passed; 1: failed; 77: skipped (LinuxCNC or namespaces cannot
# start here; the message says why).
import argparse
import hashlib
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

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


SIM = os.path.join(HERE, "sim.place")
EXAMPLE_PROGRAM = os.path.join(SOURCE, "examples", "paper-cell", "layers.place")

# expect: "ok" (every cycle places), or the check the last cycle's scan fails.
# The paper cell's V paths cross marker 2's edge p3 1 mm from its corner
# (T8 at y 83 of the board, the corner at 82) and marker 1's p2 1 mm from
# its corner (T4 at y 7): a board about 0.6 mm off in the wrong direction
# already puts a trip on the wrong edge (line_residual). The good poses stay
# inside that; the cycle_shift scenario needs a jump of more than
# max_shift_mm = 2 mm between two boards the scan can still measure, so it
# runs a copy of the cell held to 0.8 mm.
SCENARIOS = {
    "good_boards": {"program": SIM, "expect": "ok",
                    "cycles": [pose(0.3, -0.2, 0.1), pose(-0.6, 0.45, -0.2), pose(-0.2, 0.4, 0.25)]},
    "missing_board": {"program": SIM, "expect": "missing_trip", "cycles": [pose(present=False)]},
    "shifted_board": {"program": SIM, "expect": "trip_window", "cycles": [pose(2.2, 0.0)]},
    "rotated_board": {"program": SIM, "expect": "nominal_rotation", "cycles": [pose(turn_deg=-0.6)]},
    "cycle_shift": {"program": SIM, "expect": "cycle_shift", "cell": {"max_shift_mm": 0.8},
                    "cycles": [pose(-0.45, 0.3), pose(0.45, -0.3)]},
    "cycle_rotation": {"program": SIM, "expect": "cycle_rotation",
                       "cycles": [pose(turn_deg=-0.3), pose(turn_deg=0.25)]},
    # The dry-run probe file (compile --dry-run-probe) first on the machine's
    # path by mistake: it must abort before the first move.
    "dry_run_on_machine": {"program": SIM, "expect": "dry_run_refused", "dry_run": True, "cycles": [pose()]},
    # Opt-in (the linuxcnc-sim-full target): the shipped example, 40 parts a
    # cycle, three boards.
    "example_three_boards": {"program": EXAMPLE_PROGRAM, "expect": "ok",
                             "cycles": [pose(0.4, -0.3, 0.15), pose(-0.5, 0.2, -0.25), pose(0.1, 0.3, 0.05)]},
}
# Opt-in: the trip latency against the scan speed (one good board each).
for speed in (6, 12, 25, 50, 100):
    SCENARIOS[f"latency_{speed}mm_s"] = {"program": SIM, "expect": "ok", "cell": {"scan_speed_mm_s": speed},
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
    """paper-cell.ini made headless, with the sensor HAL and the program's subroutines.
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
            line = "SUBROUTINE_PATH = " + os.path.join(program_dir, "subroutines")
            if dry_run:
                line = line.replace(" = ", " = " + os.path.join(program_dir, "dry-run") + ":")
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
    argv = ["timeout", "-k", "10", str(timeout_s + 60), "unshare", "--pid", "--fork", "--kill-child",
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
while time.time() < end and "marker scan" not in out:
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
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    for name in os.listdir(EXAMPLE):
        if name.startswith("paper-cell"):
            shutil.copy(os.path.join(EXAMPLE, name), work)
    compiled = smtcal(["compile", EXAMPLE_PROGRAM, "--cell", CELL, "--target", "linuxcnc", "-o",
                       os.path.join(work, "layers")], args.smtcal)
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
    want = "ERROR smtcal: marker scan of fixture Board failed check missing_trip: 8 trips missing"
    if want not in result.stdout:
        log_text = open(os.path.join(work, "linuxcnc.log")).read()[-3000:] if os.path.exists(
            os.path.join(work, "linuxcnc.log")) else ""
        fail(f"expected '{want}' from linuxcncrsh; got:\n{result.stdout[-2000:]}{result.stderr}\n{log_text}")
    log("paper-cell-headless.ini as shipped: linuxcncrsh homed the machine and ran layers.ngc; with no sensor "
        "wired the first scan aborted:\n  " + next(l for l in result.stdout.splitlines() if "marker scan" in l))


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


def trips_of_cycle(probes, paths):
    """The trips the runtime latched, by index: its probe moves in order, per
    path until the first move that did not trip (smtcal_probe_trips.ngc)."""
    trips = {}
    at = 0
    index = 0
    for name in dict.fromkeys(paths):  # paths in order
        count = paths.count(name)
        for k in range(count):
            if at >= len(probes):
                break
            probe = probes[at]
            at += 1
            if not probe["tripped"]:
                break
            trips[index + k] = probe
        index += count
    if at != len(probes):
        fail(f"{len(probes)} probe moves, but the scan paths explain only {at}")
    return trips


def write_trips(path, trips):
    with open(path, "w") as f:
        f.write("# the trips LinuxCNC latched (#5061, #5062, #5063), written by run_scenario.py\n")
        f.write("name,x_mm,y_mm,z_mm\n")
        for index in sorted(trips):
            p = trips[index]
            f.write(f"T{index + 1},{p['x']!r},{p['y']!r},{p['z']!r}\n")


# ------------------------------------------------------------------ the scenario

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
    cell = CELL
    if "cell" in scenario:
        # A copy of the cell (and its tables, named relative to it) with some keys changed.
        text = open(CELL).read()
        for key, value in scenario["cell"].items():
            text, n = re.subn(rf"(?m)^{key} = \S+", f"{key} = {value}", text)
            if n != 1:
                fail(f"cannot set {key} in a copy of the cell file")
        cell_dir = os.path.join(work, "cell")
        os.makedirs(cell_dir)
        for name in os.listdir(os.path.dirname(CELL)):
            if name.endswith("-table.csv"):
                shutil.copy(os.path.join(os.path.dirname(CELL), name), cell_dir)
        cell = os.path.join(cell_dir, os.path.basename(CELL))
        open(cell, "w").write(text)
    program_dir = os.path.join(work, "program")
    compiled = smtcal(["compile", scenario["program"], "--cell", cell, "--target", "linuxcnc", "-o", program_dir]
                      + (["--dry-run-probe"] if scenario.get("dry_run") else []), args.smtcal)
    if compiled.returncode != 0:
        fail("smtcal compile: " + compiled.stderr)
    stem = os.path.splitext(os.path.basename(scenario["program"]))[0]
    ini = derive_ini(work, program_dir, scenario.get("dry_run", False))
    # Where the robot really puts the sensor around each marker (the cell's tables there, affine).
    model = run([args.checker, "--cell", cell, "--sensor-model"])
    if model.returncode != 0:
        fail("the checker's sensor model: " + model.stderr)
    sensor_models = json.loads(model.stdout)
    if len(sensor_models) != 2:
        fail(f"the sensor HAL has two markers; the cell's fixture has {len(sensor_models)} scan paths")
    plan = {"program": os.path.join(program_dir, stem + ".ngc"), "cycles": scenario["cycles"],
            "sensor_models": sensor_models, "timeout_s": 120 + 100 * len(scenario["cycles"])}
    plan_path = os.path.join(work, "plan.json")
    json.dump(plan, open(plan_path, "w"), indent=1)
    run_path = os.path.join(work, "run.json")
    record, machine_s = run_linuxcnc(work, ini, plan_path, run_path, plan["timeout_s"])
    log(f"scenario {args.scenario}: {os.path.basename(scenario['program'])}, {len(record['cycles'])} cycle(s), "
        f"LinuxCNC ran {machine_s:.1f} s (ready after {record['times'].get('ready_s', 0):.1f} s), "
        f"run ended: {record['end']}")
    if record["end"].startswith("timeout"):
        fail(record["end"])

    if scenario["expect"] == "dry_run_refused":
        check_dry_run_refused(record)
        log(f"scenario {args.scenario}: passed in {time.monotonic() - started:.1f} s")
        return

    # Per cycle: the latched trips, smtcal fixture's verdict on them.
    paths = trip_paths(args.smtcal, work)
    previous = None
    verdicts = []
    check_cycles = []
    for n, cycle in enumerate(record["cycles"]):
        trips = trips_of_cycle(cycle["probes"], paths)
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
        places = [e for e in record["vacuum"] if e["cycle"] == n and not e["on"]]
        check_cycles.append({"pose": cycle["pose"], "trips": {str(k): [p["x"], p["y"]] for k, p in trips.items()},
                             "scan": scan_json, "places": [e["position"] + [e["velocity"]] for e in places]})
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
    log(f"scenario {args.scenario}: passed in {time.monotonic() - started:.1f} s")


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
