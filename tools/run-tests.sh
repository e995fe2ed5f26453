#!/usr/bin/env bash
# Builds smtcal and runs every test (unit, golden, integration) with CTest.
#   bash tools/run-tests.sh              # build/ , RelWithDebInfo
#   bash tools/run-tests.sh --sanitize   # build-asan/, AddressSanitizer + UBSan
#   bash tools/run-tests.sh --fuzz [S]   # build-fuzz/, every libFuzzer harness for S s (default 30)
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--fuzz" ]; then
  bash tools/install-deps.sh
  exec bash tests/fuzz/run-fuzzers.sh "${2:-30}"
fi

build_dir=build
cmake_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo)
if [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-asan
  cmake_flags=(-DCMAKE_BUILD_TYPE=Debug -DSMTCAL_SANITIZE=ON)
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
fi

bash tools/install-deps.sh
cmake -S . -B "$build_dir" "${cmake_flags[@]}"
cmake --build "$build_dir" -j"$(nproc)"
ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)"
