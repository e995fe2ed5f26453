#!/bin/sh
# make-logs.sh SMTCAL - writes the recorded logs of the monitor's golden
# tests (tests/golden/monitor/) with smtcal simulate --record: the paper cell
# in control, and drifting from cycle 60 on as each truth file here says.
# Run from the source tree's top; the logs are committed (recorded data: a
# change of simulate does not change them). The stored baseline
# data/in_control.baseline holds the SHA-256 of examples/paper-cell's cell
# file and tables: after a change of them, run this again (the golden
# phase2 says "taken with cell ... as it was then" otherwise).
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
# The stored baseline (Phase I) of the in-control log, for the golden phase2
# (board_walk.log judged against it, Phase II).
"$smtcal" monitor $out/in_control.log --cell $cell --baseline-out $out/data/in_control.baseline -q > /dev/null

# Refusals that rise: a clean start (100 cycles), then one scan in 33 with a
# missed trip (700 cycles, a restart between: two runs of the log).
rise=$(mktemp)
"$smtcal" simulate $program --cell $cell --cycles 100 --seed 41 --record $out/refusals_rise.log -q > /dev/null
"$smtcal" simulate $program --cell $cell --cycles 700 --seed 42 --missed-trip-rate 0.03 --record "$rise" -q > /dev/null
cat "$rise" >> $out/refusals_rise.log
rm -f "$rise"

# The small logs of the warn_* and fail_record_* tests: twelve scans of
# monitor.place (a baseline of 10 and two more), each test's one change made
# by hand here.
base=$(mktemp)
more=$(mktemp)
"$smtcal" simulate tests/linuxcnc-sim/monitor.place --cell $cell --cycles 12 --seed 30 --record "$base" -q > /dev/null
"$smtcal" simulate tests/linuxcnc-sim/monitor.place --cell $cell --cycles 6 --seed 31 --record "$more" -q > /dev/null
# Another cell's run after this cell's: left out, never pooled.
{ cat "$base"; sed 's/^smtcal-record 2 cell=paper-cell /smtcal-record 2 cell=other-cell /' "$more"; } \
  > $out/warn_monitor_other_cell.log
# Trip T3 of cycle 3 moved by 10 µm: the record no longer what its trips give.
awk '$1 == "trip" && $3 == 3 && $4 == 3 { $6 = sprintf("%.9f", $6 + 0.01) } { print }' "$base" \
  > $out/warn_monitor_record_disagrees.log
# The last record without its last four trips; two cycles skipped.
awk '!($1 == "trip" && $3 == 12 && $4 >= 5) { print }' "$base" > $out/warn_record_incomplete.log
awk '($1 == "cycle" || $1 == "checks" || $1 == "trip") && $3 >= 5 { $3 += 2 } { print }' "$base" \
  > $out/warn_record_cycle_gap.log
# A power cut in cycle 7's trip lines: the line cut after 14 bytes, 4096 NUL
# bytes where the file's size ran ahead of its data, then the restart's run.
awk '$1 == "trip" && $3 == 7 && $4 == 3 { exit } { print }' "$base" > $out/warn_record_damaged.log
awk '$1 == "trip" && $3 == 7 && $4 == 3 { printf "%s", substr($0, 1, 14); exit }' "$base" >> $out/warn_record_damaged.log
head -c 4096 /dev/zero >> $out/warn_record_damaged.log
cat "$more" >> $out/warn_record_damaged.log
# The same cut, the restart's begin line written right after it (no NUL bytes).
awk '$1 == "trip" && $3 == 7 && $4 == 3 { exit } { print }' "$base" > $out/warn_record_damaged_cut_line.log
awk '$1 == "trip" && $3 == 7 && $4 == 3 { printf "%s", substr($0, 1, 14); exit }' "$base" \
  >> $out/warn_record_damaged_cut_line.log
cat "$more" >> $out/warn_record_damaged_cut_line.log
# Lines no writer writes between records, a field that is not a number, two
# trip lines swapped: each the one stretch it spoils, the other records read.
awk '{ print } $1 == "trip" && $3 == 2 && $4 == 8 { print "pose 0 2 138.0 40.0" }' "$base" \
  > $out/warn_record_damaged_unknown_line.log
awk '$1 == "trip" && $3 == 3 && $4 == 2 { $5 = "x" $5 } { print }' "$base" > $out/warn_record_damaged_field.log
awk '$1 == "trip" && $3 == 5 && $4 == 1 { held = $0; next } { print } $1 == "trip" && $3 == 5 && $4 == 2 { print held }' \
  "$base" > $out/warn_record_damaged_out_of_order.log
# The log given twice (warn_record_repeated.args names it twice).
cp "$base" $out/warn_record_repeated.log
# One baseline record's S1 moved by 1.5 mm: an outlier the baseline leaves out.
awk '$1 == "cycle" && $3 == 5 { $7 = sprintf("%.9f", $7 + 1.5) } { print }' "$base" \
  > $out/warn_monitor_baseline_outliers.log
# Values no scan gives: S1 x of 1e300; S1 at (1000, 1000) mm, outside the
# robot's travel; check 7 (line_residual) of 1e300; a time before the last.
awk '$1 == "cycle" && $3 == 4 { $7 = "1e300" } { print }' "$base" > $out/fail_record_absurd_value.log
awk '$1 == "cycle" && $3 == 4 { $7 = "1000"; $8 = "1000" } { print }' "$base" > $out/fail_record_absurd_value_travel.log
awk '$1 == "checks" && $3 == 4 { $10 = "1e300" } { print }' "$base" > $out/fail_record_absurd_value_check.log
awk '$1 == "cycle" && $3 == 5 { $6 = sprintf("%.9f", $6 - 10) } { print }' "$base" \
  > $out/fail_record_inconsistent_time.log
# A begin line with a trip count no runtime writes; no begin line at all.
sed '1s/fixtures=Board:8/fixtures=Board:40/' "$base" > $out/fail_record_bad_field.log
tail -n +2 "$base" > $out/fail_record_no_begin.log
rm -f "$base" "$more"
