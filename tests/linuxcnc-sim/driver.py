#!/usr/bin/python3
# driver.py - the DISPLAY program of the simulated paper cell (run_scenario.py
# writes it into the derived INI's [DISPLAY] DISPLAY): it plays the operator
# and the cell's transport through LinuxCNC's Python interface and records
# what the machine did.
#
# Reads the plan (JSON, path in $SMTCAL_SIM_PLAN): the program, the board's
# true pose for each cycle, how many cycles to run. Then: e-stop reset,
# machine on, home all joints (the example's homing step: every joint homes
# where it stands, HOME_SEQUENCE 0 = Z first), AUTO, open the program, run.
# The program waits for the transport (Wait Sw(12) = On) before each cycle:
# the driver puts the board at the cycle's true pose (the sensor HAL's sum2
# gains and offsets, board-present) and then clamps it (transport-clamped);
# when the program releases it (On 14), the next board comes. After the last
# planned cycle the driver stops the program, as an operator would.
#
# Recorded from linuxcnc.stat, polled every millisecond (the task writes
# the status every millisecond, CYCLE_TIME; a probe move's result shows
# there for as little as 15 ms, the two-stage scan's moves back over an
# edge and latching it, its tripped flag for a few). Not at a realtime
# priority: without a realtime kernel LinuxCNC's servo thread runs at the
# normal one, and a driver that preempts it widens the window of LinuxCNC
# 2.9's "Queue is not empty after probing" race (the first run here with a
# SCHED_FIFO driver hit it); run_scenario.py runs the whole machine, driver
# included, at nice -10 instead, ahead of a parallel CTest's load.
# Each cycle records the longest gap between two polls:
#   probes   every probe move's result: motion's latched position
#            (probed_position, the #5061.. the runtime reads) and whether it
#            tripped; a new result is a change of the position;
#   vacuum   every change of the vacuum valve (motion.digital-out-08) with the
#            commanded position and speed at the first status update that
#            shows it: on = a Pick, off = a Place (M64/M65 wait until the
#            machine stands; on a loaded host the update can come as the
#            next move, the rise in z, begins);
#   messages every operator message (an abort is one);
#   poll_gap_max_s per cycle, the longest time between two status polls
#            (run_scenario.py names it when the probe moves do not add up);
#   trace    per cycle, the machine's position (x, y, z) at every status
#            update that shows it changed, from the clamp to the cycle's
#            first vacuum change: when the scan's first move began and
#            when the first placement move left the scan (run_scenario.py
#            measures the scan's overhead from it).
# With $SMTCAL_SIM_REAL_PINS (a robot model's HAL component, run_measure.py)
# every Place also records where the robot really was ("real": the model's
# position latched in the servo thread when the valve went off).
# Written to $SMTCAL_SIM_RUN (JSON) when the run ends.
import gc
import json
import os
import subprocess
import sys
import time
import math

import linuxcnc

VACUUM_OUT = 8      # layers.place: Vacuum 8 -> motion.digital-out-08
RELEASE_OUT = 14    # layers.place: On 14 releases the board (transport)


def hal(commands):
    """Runs halcmd commands (one per line) in one halcmd process."""
    subprocess.run(["halcmd", "-f"], input="\n".join(commands) + "\n", text=True, check=True)


def place_board(pose, sensor_models):
    """The board's true pose for the sensor HAL (marker-sensor.hal): per
    marker k (the models in marker order), f = R(a)^T (M p + b - o) into
    sum2.(2k) and sum2.(2k+1), where M p + b is where the robot really puts
    the sensor for a command p around that marker. A robot whose scale the
    tables do not know (robot_scale_ppm about robot_scale_about_mm, the
    monitor's scenario) puts it s (p - about) farther: M + s I, b - s about."""
    a = math.radians(pose["angle_deg"])
    c, s = math.cos(a), math.sin(a)
    o = (pose["x_mm"], pose["y_mm"])
    scale = pose.get("robot_scale_ppm", 0.0) * 1e-6
    about = pose.get("robot_scale_about_mm", [0.0, 0.0])
    commands = [f"sets board-present {'true' if pose.get('present', True) else 'false'}"]
    for k, model in enumerate(sensor_models):
        m = [[model["m"][0][0] + scale, model["m"][0][1]], [model["m"][1][0], model["m"][1][1] + scale]]
        b = [model["b"][0] - scale * about[0], model["b"][1] - scale * about[1]]
        rt = ((c, s), (-s, c))  # R(a)^T
        for row in range(2):
            g0 = rt[row][0] * m[0][0] + rt[row][1] * m[1][0]
            g1 = rt[row][0] * m[0][1] + rt[row][1] * m[1][1]
            offset = rt[row][0] * (b[0] - o[0]) + rt[row][1] * (b[1] - o[1])
            unit = 2 * k + row
            commands += [f"setp sum2.{unit}.gain0 {g0!r}", f"setp sum2.{unit}.gain1 {g1!r}",
                         f"setp sum2.{unit}.offset {offset!r}"]
    hal(commands)


def main():
    plan = json.load(open(os.environ["SMTCAL_SIM_PLAN"]))
    real_pins = os.environ.get("SMTCAL_SIM_REAL_PINS", "")  # the robot model's component, when there is one
    out_path = os.environ["SMTCAL_SIM_RUN"]
    started = time.monotonic()
    record = {"cycles": [], "messages": [], "vacuum": [], "end": None, "times": {}}

    def now():
        return round(time.monotonic() - started, 4)

    def drain_messages():
        """Every operator message LinuxCNC has queued, with the cycle it came in."""
        message = errors.poll()
        while message:
            record["messages"].append({"t": now(), "kind": message[0], "text": message[1],
                                       "cycle": len(record["cycles"]) - 1})
            message = errors.poll()

    def save(end):
        record["end"] = end
        record["times"]["total_s"] = now()
        with open(out_path + ".tmp", "w") as f:
            json.dump(record, f, indent=1)
        os.replace(out_path + ".tmp", out_path)

    stat, command, errors = linuxcnc.stat(), linuxcnc.command(), linuxcnc.error_channel()
    reader = None
    if real_pins:
        import hal as hal_module
        reader = hal_module.component("smtcal-sim-reader")
        reader.newpin("x", hal_module.HAL_FLOAT, hal_module.HAL_IN)
        reader.newpin("y", hal_module.HAL_FLOAT, hal_module.HAL_IN)
        reader.ready()
        hal([f"net placed-x {real_pins}.x-latched => smtcal-sim-reader.x",
             f"net placed-y {real_pins}.y-latched => smtcal-sim-reader.y"])

    def wait_for(predicate, what, timeout_s=30):
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            stat.poll()
            if predicate():
                return
            time.sleep(0.005)
        save("timeout: " + what)
        sys.exit(1)

    hal(["sets transport-clamped false"])
    command.state(linuxcnc.STATE_ESTOP_RESET)
    wait_for(lambda: stat.task_state == linuxcnc.STATE_ESTOP_RESET, "e-stop reset")
    command.state(linuxcnc.STATE_ON)
    wait_for(lambda: stat.task_state == linuxcnc.STATE_ON, "machine on")
    command.mode(linuxcnc.MODE_MANUAL)
    command.wait_complete()
    command.home(-1)  # all joints, in HOME_SEQUENCE order
    wait_for(lambda: all(stat.homed[j] for j in range(stat.joints)), "homing")
    command.mode(linuxcnc.MODE_AUTO)
    command.wait_complete()
    command.program_open(plan["program"])
    command.wait_complete()
    record["times"]["ready_s"] = now()

    cycles = plan["cycles"]
    cycle = None          # the record of the cycle the board is in
    next_cycle = 0
    clamped = False
    stat.poll()
    last_probe = tuple(stat.probed_position[:3])
    last_dout = {VACUUM_OUT: stat.dout[VACUUM_OUT], RELEASE_OUT: stat.dout[RELEASE_OUT]}
    # No cyclic garbage collector while polling: its full passes over the
    # growing record (a position every millisecond) stalled the polls by
    # tens of milliseconds (up to 68.6 ms beside other runs; 8.2 ms without
    # it); the record holds no cycles, reference counting frees the rest.
    gc.disable()
    command.auto(linuxcnc.AUTO_RUN, 0)
    running_seen = False
    deadline = time.monotonic() + plan["timeout_s"]
    end = None
    last_poll = time.monotonic()
    while end is None:
        polled = time.monotonic()
        if cycle is not None:
            cycle["poll_gap_max_s"] = round(max(cycle["poll_gap_max_s"], polled - last_poll), 4)
        last_poll = polled
        if polled > deadline:
            end = "timeout: the run took longer than %s s" % plan["timeout_s"]
            command.abort()
            break
        stat.poll()
        drain_messages()
        # A probe move's result: motion's latched position changes (the
        # tripped flag alone falls back when the next move starts).
        if cycle is not None and "traced" not in cycle:
            here = [round(v, 6) for v in stat.position[:3]]
            if not cycle["trace"] or cycle["trace"][-1][1:] != here:
                cycle["trace"].append([now()] + here)
        probe = tuple(stat.probed_position[:3])
        if probe != last_probe:
            last_probe = probe
            if cycle is not None:
                cycle["probes"].append({"t": now(), "x": probe[0], "y": probe[1], "z": probe[2],
                                        "tripped": bool(stat.probe_tripped)})
        for out in (VACUUM_OUT, RELEASE_OUT):
            if stat.dout[out] == last_dout[out]:
                continue
            last_dout[out] = stat.dout[out]
            if out == VACUUM_OUT:
                event = {"t": now(), "on": bool(stat.dout[out]), "position": list(stat.position[:6]),
                         "velocity": stat.current_vel, "cycle": len(record["cycles"]) - 1}
                if reader is not None and not event["on"]:
                    # Where the modelled robot really was when the valve went
                    # off (latched in the servo thread by run_measure.py's model).
                    event["real"] = [reader["x"], reader["y"]]
                record["vacuum"].append(event)
                if cycle is not None:
                    cycle["traced"] = True  # the trace ends at the cycle's first Pick
            elif stat.dout[out] and clamped:
                # The program released the board: this cycle is done.
                hal(["sets transport-clamped false"])
                clamped = False
                cycle["released_s"] = now()
                cycle = None
                if next_cycle == len(cycles):
                    command.abort()  # the operator stops the line after the planned boards
                    end = "stopped after %d cycles" % next_cycle
        if stat.interp_state != linuxcnc.INTERP_IDLE:
            running_seen = True
        elif running_seen or record["messages"]:
            end = "program ended" if not record["messages"] else "program aborted"
        if end is None and not clamped and cycle is None and next_cycle < len(cycles) and not stat.dout[RELEASE_OUT]:
            # The next board arrives at its true pose and is clamped.
            pose = cycles[next_cycle]
            place_board(pose, plan["sensor_models"])
            hal(["sets transport-clamped true"])
            clamped = True
            stat.poll()
            cycle = {"pose": pose, "clamped_s": now(), "probes": [], "poll_gap_max_s": 0.0,
                     "trace": [[now()] + [round(v, 6) for v in stat.position[:3]]]}
            record["cycles"].append(cycle)
            last_poll = time.monotonic()  # the board's placing is not a gap in the polls
            next_cycle += 1
        time.sleep(0.001)
    # Let the last status and messages arrive.
    time.sleep(0.2)
    stat.poll()
    drain_messages()
    record["final_dout"] = {str(VACUUM_OUT): bool(stat.dout[VACUUM_OUT])}
    save(end)


if __name__ == "__main__":
    main()
