#!/usr/bin/python3
# measure_driver.py - the DISPLAY program of the measurement scenarios
# (run_measure.py writes it into the derived INI): it plays the operator
# who mounts the measuring device and runs smtcal's measuring programs one
# after the other, and the external measuring system when the device is
# external.
#
# Reads the plan (JSON, path in $SMTCAL_SIM_PLAN):
#   programs  [{"path": ..., "setup": [halcmd lines run before it],
#               "fault_after_s": s (optional: the device's ready signal drops then),
#               "events": [{"after_s": s, "hal": [halcmd lines]}, ...] (optional: e.g.
#               the plate bumped while the program runs)}, ...]
#   ready_signal the HAL signal of the device's ready input
#   external  {"trigger": n, "done_signal": "ext-done", "node_out": k,
#              "noise_mm": s, "seed": n, "readings": path} or null
#   timeout_s the whole run
# Then: e-stop reset, machine on, home all, and per program: the setup
# (the device mounted: halcmd setp), AUTO, open, run, wait until the
# interpreter is idle again. A program that aborts ends the run (as an
# operator would stop and look). Records every operator message, each
# program's wall time, and how it ended, to $SMTCAL_SIM_RUN (JSON).
#
# The external system: on the trigger output's rising edge it reads the
# node, set and repetition from the analog outputs, the robot's real
# position from the model (smtcal-robot-model.0.x-real, y-real), adds its
# noise, appends a CSV row, and sets its done input; when the trigger falls
# it clears done.
import json
import os
import random
import subprocess
import sys
import time

import linuxcnc


def hal(commands):
    subprocess.run(["halcmd", "-f"], input="\n".join(commands) + "\n", text=True, check=True)


def getp(name):
    return float(subprocess.run(["halcmd", "getp", name], capture_output=True, text=True, check=True).stdout)


def main():
    plan = json.load(open(os.environ["SMTCAL_SIM_PLAN"]))
    out_path = os.environ["SMTCAL_SIM_RUN"]
    started = time.monotonic()
    record = {"programs": [], "messages": [], "end": None}
    stat, command, errors = linuxcnc.stat(), linuxcnc.command(), linuxcnc.error_channel()

    def now():
        return round(time.monotonic() - started, 3)

    def save(end):
        record["end"] = end
        record["total_s"] = now()
        with open(out_path + ".tmp", "w") as f:
            json.dump(record, f, indent=1)
        os.replace(out_path + ".tmp", out_path)

    def wait_for(predicate, what, timeout_s=30):
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            stat.poll()
            if predicate():
                return
            time.sleep(0.005)
        save("timeout: " + what)
        sys.exit(1)

    external = plan.get("external")
    ext_file = None
    rng = None
    if external:
        ext_file = open(external["readings"], "w")
        ext_file.write("# readings of the simulated external system (measure_driver.py)\n")
        ext_file.write("node,set,repetition,x_mm,y_mm\n")
        ext_file.flush()
        rng = random.Random(external["seed"])
        hal([f"sets {external['done_signal']} false"])

    command.state(linuxcnc.STATE_ESTOP_RESET)
    wait_for(lambda: stat.task_state == linuxcnc.STATE_ESTOP_RESET, "e-stop reset")
    command.state(linuxcnc.STATE_ON)
    wait_for(lambda: stat.task_state == linuxcnc.STATE_ON, "machine on")
    command.mode(linuxcnc.MODE_MANUAL)
    command.wait_complete()
    command.home(-1)
    wait_for(lambda: all(stat.homed[j] for j in range(stat.joints)), "homing")
    deadline = time.monotonic() + plan["timeout_s"]
    end = "all programs ran"
    for program in plan["programs"]:
        if program.get("setup"):
            hal(program["setup"])
        command.mode(linuxcnc.MODE_AUTO)
        command.wait_complete()
        command.program_open(program["path"])
        command.wait_complete()
        began = now()
        command.auto(linuxcnc.AUTO_RUN, 0)
        running_seen = False
        trigger_was = False
        aborted = False
        fault_at = time.monotonic() + program["fault_after_s"] if "fault_after_s" in program else None
        events = sorted(((time.monotonic() + e["after_s"], e["hal"]) for e in program.get("events", [])),
                        key=lambda e: e[0])
        while True:
            if fault_at is not None and time.monotonic() > fault_at:
                hal([f"sets {plan['ready_signal']} false"])  # the device faults
                fault_at = None
            while events and time.monotonic() > events[0][0]:
                hal(events.pop(0)[1])
                record.setdefault("events", []).append({"t": now(), "program": os.path.basename(program["path"])})
            if time.monotonic() > deadline:
                command.abort()
                save("timeout: the run took longer than %s s" % plan["timeout_s"])
                sys.exit(1)
            stat.poll()
            message = errors.poll()
            while message:
                record["messages"].append({"t": now(), "kind": message[0], "text": message[1],
                                           "program": os.path.basename(program["path"])})
                aborted = aborted or message[0] in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR)
                message = errors.poll()
            if external:
                trigger = bool(stat.dout[external["trigger"]])
                if trigger and not trigger_was:
                    k = external["node_out"]
                    node, set_, rep = (int(round(stat.aout[k])), int(round(stat.aout[k + 1])),
                                       int(round(stat.aout[k + 2])))
                    x = getp("smtcal-robot-model.0.x-real") + rng.gauss(0, external["noise_mm"])
                    y = getp("smtcal-robot-model.0.y-real") + rng.gauss(0, external["noise_mm"])
                    ext_file.write(f"{node},{set_},{rep},{x:.6f},{y:.6f}\n")
                    ext_file.flush()
                    hal([f"sets {external['done_signal']} true"])
                elif not trigger and trigger_was:
                    hal([f"sets {external['done_signal']} false"])
                trigger_was = trigger
            if stat.interp_state != linuxcnc.INTERP_IDLE:
                running_seen = True
            elif running_seen or aborted:
                break
            time.sleep(0.001)
        time.sleep(0.2)
        stat.poll()
        message = errors.poll()
        while message:
            record["messages"].append({"t": now(), "kind": message[0], "text": message[1],
                                       "program": os.path.basename(program["path"])})
            aborted = aborted or message[0] in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR)
            message = errors.poll()
        record["programs"].append({"path": program["path"], "began_s": began, "ran_s": round(now() - began, 3),
                                   "aborted": aborted})
        if aborted:
            end = "aborted in " + os.path.basename(program["path"])
            break
    if ext_file:
        ext_file.close()
    save(end)


if __name__ == "__main__":
    main()
