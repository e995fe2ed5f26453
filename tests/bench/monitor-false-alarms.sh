#!/bin/sh
# monitor-false-alarms.sh SMTCAL [SHIFTS] [SCANS] [BASELINE] - smtcal monitor's
# false alarms (docs/monitor.md, "Figures"): SHIFTS in-control logs of the
# paper cell (seeds 1..SHIFTS), SCANS scans each, made by smtcal simulate
# --record with the default truth (the board's play, the sensor's noise, no
# drift), each read by smtcal monitor as one shift's log. Prints how many
# shifts alarmed (exit 4), by which chart, how many baselines Phase I
# refused as drifting (exit 1) or found outliers in, and the false alarms
# per 1000 scans. Run from the source tree's top.
set -e
smtcal=${1:-build/smtcal}
shifts=${2:-100}
scans=${3:-1000}
baseline=${4:-50}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cell=examples/paper-cell/paper.cell.toml
for seed in $(seq 1 "$shifts"); do
  "$smtcal" simulate tests/linuxcnc-sim/monitor.place --cell $cell --cycles "$scans" --seed "$seed" \
    --record "$work/$seed.log" -q > /dev/null
  code=0
  "$smtcal" monitor "$work/$seed.log" --cell $cell --baseline "$baseline" --json --exit-zero \
    > "$work/$seed.json" 2> "$work/$seed.err" || code=$?
  echo "$code" > "$work/$seed.exit"
  rm -f "$work/$seed.log"
done
python3 - "$work" "$shifts" "$scans" <<'PY'
import collections, json, os, sys
work, shifts, scans = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
alarmed, refused, outliers, charts, signals, judged = 0, 0, 0, collections.Counter(), collections.Counter(), 0
for seed in range(1, shifts + 1):
    err = open(os.path.join(work, f"{seed}.err")).read()
    if "outliers" in err or "far from their neighbours" in err:
        outliers += 1
    if open(os.path.join(work, f"{seed}.exit")).read().strip() != "0":
        refused += 1  # Phase I refused the baseline (a drift in it): nothing judged
        continue
    judged += 1
    board = json.load(open(os.path.join(work, f"{seed}.json")))["fixtures"][0]
    if board["findings"]:
        alarmed += 1
    for finding in board["findings"]:
        for chart in finding["charts"] or ["refusals " + str(finding.get("check"))]:
            charts[chart] += 1
    for name, chart in board["charts"].items():
        for run in chart.get("rules", []):
            if not run["rule"].startswith(("cusum", "ewma")):
                signals[run["rule"]] += 1
print(f"{alarmed} of {judged} judged in-control shifts of {scans} scans alarmed "
      f"({1000 * alarmed / max(1, judged * scans):.3f} false alarms per 1000 scans, at most one counted per shift)")
print(f"{refused} of {shifts} baselines refused by Phase I as drifting; {outliers} with outliers left out")
print("alarms by chart:", dict(charts) or "none")
print("Nelson's rules and the moving range (signals, not the verdict), runs per 1000 scans:",
      {rule: round(1000 * n / max(1, judged * scans), 2) for rule, n in sorted(signals.items())})
PY
