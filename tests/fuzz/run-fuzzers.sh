#!/usr/bin/env bash
# Builds the libFuzzer harnesses in the sanitizer build (build-asan/, clang
# 14, ASan + UBSan; the same objects `tools/run-tests.sh --sanitize` tests)
# and runs each for a bounded time from its seed corpus and regression inputs.
# Exit 1 on any finding: a crash, an abort (internal check, escaping
# exception, a failed property), a leak, a sanitizer report, a timeout
# (-timeout: 10 s for one input, 60 s in the compile harness) or more memory
# than -rss_limit_mb. The finding's input is left
# in build-asan/findings/; copy it to tests/fuzz/regressions/<harness>/.
#
#   bash tests/fuzz/run-fuzzers.sh [SECONDS_PER_HARNESS] [HARNESS...]
#
# Default 30 s each (CI). The seed is fixed (-seed=1): a run explores the
# same inputs in the same order on every machine, so a finding reproduces;
# a faster machine only goes further along the same sequence. The campaign in tests/fuzz/README.md used longer
# runs under `nice -n 19`. Runs as many harnesses at once as there are cores.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-30}
shift || true

build=build-asan
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DSMTCAL_SANITIZE=ON \
  -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 "${launcher[@]}" >/dev/null
cmake --build "$build" -j"$(nproc)" --target smtcal_fuzzers

harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
  for source in tests/fuzz/fuzz_*.cpp; do
    name=$(basename "$source" .cpp)
    name=${name#fuzz_}
    [ "$name" = support ] || harnesses+=("$name")
  done
fi

dict_of() {
  case "$1" in
    place_check | fmt_roundtrip | compile) echo place ;;
    table_csv | raw_csv | points_csv | trips_csv | text) echo csv ;;
    cell_toml | feeders_toml | truth_toml) echo toml ;;
    cad) echo cad ;;
    previous_json) echo json ;;
    linuxcnc_ini) echo ini ;;
    record_log) echo record ;;
    measure_log) echo measure ;;
  esac
}

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
mkdir -p "$build/findings" "$build/fuzz-logs"

run_one() {
  local name=$1
  local work="$build/fuzz-corpus/$name"
  mkdir -p "$work"
  local seeds=(tests/fuzz/corpus/"$name")
  [ -d tests/fuzz/regressions/"$name" ] && seeds+=(tests/fuzz/regressions/"$name")
  local dict
  dict=$(dict_of "$name")
  # One input may take this long. The compile harness's seeds include the
  # loop that runs the compile-time trace to its 5 000 000-statement limit:
  # 0.3 s in a release build, 10-20 s under the sanitizers.
  local timeout=10
  [ "$name" = compile ] && timeout=60
  if "$build/tests/fuzz/smtcal_fuzz_$name" "$work" "${seeds[@]}" \
      -dict="tests/fuzz/dict/$dict.dict" -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb=2048 \
      -max_len=65536 -seed=1 -print_final_stats=1 -artifact_prefix="$build/findings/$name-" \
      >"$build/fuzz-logs/$name.log" 2>&1; then
    echo "fuzz $name: $(grep -E '^stat::number_of_executed_units' "$build/fuzz-logs/$name.log" | awk '{print $2}') runs," \
         "$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$build/fuzz-logs/$name.log" | tail -1), no finding"
  else
    echo "fuzz $name: FINDING (log $build/fuzz-logs/$name.log, input $build/findings/$name-*)"
    tail -40 "$build/fuzz-logs/$name.log"
    return 1
  fi
}

failed=0
running=0
for name in "${harnesses[@]}"; do
  run_one "$name" &
  running=$((running + 1))
  if [ "$running" -ge "$(nproc)" ]; then
    wait -n || failed=$((failed + 1))
    running=$((running - 1))
  fi
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=$((failed + 1))
  running=$((running - 1))
done
echo "fuzz: $((${#harnesses[@]} - failed)) passed, $failed failed"
[ "$failed" -eq 0 ]
