#!/usr/bin/env bash
# Makes the seed corpora tests/fuzz/corpus/<harness>/ anew from the golden
# inputs (tests/golden/) and the example cell, so every harness starts from
# real files of its kind. The corpora are committed; run this after adding
# golden cases, then review `git status tests/fuzz/corpus`.
set -euo pipefail
cd "$(dirname "$0")/../.."
corpus=tests/fuzz/corpus
golden=tests/golden

# seed HARNESS FILE... : copies each file as <suite>_<name> (inputs only).
seed() {
  local harness=$1
  shift
  mkdir -p "$corpus/$harness"
  for file in "$@"; do
    [ -f "$file" ] || continue
    case "$file" in *.out | *.err | *.args | *.exit | */ARGS) continue ;; esac
    cp "$file" "$corpus/$harness/$(basename "$(dirname "$file")")_$(basename "$file")"
  done
}

rm -rf "$corpus"
places=("$golden"/check/*.place "$golden"/syntax/*.place "$golden"/fmt/*.place examples/paper-cell/layers.place)
seed place_check "${places[@]}"
seed fmt_roundtrip "${places[@]}"
seed compile "$golden"/compile/*.place "$golden"/verify/*.place "$golden"/linuxcnc/*.place "$golden"/simulate/*.place \
  examples/paper-cell/layers.place
seed table_csv "$golden"/tables-check/*.csv "$golden"/tables-stats/*.csv "$golden"/tables-plot/*.csv
seed raw_csv "$golden"/tables-build/*.csv examples/paper-cell/placing-raw.csv
seed points_csv "$golden"/tables-solve/*.csv
seed trips_csv "$golden"/fixture/*.csv
seed cell_toml "$golden"/cell/*.toml examples/paper-cell/paper.cell.toml
seed feeders_toml "$golden"/import-feeders/*.toml "$golden"/import-data/*.toml
seed truth_toml "$golden"/simulate/data/*.toml
seed previous_json "$golden"/fixture/data/*.json
# The CAD harness reads its first byte as the format choice: 7 (0x07) is
# "detect", so a seed is that byte followed by a real list.
mkdir -p "$corpus/cad"
for file in "$golden"/import-formats/* "$golden"/import-options/* "$golden"/import-samples/* "$golden"/import-data/board.csv; do
  case "$file" in *.out | *.err | *.args | *.exit | */ARGS | *.toml) continue ;; esac
  { printf '\x07'; cat "$file"; } > "$corpus/cad/$(basename "$(dirname "$file")")_$(basename "$file")"
done
# The machine harness reads an INI, then after a line %%HAL%% its HAL file,
# as machine.ini and machine.hal: each INI of the golden machines and the
# example, its #INCLUDE written in place and its HALFILE named machine.hal.
mkdir -p "$corpus/linuxcnc_ini"
for ini in "$golden"/linuxcnc/machines/*.ini examples/linuxcnc/paper-cell.ini; do
  python3 - "$ini" "$corpus/linuxcnc_ini/$(basename "$(dirname "$ini")")_$(basename "$ini")" <<'PY'
import os, re, sys
ini, out = sys.argv[1], sys.argv[2]
folder = os.path.dirname(ini)
text = open(ini).read()
text = re.sub(r"^#INCLUDE (\S+)$", lambda m: open(os.path.join(folder, m.group(1))).read(), text, flags=re.M)
hal = re.search(r"^HALFILE = (\S+\.hal)$", text, flags=re.M)
if hal and os.path.isfile(os.path.join(folder, hal.group(1))):
    hal_text = open(os.path.join(folder, hal.group(1))).read()
    text = text.replace(hal.group(0), "HALFILE = machine.hal") + "\n%%HAL%%\n" + hal_text
open(out, "w").write(text)
PY
done
# Cycle-record logs: the monitor goldens (the long simulated ones go by the
# 64 KiB rule below).
seed record_log "$golden"/monitor/*.log
# Measuring logs: the measure-read goldens and the guide's station logs
# (examples/calibrating/logs, read against the guide's plan).
seed measure_log "$golden"/measure-read/*.log examples/calibrating/logs/*.log
# The loop that runs the compile-time trace to its 5 000 000-statement limit
# takes 0.3 s in a release build but 10-90 s under the sanitizers on a busy
# machine: every mutation of it would be a timeout. The golden suite keeps it.
rm -f "$corpus"/compile/*warn_trace_incomplete*
# Anything over 64 KiB slows the fuzzers more than it teaches them.
find "$corpus" -type f -size +64k -delete
du -sh "$corpus"
for dir in "$corpus"/*; do echo "$(basename "$dir"): $(ls "$dir" | wc -l) files"; done
