#!/usr/bin/python3
# restart_driver.py - the DISPLAY program of the restart scenario
# (run_restart.py): the operator of a production line whose scans are
# refused now and then. Like driver.py it homes the machine, runs the
# program and feeds it boards through the transport handshake (Wait
# Sw(12) = On, On 14 releases), with the sensor HAL set to each board's
# true pose (driver.place_board); unlike it, when the runtime refuses a scan
# and aborts the program, the operator clears the board and starts the
# program again (cycle start), as a line does, so one controller run holds
# many program runs, each opening with its begin line in the cycle record.
#
# Plan ($SMTCAL_SIM_PLAN, JSON): "program", "sensor_models", "boards" (true
# poses; "present": false for a board the sensor cannot see: its scan is
# refused), "timeout_s". Written to $SMTCAL_SIM_RUN when the run ends: the
# operator messages, the boards fed, the program starts, the end. The
# scenario may kill the whole controller (a power cut) before that.
import json
import os
import sys
import time

import linuxcnc

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from driver import RELEASE_OUT, hal, place_board  # noqa: E402

REFUSAL = "smtcal: marker scan of fixture"


def main():
    plan = json.load(open(os.environ["SMTCAL_SIM_PLAN"]))
    out_path = os.environ["SMTCAL_SIM_RUN"]
    started = time.monotonic()
    record = {"messages": [], "fed": [], "starts": 0, "end": None}

    def now():
        return round(time.monotonic() - started, 3)

    def save(end):
        record["end"] = end
        with open(out_path + ".tmp", "w") as f:
            json.dump(record, f, indent=1)
        os.replace(out_path + ".tmp", out_path)

    stat, command, errors = linuxcnc.stat(), linuxcnc.command(), linuxcnc.error_channel()

    def wait_for(predicate, what, timeout_s=30):
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            stat.poll()
            if predicate():
                return
            time.sleep(0.005)
        save("timeout: " + what)
        sys.exit(1)

    def start_program():
        command.mode(linuxcnc.MODE_AUTO)
        command.wait_complete()
        command.auto(linuxcnc.AUTO_RUN, 0)
        record["starts"] += 1
        wait_for(lambda: stat.interp_state != linuxcnc.INTERP_IDLE, "the program to start")

    hal(["sets transport-clamped false"])
    command.state(linuxcnc.STATE_ESTOP_RESET)
    wait_for(lambda: stat.task_state == linuxcnc.STATE_ESTOP_RESET, "e-stop reset")
    command.state(linuxcnc.STATE_ON)
    wait_for(lambda: stat.task_state == linuxcnc.STATE_ON, "machine on")
    command.mode(linuxcnc.MODE_MANUAL)
    command.wait_complete()
    command.home(-1)
    wait_for(lambda: all(stat.homed[j] for j in range(stat.joints)), "homing")
    command.mode(linuxcnc.MODE_AUTO)
    command.wait_complete()
    command.program_open(plan["program"])
    command.wait_complete()
    start_program()

    boards = plan["boards"]
    fed = 0          # boards given so far
    clamped = False
    deadline = time.monotonic() + plan["timeout_s"]
    while True:
        if time.monotonic() > deadline:
            command.abort()
            save("timeout: the run took longer than %s s" % plan["timeout_s"])
            return
        stat.poll()
        message = errors.poll()
        aborted = None
        while message:
            record["messages"].append({"t": now(), "text": message[1], "board": fed - 1})
            aborted = message[1]
            message = errors.poll()
        if aborted is not None:
            # The program stopped. A refused scan: that board goes (the next
            # one comes); anything else (LinuxCNC's own probe race): the same
            # board is scanned again. Then cycle start, as an operator would.
            wait_for(lambda: stat.interp_state == linuxcnc.INTERP_IDLE, "the program to stop after an abort")
            hal(["sets transport-clamped false"])
            clamped = False
            if not aborted.strip().startswith(REFUSAL):
                fed -= 1
            if fed >= len(boards):
                break
            time.sleep(0.3)
            start_program()
            continue
        if clamped and stat.dout[RELEASE_OUT]:
            hal(["sets transport-clamped false"])  # the program released the board: this cycle is done
            clamped = False
            if fed == len(boards):
                break
        if not clamped and not stat.dout[RELEASE_OUT] and fed < len(boards):
            place_board(boards[fed], plan["sensor_models"])
            hal(["sets transport-clamped true"])
            clamped = True
            record["fed"].append({"t": now(), "board": fed, "present": boards[fed].get("present", True)})
            fed += 1
        time.sleep(0.002)
    command.abort()  # the operator stops the line after the planned boards
    time.sleep(0.2)
    save(f"stopped after {fed} boards")


if __name__ == "__main__":
    main()
