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
# The small logs of the warn_* tests: six scans of monitor.place, each test's
# one change made by hand here (a line's y moved by 10 µm, the last line cut
# off, the last record without its last four trips, two cycles skipped,
# another cell's name).
base=$(mktemp)
"$smtcal" simulate tests/linuxcnc-sim/monitor.place --cell $cell --cycles 6 --seed 30 --record "$base" -q > /dev/null
sed 's/^smtcal-record 2 cell=paper-cell /smtcal-record 2 cell=other-cell /' "$base" > $out/warn_monitor_other_cell.log
awk '$1 == "trip" && $3 == 3 && $4 == 3 { $6 = sprintf("%.9f", $6 + 0.01) } { print }' "$base" \
  > $out/warn_monitor_record_disagrees.log
head -c -1 "$base" > $out/warn_record_cut_off.log
awk '!($1 == "trip" && $3 == 6 && $4 >= 5) { print }' "$base" > $out/warn_record_incomplete.log
awk '($1 == "cycle" || $1 == "checks" || $1 == "trip") && $3 >= 5 { $3 += 2 } { print }' "$base" \
  > $out/warn_record_cycle_gap.log
rm -f "$base"
