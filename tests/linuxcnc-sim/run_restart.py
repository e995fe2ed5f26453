#!/usr/bin/python3
# run_restart.py - the cycle record through a production line's life on
# LinuxCNC's controller (docs/monitor.md): a power cut, a restart and
# refusals that rise, then `smtcal monitor` on the log the runtime wrote.
#
#   run_restart.py --smtcal BIN --checker BIN --work DIR
#
# The machine is run_scenario.py's (the example's INI made headless, the
# simulated marker sensor, the clock pin), with monitor.place compiled for
# it and restart_driver.py as the operator.
# 1. The controller runs 12 good boards (their pose jittered by +-10 µm and
#    +-3 mdeg); 1.5 s into the 13th board's scan the whole controller is
#    killed (SIGKILL to its PID namespace: every process at once, as a power
#    cut stops them). The file system's part of a power cut, which killing
#    processes cannot make, is then appended to the log as many file
#    systems leave it: 4096 NUL bytes where the file's size ran ahead of its
#    data.
# 2. The controller starts again (its /tmp emptied, as a reboot does) on the
#    same log and parameter file, and runs 6 times 3 good boards and one it
#    cannot see (refused by missing_trip; the runtime aborts, the operator
#    starts the program again), then 3 good ones: refusals rising from none
#    to one scan in four.
# 3. `smtcal monitor LOG --cell CELL --baseline 10 --json`: the damage is one
#    warning naming its bytes; the restarts are runs of the log (the first
#    record after each begins afresh); every record before and after counts;
#    the verdict is out of control (exit 4) by the refusals alone, the
#    refusals' CUSUM alarming at the sixth refused scan; no pose alarm.
# About 4 minutes; opt-in (the linuxcnc-sim-full target).
#
# Exit 0: passed; 1: failed; 77: skipped (LinuxCNC or namespaces cannot
# start here).
import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import threading
import time

import run_scenario as sim

GOOD_FIRST = 12      # good boards before the power cut
BLOCKS = 6           # then, after the restart: 3 good boards and a refused one, this many times
GOOD_LAST = 3
KILL_AFTER_S = 1.5   # into the 13th board's scan


def boards(count, seed, missing_every=0):
    rng = random.Random(seed)
    out = []
    for n in range(count):
        present = not (missing_every and n % missing_every == missing_every - 1)
        out.append(sim.pose(rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01), rng.uniform(-0.003, 0.003),
                            present=present))
    return out


def records_in(path):
    if not os.path.exists(path):
        return 0
    with open(path, "rb") as f:
        return sum(1 for line in f if line.startswith(b"cycle "))


def controller_pids(plan_path):
    """The `unshare` of a run (its PID namespace dies with it)."""
    pids = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            cmdline = open(f"/proc/{pid}/cmdline", "rb").read().split(b"\0")
            if cmdline[0] == b"unshare" and ("SMTCAL_SIM_PLAN=" + plan_path).encode() in open(
                    f"/proc/{pid}/environ", "rb").read():
                pids.append(int(pid))
        except OSError:
            pass
    return pids


def run_controller(work, ini, plan, name, kill_when=None):
    """One start of the controller with restart_driver.py; `kill_when`: a
    function of the log's record count that says when to cut its power."""
    plan_path = os.path.join(work, f"plan-{name}.json")
    run_path = os.path.join(work, f"run-{name}.json")
    json.dump(plan, open(plan_path, "w"), indent=1)
    # A reboot empties /tmp (LinuxCNC's lock file, its FIFO).
    shutil.rmtree(os.path.join(work, "tmp"), ignore_errors=True)
    result = {}
    thread = threading.Thread(target=lambda: result.setdefault(
        "code", sim.start_linuxcnc(work, ini, plan_path, run_path, plan["timeout_s"])))
    began = time.monotonic()
    thread.start()
    killed = False
    while thread.is_alive():
        if kill_when and not killed and kill_when(records_in(os.path.join(work, sim.RECORD_FILE))):
            time.sleep(KILL_AFTER_S)
            pids = controller_pids(plan_path)
            if not pids:
                sim.fail("the controller to cut the power of is not running")
            for pid in pids:
                os.kill(pid, signal.SIGKILL)
            killed = True
        thread.join(0.05)
    seconds = time.monotonic() - began
    left = sim.leftover_processes("SMTCAL_SIM_PLAN=" + plan_path)
    # The kernel kills a PID namespace's processes when its init dies, but
    # not at once: on a loaded host rtapi_app (its threads, its shared
    # memory) was measured still there when the run's thread had ended.
    # What outlives 10 s after the power cut has escaped the namespace.
    settle = time.monotonic() + 10
    while killed and left and time.monotonic() < settle:
        time.sleep(0.1)
        left = sim.leftover_processes("SMTCAL_SIM_PLAN=" + plan_path)
    if left:
        sim.fail("processes of the run outlived it: " + "; ".join(left))
    if killed:
        return None, seconds
    if not os.path.exists(run_path):
        tail = open(os.path.join(work, "linuxcnc.log")).read()[-3000:]
        if "rtapi" in tail and ("Permission" in tail or "not permitted" in tail):
            sim.skip("LinuxCNC could not start here:\n" + tail)
        sim.fail(f"LinuxCNC ended (exit {result.get('code')}) without the driver's record; its log:\n{tail}")
    return json.load(open(run_path)), seconds


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--smtcal", required=True)
    parser.add_argument("--checker", required=True)
    parser.add_argument("--work", required=True)
    args = parser.parse_args()
    sim.check_prerequisites()
    started = time.monotonic()
    work = os.path.join(sim.work_root(args.work), "monitor_restart")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    cell = sim.cell_copy(work, {"cell_add": sim.MONITOR_CELL})
    program_dir = os.path.join(work, "program")
    ini = sim.derive_ini(work, program_dir, False, display="restart_driver.py")
    shutil.copy(os.path.join(sim.HERE, "driver.py"), work)  # restart_driver.py uses its board model
    compiled = sim.smtcal(["compile", sim.MONITOR, "--cell", cell, "--target", "linuxcnc", "--ini", ini, "-o",
                           program_dir], args.smtcal)
    if compiled.returncode != 0:
        sim.fail("smtcal compile: " + compiled.stderr)
    model = sim.run([args.checker, "--cell", cell, "--sensor-model"])
    if model.returncode != 0:
        sim.fail("the checker's sensor model: " + model.stderr)
    sensor_models = sorted(json.loads(model.stdout), key=lambda m: m["marker"])
    program = os.path.join(program_dir, "monitor.ngc")
    log_path = os.path.join(work, sim.RECORD_FILE)

    # 1. Good boards, then the power cut in the 13th board's scan.
    first = boards(GOOD_FIRST + 1, 41)
    plan = {"program": program, "sensor_models": sensor_models, "boards": first, "timeout_s": 60 + 15 * len(first)}
    _, seconds = run_controller(work, ini, plan, "before-the-cut", kill_when=lambda n: n >= GOOD_FIRST)
    held = records_in(log_path)
    if held != GOOD_FIRST:
        sim.fail(f"the log holds {held} records after the power cut, expected {GOOD_FIRST}")
    size = os.path.getsize(log_path)
    with open(log_path, "ab") as f:
        f.write(b"\0" * 4096)
    sim.log(f"  power cut {KILL_AFTER_S} s into board {GOOD_FIRST + 1}'s scan after {seconds:.1f} s: {held} records "
            f"({size} bytes), then 4096 NUL bytes appended (bytes {size}-{size + 4095})")

    # 2. The restart: refusals rising.
    second = []
    for block in range(BLOCKS):
        second += boards(4, 100 + block, missing_every=4)
    second += boards(GOOD_LAST, 200)
    plan = {"program": program, "sensor_models": sensor_models, "boards": second, "timeout_s": 120 + 15 * len(second)}
    record, seconds = run_controller(work, ini, plan, "after-the-restart")
    refusals = [m for m in record["messages"] if m["text"].strip().startswith("smtcal: marker scan of fixture")]
    others = [m for m in record["messages"] if m not in refusals]
    sim.log(f"  restart: {len(record['fed'])} boards in {seconds:.1f} s, the program started {record['starts']} "
            f"times, {len(refusals)} scans refused, run ended: {record['end']}")
    if record["end"].startswith("timeout"):
        sim.fail(record["end"])
    if len(refusals) != BLOCKS:
        sim.fail(f"expected {BLOCKS} refused scans, got {len(refusals)}: {record['messages']}")
    for m in others:
        sim.log(f"  (LinuxCNC: {m['text']!r}: the board was scanned again)")

    # 3. smtcal monitor on the log.
    result = sim.smtcal(["monitor", log_path, "--cell", cell, "--baseline", "10", "--json"], args.smtcal)
    if result.returncode != 4:
        sim.fail(f"smtcal monitor: exit {result.returncode}, expected 4 (out of control)\n{result.stdout}"
                 f"{result.stderr}")
    warnings = [line for line in result.stderr.splitlines() if ": warning: " in line]
    damaged = [w for w in warnings if "are not records" in w]
    if len(damaged) != 1 or "4096 NUL bytes" not in damaged[0] or f"bytes {size}-{size + 4095}" not in damaged[0]:
        sim.fail(f"expected one warning naming the 4096 NUL bytes {size}-{size + 4095}, got:\n{result.stderr}")
    report = json.loads(result.stdout)
    board = report["fixtures"][0]
    scans = GOOD_FIRST + len(record["fed"])
    starts = 1 + record["starts"]
    if board["scans"] != scans:
        sim.fail(f"monitor counted {board['scans']} scans, the controller made {scans}")
    if len(board["restarts"]) != starts - 1:
        sim.fail(f"monitor found {len(board['restarts'])} restarts, the program started {starts} times")
    kinds = [f["kind"] for f in board["findings"]]
    # One finding for the check whose chart alarmed (the chart of every
    # refusal together is said in it: docs/monitor.md, "what an alarm means").
    checks = [f.get("check") for f in board["findings"]]
    if (kinds != ["refusals"] or checks != ["missing_trip"] or board["refusals"]["all"]["alarm_scan"] is None
            or board["refusals"]["missing_trip"]["alarm_scan"] is None):
        sim.fail(f"expected the refusals alone (missing_trip's chart and all together) to alarm, got {kinds} {checks}")
    sixth = GOOD_FIRST + 4 * BLOCKS  # the scan number of the sixth refused scan
    alarm = board["refusals"]["all"]["alarm_scan"]
    if alarm != sixth:
        sim.fail(f"the refusals' CUSUM alarmed at scan {alarm}, expected {sixth} (the sixth refusal)")
    for line in damaged:
        sim.log("  " + line)
    sim.log(f"  smtcal monitor: exit 4, {board['scans']} scans in {starts} program runs, baseline scans "
            f"{board['baseline']['first_scan']}-{board['baseline']['last_scan']}; refusals' CUSUM alarm at scan {alarm} "
            f"(designed for {board['refusals']['all']['p0'] * 100:.0f} %, in control once in "
            f"{board['refusals']['all']['in_control_scans']:.0f} scans); findings {kinds}")
    sim.log(f"scenario monitor_restart: passed in {time.monotonic() - started:.1f} s")


if __name__ == "__main__":
    main()
