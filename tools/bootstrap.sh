#!/usr/bin/env bash
# One command from a fresh Debian 12 machine (as root) to a working smtcal:
# installs the dependencies, builds the smtcal executable (only it: the tests
# and benchmarks are built by tools/run-tests.sh), and runs smtcal on the
# shipped example.
set -euo pipefail
cd "$(dirname "$0")/.."

bash tools/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build build -j"$(nproc)" --target smtcal

example=examples/paper-cell
echo "== smtcal check $example/layers.place"
build/smtcal check "$example/layers.place"
echo "== smtcal fmt $example/layers.place (canonical form, first 20 lines)"
build/smtcal fmt "$example/layers.place" -o build/layers.fmt.place
head -n 20 build/layers.fmt.place
build/smtcal fmt --check "$example/layers.place" && echo "(the example is already in canonical form)"
echo "== smtcal table stats $example/placing-table.csv"
build/smtcal table stats "$example/placing-table.csv"
echo "== smtcal cell check $example/paper.cell.toml"
build/smtcal cell check "$example/paper.cell.toml"
echo "== smtcal verify $example/layers.place --cell $example/paper.cell.toml"
build/smtcal verify "$example/layers.place" --cell "$example/paper.cell.toml"
echo "== smtcal compile $example/layers.place --cell $example/paper.cell.toml -o build/layers.corrected.place"
build/smtcal compile "$example/layers.place" --cell "$example/paper.cell.toml" \
  -o build/layers.corrected.place --report build/layers.report.json
diff "$example/layers.place" build/layers.corrected.place | head -n 30 || true
echo "== smtcal compile $example/layers.place --cell $example/paper.cell.toml --target linuxcnc -o build/layers-linuxcnc"
build/smtcal compile "$example/layers.place" --cell "$example/paper.cell.toml" --target linuxcnc -o build/layers-linuxcnc
head -n 12 build/layers-linuxcnc/layers.ngc
ls build/layers-linuxcnc/subroutines
echo "== smtcal simulate $example/layers.place --cell $example/paper.cell.toml --cycles 1000 --seed 1"
build/smtcal simulate "$example/layers.place" --cell "$example/paper.cell.toml" --cycles 1000 --seed 1
cat <<NEXT
bootstrap: done; smtcal is build/smtcal (build/smtcal --help, and --help on every command).
Next:
  build/smtcal import YOUR-LIST.pos --cell $example/paper.cell.toml --feeders $example/feeders.toml -o board.place
      a KiCad, Altium or EasyEDA placement list to a program (docs/import.md)
  build/smtcal verify board.place --cell $example/paper.cell.toml
      every part's error budget against its tolerance (docs/compile.md)
  build/smtcal compile board.place --cell $example/paper.cell.toml --target linuxcnc -o board-linuxcnc
      the calibrated program for LinuxCNC (docs/linuxcnc.md)
  bash tools/run-tests.sh
      builds the tests and runs them all
NEXT
