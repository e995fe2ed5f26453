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
build/smtcal check "$example/layers.place" && echo "no errors, no warnings"
echo "== smtcal fmt $example/layers.place (canonical form, first 20 lines)"
build/smtcal fmt "$example/layers.place" -o build/layers.fmt.place
head -n 20 build/layers.fmt.place
build/smtcal fmt --check "$example/layers.place" && echo "(the example is already in canonical form)"
echo "== smtcal table stats $example/placing-table.csv"
build/smtcal table stats "$example/placing-table.csv"
echo "bootstrap: done; smtcal is build/smtcal"
