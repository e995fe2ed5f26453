#!/usr/bin/env bash
# Runs each benchmark named by a filter alone, N times (default 3), each
# after a sync and a pause, and prints its CPU time, peak memory and output
# size: on a machine whose page cache and fresh memory cost vary from run
# to run, several lone runs say more than one run of the whole family.
#   N=5 tests/bench/run-alone.sh 'CompileLinuxCnc/placements:100000$' ...
# BENCH names the benchmark program (default: build/tests/smtcal_bench).
set -euo pipefail
bench=${BENCH:-build/tests/smtcal_bench}
runs=${N:-3}
for filter in "$@"; do
  for _ in $(seq "$runs"); do
    sync
    sleep 2
    "$bench" --benchmark_filter="$filter" 2>&1 | awk '/^BM/ {
      line = sprintf("%-45s cpu %8s %s", $1, $4, $5)
      for (i = 6; i <= NF; i++) if ($i ~ /peak_rss|output_mb/) line = line " " $i
      print line }'
  done
done
