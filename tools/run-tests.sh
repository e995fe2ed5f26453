#!/usr/bin/env bash
# Builds smtcal and runs every test (unit, cli, golden, docs, fuzz replay,
# example, layering, LinuxCNC's controller) with CTest.
#   bash tools/run-tests.sh              # build/, RelWithDebInfo (GCC)
#   bash tools/run-tests.sh --sanitize   # build-asan/: clang, AddressSanitizer + UBSan, the suite
#                                        # but the LinuxCNC scenarios (they run in real time, the
#                                        # same commands as in build/)
#   bash tools/run-tests.sh --fuzz [S]   # build-asan/: every libFuzzer harness for S s (default 30)
# The LinuxCNC scenarios (label linuxcnc-sim) run after the rest, two at a
# time on their own: they run in real time, and a compiler or a sanitized
# test beside them on two cores delays the controller's polls.
# Where ccache is installed (a machine that keeps its cache between builds)
# the builds use it; tools/install-deps.sh does not install it, so a fresh
# machine, where a cache would only cost, builds without.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--fuzz" ]; then
  bash tools/install-deps.sh
  exec bash tests/fuzz/run-fuzzers.sh "${2:-30}"
fi

build_dir=build
cmake_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo)
ctest_flags=()
if [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-asan
  cmake_flags=(-DCMAKE_BUILD_TYPE=Debug -DSMTCAL_SANITIZE=ON
               -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14)
  ctest_flags=(-LE linuxcnc-sim)
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
fi
if command -v ccache >/dev/null; then
  cmake_flags+=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

bash tools/install-deps.sh
cmake -S . -B "$build_dir" "${cmake_flags[@]}"
cmake --build "$build_dir" -j"$(nproc)"
if [ ${#ctest_flags[@]} -eq 0 ]; then
  ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)" -LE linuxcnc-sim
  ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)" -L linuxcnc-sim
else
  ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)" "${ctest_flags[@]}"
fi
