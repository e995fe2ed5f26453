#!/bin/sh
# make-logs.sh SMTCAL - writes the recorded logs of the monitor's golden
# tests (tests/golden/monitor/) with smtcal simulate --record: the paper cell
# in control, and drifting from cycle 60 on as each truth file here says.
# Run from the source tree's top; the logs are committed (recorded data: a
# change of simulate does not change them).
set -e
smtcal=${1:-build/smtcal}
cell=examples/paper-cell/paper.cell.toml
program=tests/linuxcnc-sim/sim.place
out=tests/golden/monitor
"$smtcal" simulate $program --cell $cell --cycles 200 --seed 30 --record $out/in_control.log -q > /dev/null
for drift in board-walk robot-scale dirty-sensor; do
  "$smtcal" simulate $program --cell $cell --cycles 200 --seed 30 --truth $out/data/$drift.truth.toml \
    --record $out/$(echo $drift | tr - _).log -q > /dev/null
done
