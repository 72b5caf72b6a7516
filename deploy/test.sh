#!/usr/bin/env bash
# Installs the dependencies, builds, and runs the whole test suite:
#   1. AddressSanitizer + UndefinedBehaviorSanitizer: every test (ctest), including the
#      `mocap` end-to-end checks, the fuzz-corpus replays and the fault-injection tests;
#   2. ThreadSanitizer: the tests labelled "concurrency" (rings, pipeline, publishers,
#      service, faults).
# Both at -O1 without debug info (sanitizer reports still name the functions), the tests'
# own code at -O0, and as unity builds (CMAKE_UNITY_BUILD: a few sources per compiler
# run), which keeps the CI time (2 cores) down. The optimised build (-O2, the shipped flags,
# plus the benchmarks) runs the same suite when MOCAP_TEST_OPTIMISED=1; `deploy/demo.sh`
# builds the Release binary.
# This is the README's second command and exactly what .ci/run runs.
# Usage: bash deploy/test.sh            (from the repository root, as root or with sudo)
#   MOCAP_TEST_OPTIMISED=1 bash deploy/test.sh        also the optimised build and its tests
#   MOCAP_TEST_SKIP_SANITIZERS=1 bash deploy/test.sh  only the optimised build and its tests
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
if [ "${MOCAP_TEST_OPTIMISED:-0}" = "1" ] || [ "${MOCAP_TEST_SKIP_SANITIZERS:-0}" = "1" ]; then
  bash deploy/install-deps.sh  # the optimised build includes bench/ (OpenCV baseline)
else
  bash deploy/install-deps.sh --for test
fi

jobs=$(nproc 2>/dev/null || echo 2)
export CTEST_OUTPUT_ON_FAILURE=1

if [ "${MOCAP_TEST_OPTIMISED:-0}" = "1" ] || [ "${MOCAP_TEST_SKIP_SANITIZERS:-0}" = "1" ]; then
  echo "== build: optimised, no debug info (tests + benchmarks)"
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -DNDEBUG" >/dev/null
  cmake --build build -j"$jobs"
  echo "== test: optimised"
  ctest --test-dir build -j"$jobs" --timeout 300
fi

if [ "${MOCAP_TEST_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== build: AddressSanitizer + UndefinedBehaviorSanitizer"
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1" -DMOCAP_SANITIZE="address;undefined" -DMOCAP_BUILD_BENCH=OFF \
    -DCMAKE_UNITY_BUILD=ON >/dev/null
  cmake --build build-asan -j"$jobs" --target mocap mocap_all_tests
  echo "== test: AddressSanitizer + UndefinedBehaviorSanitizer"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    MOCAP_SANITIZER=asan ctest --test-dir build-asan -j"$jobs" --timeout 600

  echo "== build: ThreadSanitizer (concurrency tests)"
  cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1" -DMOCAP_SANITIZE=thread -DMOCAP_BUILD_BENCH=OFF \
    -DCMAKE_UNITY_BUILD=ON >/dev/null
  cmake --build build-tsan -j"$jobs" --target mocap_concurrency_tests
  echo "== test: ThreadSanitizer"
  # atexit_sleep_ms: TSan sleeps 1 s at every process exit by default, to catch threads
  # still running then; every test joins its threads first, and ctest starts one process
  # per test, so 50 ms keeps the check and saves about a minute.
  TSAN_OPTIONS=halt_on_error=1:atexit_sleep_ms=50 MOCAP_SANITIZER=tsan \
    ctest --test-dir build-tsan -L concurrency -j"$jobs" --timeout 600 --no-tests=error
fi
echo "== all test configurations passed"
