#!/usr/bin/env bash
# One command from a fresh Debian 12 machine (as root) to a working smtcal:
# installs the dependencies, builds, and runs smtcal on the shipped example.
set -euo pipefail
cd "$(dirname "$0")/.."

bash tools/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build -j"$(nproc)"

example=examples/paper-cell
echo "== smtcal check $example/layers.place"
build/smtcal check "$example/layers.place"
echo "== smtcal fmt $example/layers.place (canonical form)"
build/smtcal fmt "$example/layers.place"
echo "== smtcal table stats $example/placing-table.csv"
build/smtcal table stats "$example/placing-table.csv"
echo "bootstrap: done; smtcal is build/smtcal"
