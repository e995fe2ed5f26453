#!/usr/bin/python3
# run_measure.py - the measurement scenarios of the LinuxCNC simulation
# (README.md, "Measuring"): smtcal's measuring programs run on LinuxCNC's
# real motion controller with a modelled robot (smtcal_robot_model.comp: a
# known smooth error field and backlash, in the servo thread) and the
# measuring device of each kind; the tables built from their logs are
# judged against the model's field, and (the loop) a program compiled with
# them is run on the same robot and every part judged where it really lands.
#
#   run_measure.py --smtcal BIN --model SO --work DIR SCENARIO
#
# 1. The cell: examples/paper-cell/paper.cell.toml with the robot's final
#    approach and a [measure] table for the scenario's device, its tables
#    not there yet (a cell from scratch).
# 2. smtcal measure plan, smtcal measure program.
# 3. LinuxCNC (run_scenario.py's headless machine) with the robot model and
#    the device in HAL; measure_driver.py mounts the device for each program
#    (halcmd setp) and runs them; the external system is played by it too.
# 4. smtcal measure read per region, smtcal table build.
# 5. Every node of every built table against the model: the error the
#    robot really makes at the node reached by the final approach, within
#    the device's stated noise (4 standard errors of the node's mean) plus
#    what the device's own geometry adds (documented per device below).
# 6. The loop: cell check, verify and compile of measure-loop.place with the
#    built tables, run on the same robot with the marker sensor, and every
#    part within its region's tolerance of its point on the board's true
#    pose.
#
# Exit 0: passed; 1: failed; 77: skipped (LinuxCNC, the namespaces or
# halcompile missing).
import argparse
import json
import math
import os
import random
import re
import shutil
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import measure_model  # noqa: E402
from run_scenario import (check_prerequisites, derive_ini, fail, log, pose, run_linuxcnc, skip,  # noqa: E402
                          smtcal, work_root)

HERE = os.path.dirname(os.path.abspath(__file__))
LOOP_PROGRAM = os.path.join(HERE, "measure-loop.place")
RTLIB_DIR = "/usr/lib/linuxcnc/modules"
SCRATCH_CELL = os.path.join(os.path.dirname(os.path.dirname(HERE)), "examples", "calibrating", "scratch.cell.toml")
APPROACH = (0.5, 0.5)

# The devices as the cell describes them (docs/cell.md, "[measure]"), and
# what the model needs to play them.
DEVICES = {
    "probe": {
        "toml": """[measure]
device = "probe"
z_mm = -8           # the stylus's centre inside the holes
clear_z_mm = -5     # out of the holes between nodes
dwell_s = 0.05
noise_mm = 0.001
placement_mm = 0.25
placement_deg = 0.1
artefact_pitch_u_ppm = 2
[measure.probe]
hole_diameter_mm = 4
hole_diameter_u_mm = 0.0005
hole_pitch_mm = 5
holes = 18
stylus_diameter_mm = 1
stylus_diameter_u_mm = 0.0005
speed_mm_s = 2
overtravel_mm = 0.8
""",
        # The plate's top: the stylus is in a hole below it.
        "plate_z": -6.0, "noise_mm": 0.001,
    },
    "transducer": {
        "toml": """[measure]
device = "transducer"
z_mm = -10          # the plate rests on the transducers, about 1 mm in
clear_z_mm = -8
dwell_s = 0.05
noise_mm = 0.001
[measure.transducer]
input = 0
reference_input = 1
slope = 1
zero_mm = 0
range_mm = [0.3, 1.7]
groove_pitch_mm = 5
grooves = 11
""",
        "contact_z": -9.0, "noise_mm": 0.001,
    },
    "external": {
        "toml": """[measure]
device = "external"
z_mm = -8
clear_z_mm = -5
dwell_s = 0.05
noise_mm = 0.002
timeout_s = 5
[measure.external]
trigger_output = 9
done_input = 15
node_output = 0
""",
        "noise_mm": 0.002,
    },
}

# regions: None = all of the cell's. loop: compile and run measure-loop.place
# on the built tables. abort: the runs that stop (a fault at a visit) before
# the one that completes.
SCENARIOS = {
    # The default suite's (under a minute): the guide's probe on the placing
    # region, 2 x 2 nodes and a check point, 1 set x 2, the plate put down
    # off and turned by what the cell declares (0.25 mm, 0.1 degree).
    "measure_probe": {"device": "probe", "regions": ["layer1"], "pitch": 60, "sets": 1, "repetitions": 2,
                      "placement_mm": 0.25, "placement_deg": 0.1, "seed": 38},
    # Opt-in (linuxcnc-sim-full) from here on.
    # The guide's plan (docs/calibrating.md): every region at the default
    # pitch (the declared roughness's, which verify accepts), 1 set x 2, every
    # station's plate put down off and turned by up to what the cell declares.
    "measure_probe_loop": {"device": "probe", "regions": None, "pitch": None, "sets": 1, "repetitions": 2,
                           "loop": True, "placement_mm": 0.25, "placement_deg": 0.1, "seed": 1994},
    # A plate bumped 30 um part-way through its set: measure read names the
    # station and the visit to measure again from; measured again, the
    # tables hold.
    "measure_probe_bumped": {"device": "probe", "regions": ["layer1"], "pitch": 10, "sets": 1, "repetitions": 2,
                             "placement_mm": 0.1, "placement_deg": 0.05, "seed": 7, "faults": ["bump"],
                             "bump_after_s": 40},
    # A plate put down 2.5 mm off, far beyond the declared error: LinuxCNC's
    # own probe error stops the program; the log says where to resume.
    "measure_probe_misplaced": {"device": "probe", "regions": ["layer1"], "pitch": 30, "sets": 1, "repetitions": 2,
                                "placement_mm": 0.1, "placement_deg": 0.05, "seed": 5, "faults": ["misplaced"]},
    "measure_transducer": {"device": "transducer", "regions": ["layer1"], "pitch": 25, "sets": 1,
                           "repetitions": 2},
    "measure_external": {"device": "external", "regions": ["layer1"], "pitch": 25, "sets": 1, "repetitions": 2},
    "measure_probe_resume": {"device": "probe", "regions": ["layer1"], "pitch": 20, "sets": 1, "repetitions": 2,
                             "faults": ["ready", "no_contact"]},
    # The paper's plan for the placing region,
    # 11 x 11 nodes at 5 mm, two sets of ten repetitions, both axes.
    "measure_paper_plan": {"device": "transducer", "regions": ["layer1"], "pitch": 5, "sets": 2,
                           "repetitions": 10, "check_points": False},
}


def scenario_cell(work, device, ready_input=False):
    """The paper cell from scratch (examples/calibrating/scratch.cell.toml: the
    final approach, a probe, no tables), as shipped for the probe, else with
    the scenario's device in its [measure] table."""
    text = open(SCRATCH_CELL).read()
    if device != "probe" or ready_input:
        device_toml = DEVICES[device]["toml"]
        if ready_input:
            # The device's ready input (motion.digital-in-10, free in paper-cell.hal).
            device_toml = device_toml.replace("dwell_s = 0.05\n", "dwell_s = 0.05\nready_input = 10\n", 1)
        text = text[:text.index("\n[measure]\n") + 1] + device_toml
    path = os.path.join(work, "cell", os.path.basename(SCRATCH_CELL))
    os.makedirs(os.path.dirname(path), exist_ok=True)
    open(path, "w").write(text)
    return path


def robot_hal(work, model_so, device, ready_wired):
    """The robot model and the device in HAL, after paper-cell.hal."""
    # rtapi_app loads modules from /usr/lib/linuxcnc/modules only: LinuxCNC's
    # and the model, in a copy bound over it in the run's mount namespace.
    modules = os.path.join(work, "modules")
    if not os.path.isdir(modules):
        shutil.copytree(RTLIB_DIR, modules)
    shutil.copy(model_so, modules)
    lines = ["# robot-model.hal - written by run_measure.py: the modelled robot and its measuring device",
             "loadrt smtcal_robot_model",
             "addf smtcal-robot-model.0 servo-thread",
             "net x-pos => smtcal-robot-model.0.x-cmd",
             "net y-pos => smtcal-robot-model.0.y-cmd",
             "net z-pos => smtcal-robot-model.0.z-cmd",
             "net x-real smtcal-robot-model.0.x-real",
             "net y-real smtcal-robot-model.0.y-real"]
    lines += measure_model.hal_params()
    d = DEVICES.get(device, {})
    if device == "probe":
        lines += ["setp smtcal-robot-model.0.device 2",
                  f"setp smtcal-robot-model.0.plate-z {d['plate_z']!r}",
                  "setp smtcal-robot-model.0.hole-pitch 5",
                  "setp smtcal-robot-model.0.hole-radius 1.5",
                  f"setp smtcal-robot-model.0.probe-noise {d['noise_mm']!r}",
                  "net marker-sensor smtcal-robot-model.0.probe-contact"]
    elif device == "transducer":
        lines += ["setp smtcal-robot-model.0.device 1",
                  f"setp smtcal-robot-model.0.ldt-contact-z {d['contact_z']!r}",
                  "setp smtcal-robot-model.0.ldt-pitch 5",
                  "setp smtcal-robot-model.0.ldt-slope 1",
                  "setp smtcal-robot-model.0.ldt-zero 0",
                  # Two transducers, each noisy: the error read from their
                  # difference has the cell's stated noise.
                  f"setp smtcal-robot-model.0.ldt-noise {d['noise_mm'] / math.sqrt(2)!r}",
                  "net ldt-measure smtcal-robot-model.0.ldt-measure => motion.analog-in-00",
                  "net ldt-reference smtcal-robot-model.0.ldt-reference => motion.analog-in-01"]
    elif device == "external":
        lines += ["net ext-done => motion.digital-in-15", "sets ext-done false"]
    if ready_wired:
        lines += ["net device-ready => motion.digital-in-10", "sets device-ready true"]
    path = os.path.join(work, "robot-model.hal")
    open(path, "w").write("\n".join(lines) + "\n")
    return path


def read_plan(path):
    """The plan's visits (visit, region, axes, station, kind, node, x, y, set,
    repetitions, direction)."""
    visits = []
    for line in open(path):
        if line.startswith("#") or line.startswith("visit,"):
            continue
        f = line.strip().split(",")
        visits.append({"visit": int(f[0]), "region": f[1], "axes": f[2], "station": int(f[3]), "kind": f[4],
                       "node": int(f[5]), "x": float(f[6]), "y": float(f[7]), "set": int(f[8]),
                       "repetitions": int(f[9]), "direction": -1 if len(f) > 10 and f[10] == "-" else 1})
    return visits


def stations(visits):
    """station number -> (axes, origin x, origin y): where its artefact's
    reference goes (the box of its points' lower corner), in plan order."""
    out = {}
    for v in visits:
        axes, x0, y0 = out.get(v["station"], (v["axes"], v["x"], v["y"]))
        out[v["station"]] = (axes, min(x0, v["x"]), min(y0, v["y"]))
    return out


def placements(scenario, visits):
    """How the operator put the artefact down at each station: off by up to
    the cell's declared placement error and turned by up to the declared
    turn (drawn, seeded), or exactly where the plan says."""
    rng = random.Random(scenario.get("seed", 1994))
    off = scenario.get("placement_mm", 0.0)
    turn = scenario.get("placement_deg", 0.0)
    out = {}
    for number in stations(visits):
        a = rng.uniform(0, 2 * math.pi)
        out[number] = (off * math.cos(a), off * math.sin(a), rng.choice((-1, 1)) * turn)
    return out


def program_setups(visits, device, programs_dir, placed):
    """Per program (in order): its file and the artefact put down for it:
    the hole plate's corner hole, or the grooved plate's first groove, at
    the station's origin, off and turned as `placed` says."""
    programs = sorted(os.listdir(programs_dir))
    setups = []
    for number, (axes, x0, y0) in stations(visits).items():
        stem = f"measure_s{number}" + ("" if axes == "xy" else "_" + axes)
        if stem + ".ngc" not in programs:
            continue  # before the visit a resumed measurement starts at
        dx, dy, deg = placed.get(number, (0.0, 0.0, 0.0))
        setup = []
        if device == "probe":
            setup = [f"setp smtcal-robot-model.0.hole-x0 {x0 + dx!r}",
                     f"setp smtcal-robot-model.0.hole-y0 {y0 + dy!r}",
                     f"setp smtcal-robot-model.0.hole-angle {math.radians(deg)!r}"]
        elif device == "transducer":
            axis = 1 if axes == "y" else 0
            setup = [f"setp smtcal-robot-model.0.ldt-axis {axis}",
                     f"setp smtcal-robot-model.0.ldt-origin {(y0 + dy) if axis else (x0 + dx)!r}"]
        setups.append({"path": os.path.join(programs_dir, stem + ".ngc"), "setup": setup, "station": number})
    return setups


def measure_on_controller(args, work, cell, device, plan_csv, placed, start=1, fault=None, run_name="run"):
    """Compiles the measuring programs from `start` and runs them; returns the driver's record."""
    programs_dir = os.path.join(work, f"programs-{run_name}")
    logs = os.path.join(work, "logs")
    os.makedirs(logs, exist_ok=True)
    made = smtcal(["measure", "program", plan_csv, "--cell", cell, "-o", programs_dir, "--start", str(start),
                   "--log-dir", logs], args.smtcal)
    if made.returncode != 0:
        fail("smtcal measure program: " + made.stderr)
    visits = read_plan(plan_csv)
    setups = program_setups(visits, device, programs_dir, placed)
    if fault == "ready":
        # The device faults: its ready input drops 4 s into the first program.
        setups[0]["fault_after_s"] = 4
    ready_wired = any(f in ("ready", "no_contact") for f in SCENARIOS[args.scenario].get("faults", []))
    ini = derive_ini(work, programs_dir, False, display="measure_driver.py",
                     extra_hals=(robot_hal(work, args.model, device, ready_wired),))
    # LinuxCNC's own aborts (a probe error, an e-stop) leave their line in
    # the log too (docs/measure.md, "Aborts").
    text = open(ini).read().replace("[RS274NGC]\n", "[RS274NGC]\nON_ABORT_COMMAND = O <smtcal_measure_on_abort> call\n", 1)
    open(ini, "w").write(text)
    if fault == "no_contact":
        # The hole plate is taken away after the first program's setup: the
        # probe finds no wall (it is lowered onto nothing: plate far below).
        setups[0]["setup"].append("setp smtcal-robot-model.0.plate-z -100")
    if fault == "bump":
        # The plate is knocked 30 um along x part-way through the first program.
        s0 = setups[0]
        x0 = float(s0["setup"][0].split()[-1])
        s0["events"] = [{"after_s": SCENARIOS[args.scenario]["bump_after_s"],
                         "hal": [f"setp smtcal-robot-model.0.hole-x0 {x0 + 0.03!r}"]}]
        placed[s0["station"]] = (placed[s0["station"]][0] + 0.03,) + tuple(placed[s0["station"]][1:])
    if fault == "misplaced":
        # The plate is put down half a hole pitch off, ten times what the cell
        # declares: the stylus comes down on the plate between two holes,
        # outside a probe move, and LinuxCNC stops the program itself.
        s0 = setups[0]
        x0 = float(s0["setup"][0].split()[-1])
        s0["setup"][0] = f"setp smtcal-robot-model.0.hole-x0 {x0 + 2.5!r}"
    external = None
    if device == "external":
        external = {"trigger": 9, "done_signal": "ext-done", "node_out": 0,
                    "noise_mm": DEVICES["external"]["noise_mm"], "seed": 1994,
                    "readings": os.path.join(work, "external-readings.csv")}
    plan = {"programs": setups, "external": external, "timeout_s": 7200,
            "ready_signal": "device-ready"}
    plan_path = os.path.join(work, f"{run_name}-plan.json")
    json.dump(plan, open(plan_path, "w"), indent=1)
    run_path = os.path.join(work, f"{run_name}.json")
    record, machine_s = run_linuxcnc(work, ini, plan_path, run_path, plan["timeout_s"],
                                     modules=os.path.join(work, "modules"))
    record["machine_s"] = machine_s
    log(f"  {run_name}: LinuxCNC ran {machine_s:.1f} s; {len(record['programs'])} program(s), "
        f"{sum(p['ran_s'] for p in record['programs']):.1f} s measuring; {record['end']}")
    return record


def log_files(work):
    logs = os.path.join(work, "logs")
    return sorted(os.path.join(logs, f) for f in os.listdir(logs) if f.endswith(".log"))


def region_tables(cell_text):
    """region name -> its table file, from the cell file."""
    tables = {}
    for block in cell_text.split("[[region]]")[1:]:
        name = re.search(r'(?m)^name = "([^"]+)"', block).group(1)
        table = re.search(r'(?m)^table = "([^"]+)"', block).group(1)
        tables[name] = table
    return tables


def read_table(path):
    nodes = []
    lines = [line for line in open(path) if not line.startswith("#")]
    header = lines[0].strip().split(",")
    for line in lines[1:]:
        f = dict(zip(header, line.strip().split(",")))
        if f.get("kind", "node") != "node":
            continue
        nodes.append({"axis": f["axis"], "x": float(f["x_mm"]), "y": float(f["y_mm"]), "error": float(f["error_mm"]),
                      "stddev": float(f["stddev_mm"]) if f.get("stddev_mm") else 0.0,
                      "n": int(f["n"]) if f.get("n") else 1,
                      "u": float(f["u_mm"]) if f.get("u_mm") else 0.0})
    return nodes


def fit_frame(tables):
    """The rigid motion (tx, ty, theta about the nodes' centroid) that best
    takes the model's errors onto all the built tables together, by least
    squares: the tables' frame is the artefact's mean placement
    (docs/measure.md, "Registering the stations"), which no artefact can
    tell from the robot's own frame; what matters for a placement is
    everything else. Returns (tx, ty, theta, cx, cy)."""
    rows = []
    for nodes in tables.values():
        for node in nodes:
            ex, ey = measure_model.approached_error(node["x"], node["y"], APPROACH)
            truth = ex if node["axis"] == "x" else ey
            rows.append((node, node["error"] - truth))
    cx = sum(n["x"] for n, _ in rows) / len(rows)
    cy = sum(n["y"] for n, _ in rows) / len(rows)
    # table - truth = -(t + theta J (h - c)): x: -(tx - theta dy), y: -(ty + theta dx)
    a = [[0.0] * 3 for _ in range(3)]
    b = [0.0] * 3
    for node, d in rows:
        g = [1.0, 0.0, -(node["y"] - cy)] if node["axis"] == "x" else [0.0, 1.0, node["x"] - cx]
        for i in range(3):
            b[i] += g[i] * -d
            for j in range(3):
                a[i][j] += g[i] * g[j]
    # Solve the 3 x 3 normal equations (Gauss-Jordan; an axis without rows keeps 0).
    for i in range(3):
        a[i][i] += 1e-12
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for i in range(3):
        p = max(range(i, 3), key=lambda r: abs(m[r][i]))
        m[i], m[p] = m[p], m[i]
        for r in range(3):
            if r != i:
                f = m[r][i] / m[i][i]
                m[r] = [x - f * y for x, y in zip(m[r], m[i])]
    t = [m[i][3] / m[i][i] for i in range(3)]
    return t[0], t[1], t[2], cx, cy


def judge_table(nodes, device, frame):
    """Every node against the model in the tables' frame; returns (worst
    |diff| mm, worst in allowed units, count). The allowance is what the
    measurement states: 4 standard uncertainties of the node (its
    scatter's standard error with the device's noise as its floor, and its
    u_mm), plus the device's geometry (documented per device below)."""
    noise = DEVICES[device]["noise_mm"]
    # What the device's geometry adds beyond its noise: the probe's trips are
    # latched 0 to 1 servo period late (half a period taken off by measure
    # read: +-0.5 period of travel left, 0.001 mm at 2 mm/s, in u_mm), that
    # latency's share through the stylus's off-centre correction (a period of
    # travel times 0.45 / the contact radius of 1.5 mm, 0.0006 mm: the bound
    # of MeasurementReading.ProbeErrorsAreTheFieldAtTheNodes, tests/unit/)
    # and the move to the node through the measured field (bilinear: its
    # curvature over the contact radius, under 0.0005 mm here); the
    # transducer and the external system read at rest.
    geometry = {"probe": 0.0011, "transducer": 0.0, "external": 0.0}[device]
    tx, ty, theta, cx, cy = frame
    worst, worst_ratio, count = 0.0, 0.0, 0
    for node in nodes:
        ex, ey = measure_model.approached_error(node["x"], node["y"], APPROACH)
        truth = ex - (tx - theta * (node["y"] - cy)) if node["axis"] == "x" else ey - (ty + theta * (node["x"] - cx))
        diff = abs(node["error"] - truth)
        scatter = max(noise, node["stddev"]) / math.sqrt(node["n"])
        allowed = 4 * math.hypot(scatter, node["u"]) + geometry
        worst = max(worst, diff)
        worst_ratio = max(worst_ratio, diff / allowed)
        count += 1
    return worst, worst_ratio, count


def loop(args, work, cell, scenario):
    """The example compiled with the measured tables, run on the same robot."""
    checked = smtcal(["cell", "check", cell], args.smtcal)
    if checked.returncode != 0:
        fail("smtcal cell check on the measured cell: " + checked.stdout + checked.stderr)
    verified = smtcal(["verify", LOOP_PROGRAM, "--cell", cell], args.smtcal)
    log("  verify: " + (verified.stdout.strip().splitlines() or ["(nothing)"])[-1])
    if verified.returncode != 0:
        fail("smtcal verify on the measured cell: " + verified.stdout + verified.stderr)
    program_dir = os.path.join(work, "loop-program")
    compiled = smtcal(["compile", LOOP_PROGRAM, "--cell", cell, "--target", "linuxcnc", "-o", program_dir],
                      args.smtcal)
    if compiled.returncode != 0:
        fail("smtcal compile: " + compiled.stderr)
    # The marker sensor sees where the robot really is: its sum2 inputs are
    # the model's real position (the driver's sensor model: the identity).
    hal = robot_hal(work, args.model, "none", False)
    with open(hal, "a") as f:
        f.write("net vacuum-valve => smtcal-robot-model.0.latch\n")
        for unit in range(4):
            f.write(f"unlinkp sum2.{unit}.in0\nunlinkp sum2.{unit}.in1\n")
            f.write(f"net x-real => sum2.{unit}.in0\nnet y-real => sum2.{unit}.in1\n")
    ini = derive_ini(work, program_dir, False, display="driver.py", extra_hals=("marker-sensor.hal", hal))
    cycles = [pose(0.3, -0.2, 0.1), pose(-0.4, 0.3, -0.15)]
    identity = {"m": [[1.0, 0.0], [0.0, 1.0]], "b": [0.0, 0.0]}
    plan = {"program": os.path.join(program_dir, "measure-loop.ngc"), "cycles": cycles,
            "sensor_models": [identity, identity], "timeout_s": 400}
    plan_path = os.path.join(work, "loop-plan.json")
    json.dump(plan, open(plan_path, "w"), indent=1)
    run_path = os.path.join(work, "loop-run.json")
    record, machine_s = run_linuxcnc(work, ini, plan_path, run_path, plan["timeout_s"],
                                     extra_env={"SMTCAL_SIM_REAL_PINS": "smtcal-robot-model.0"},
                                     modules=os.path.join(work, "modules"))
    log(f"  placing: LinuxCNC ran {machine_s:.1f} s, {len(record['cycles'])} cycles, {record['end']}")
    if record["messages"]:
        fail(f"the placing run stopped: {record['messages']}")
    if len(record["cycles"]) != len(cycles):
        fail(f"{len(record['cycles'])} cycles ran of {len(cycles)}")
    points = [tuple(map(float, m.groups())) for m in
              re.finditer(r"(?m)^Point P\d = XY\(([-\d.]+), ([-\d.]+), [-\d.]+, [-\d.]+\) In Board", open(LOOP_PROGRAM).read())]
    worst = 0.0
    report = []
    for c, cycle in enumerate(cycles):
        places = [e for e in record["vacuum"] if e["cycle"] == c and not e["on"]]
        if len(places) != len(points):
            fail(f"cycle {c + 1}: {len(places)} places, the program has {len(points)}")
        a = math.radians(cycle["angle_deg"])
        for k, (fx, fy) in enumerate(points):
            want = (cycle["x_mm"] + math.cos(a) * fx - math.sin(a) * fy, cycle["y_mm"] + math.sin(a) * fx + math.cos(a) * fy)
            real = places[k]["real"]
            miss = math.hypot(real[0] - want[0], real[1] - want[1])
            worst = max(worst, miss)
            report.append(f"P{k + 1}@{miss * 1000:.1f}um")
    log(f"  parts landed within {worst:.4f} mm of their points on the board's true pose ({' '.join(report)})")
    if worst > 0.1:
        fail(f"a part landed {worst:.4f} mm from its point, beyond the ±0.1 mm tolerance")
    return worst


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--smtcal", required=True)
    parser.add_argument("--model", required=True, help="smtcal_robot_model.so (halcompile)")
    parser.add_argument("--work", required=True)
    parser.add_argument("--keep-logs", help="copy the measuring logs and the plan here (the guide's examples)")
    parser.add_argument("scenario", choices=sorted(SCENARIOS))
    args = parser.parse_args()
    check_prerequisites()
    if not os.path.exists(args.model):
        skip(f"the robot model {args.model} was not built: halcompile is missing (install linuxcnc-uspace-dev, "
             "tools/install-deps.sh)")
    scenario = SCENARIOS[args.scenario]
    started = time.monotonic()
    device = scenario["device"]
    work = os.path.join(work_root(args.work), args.scenario)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    cell = scenario_cell(work, device, ready_input=any(f in ("ready", "no_contact") for f in scenario.get("faults", [])))
    plan_csv = os.path.join(work, "cell", "plan.csv")
    argv = ["measure", "plan", "--cell", cell, "-o", plan_csv, "--sets", str(scenario["sets"]),
            "--repetitions", str(scenario["repetitions"])]
    if scenario["pitch"] is not None:
        argv += ["--pitch", str(scenario["pitch"])]
    for region in scenario["regions"] or []:
        argv += ["--region", region]
    if not scenario.get("check_points", True):
        argv.append("--no-check-points")
    planned = smtcal(argv, args.smtcal)
    if planned.returncode != 0:
        fail("smtcal measure plan: " + planned.stdout + planned.stderr)
    log(planned.stdout.rstrip())
    visits = read_plan(plan_csv)

    # How the operator puts the artefact down at each station.
    placed = placements(scenario, visits)
    for number, (dx, dy, deg) in sorted(placed.items()):
        if dx or dy or deg:
            log(f"  station {number}: the artefact put down {dx * 1000:+.1f} um, {dy * 1000:+.1f} um off and turned "
                f"{deg:+.3f} degree")

    # The runs: the faults first (each stops; the next resumes at its visit).
    start = 1
    runs = []
    for n, fault in enumerate(scenario.get("faults", [])):
        record = measure_on_controller(args, work, cell, device, plan_csv, placed, start, fault,
                                       run_name=f"fault{n + 1}")
        runs.append(record)
        if fault == "bump":
            # The run goes through; measure read finds the closure off.
            if record["messages"]:
                fail(f"the bumped run stopped: {record['messages']}")
            first = scenario["regions"][0]
            read = smtcal(["measure", "read", plan_csv, *log_files(work), "--cell", cell, "--region", first, "-o",
                           os.path.join(work, "bumped-raw.csv")], args.smtcal)
            m = re.search(r"the artefact of station (\d+) moved during set (\d+): .*--start (\d+)", read.stderr)
            if read.returncode != 1 or not m:
                fail(f"measure read did not name the bumped plate (exit {read.returncode}): {read.stderr}")
            log("  bump: " + read.stderr.strip().splitlines()[0])
            start = int(m.group(3))
            continue
        aborts = [m["text"] for m in record["messages"]]
        if not aborts:
            fail(f"the {fault} fault did not stop the measurement")
        text = aborts[0]
        if fault == "misplaced":
            # LinuxCNC's own error; the log's last line names the visit.
            last = open(log_files(work)[0]).read().rstrip().splitlines()[-1]
            m = re.match(r"# aborted at visit (\d+) repetition \d+: LinuxCNC stopped the program", last)
            if not m:
                fail(f"LinuxCNC stopped the program ({text!r}) but the log does not say where: {last!r}")
            log(f"  {fault}: LinuxCNC: {text}; the log: {last}")
            start = int(m.group(1))  # the plate put right (the next run's setup), measured again from there
            continue
        m = re.search(r"smtcal: measuring stopped at visit (\d+) - ", text)
        want = {"ready": "the device's ready input stayed off", "no_contact": "the probe did not touch"}[fault]
        if not m or want not in text or f"--start {m.group(1)}" not in text:
            fail(f"the {fault} fault's abort does not say what and where to resume: {text!r}")
        log(f"  {fault}: {text}")
        start = int(m.group(1))
    record = measure_on_controller(args, work, cell, device, plan_csv, placed, start, run_name="measure")
    if record["messages"]:
        fail(f"the measurement stopped: {record['messages']}")
    runs.append(record)
    measuring_s = sum(p["ran_s"] for r in runs for p in r["programs"])
    readings = sum(v["repetitions"] for v in visits)
    log(f"  measured {len(visits)} visits, {readings} readings in {measuring_s:.1f} s on the controller "
        f"({measuring_s / readings:.3f} s a reading)")

    # Read back, build, judge: the tables' frame (the artefact's mean
    # placement) fitted to the model over all of them, every node within
    # what the measurement states of it.
    tables = region_tables(open(cell).read())
    regions = scenario["regions"] or list(tables)
    logs = log_files(work)
    built_tables = {}
    for region in regions:
        raw = os.path.join(work, "cell", f"{region}-raw.csv")
        argv = ["measure", "read", plan_csv, *logs, "--cell", cell, "--region", region, "-o", raw]
        if device == "external":
            argv += ["--external", os.path.join(work, "external-readings.csv")]
        read = smtcal(argv, args.smtcal)
        if read.returncode != 0:
            fail(f"smtcal measure read ({region}): " + read.stderr)
        if read.stderr.strip():
            log("  " + read.stderr.strip())
        table = os.path.join(work, "cell", tables[region])
        built = smtcal(["table", "build", raw, "--cell", cell, "-o", table], args.smtcal)
        if built.returncode != 0:
            fail(f"smtcal table build ({region}): " + built.stderr)
        built_tables[region] = read_table(table)
    frame = fit_frame(built_tables)
    log(f"  the tables' frame (the artefact's mean placement) lies {frame[0] * 1000:+.1f} um, {frame[1] * 1000:+.1f} um "
        f"and {math.degrees(frame[2]):+.4f} degree from the model's")
    for region in regions:
        worst, ratio, count = judge_table(built_tables[region], device, frame)
        u = max(n["u"] for n in built_tables[region])
        log(f"  {region}: {count} nodes; the table departs from the model by at most {worst * 1000:.2f} µm, "
            f"{ratio:.2f} of what the measurement states (u_mm up to {u * 1000:.2f} µm)")
        if ratio > 1:
            fail(f"region {region}: a node departs from the model by {worst:.4f} mm, beyond what the measurement "
                 "states")
    if args.keep_logs:
        os.makedirs(args.keep_logs, exist_ok=True)
        for path in logs:
            shutil.copy(path, args.keep_logs)
    if scenario.get("loop"):
        loop(args, work, cell, scenario)
    log(f"scenario {args.scenario}: passed in {time.monotonic() - started:.1f} s")


if __name__ == "__main__":
    main()
