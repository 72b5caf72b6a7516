#!/usr/bin/env bash
# On-demand fuzzing (issue 8): builds the libFuzzer targets with clang, ASan and UBSan
# (MOCAP_FUZZ=ON, build folder build-fuzz or $MOCAP_FUZZ_BUILD) and runs each for the
# given number of seconds, starting from the committed seeds in tests/fuzz/corpus/<name>/.
# New interesting inputs go to <build>/fuzz-corpus/<name>/ (never into the source tree);
# crashes go to <build>/fuzz-findings/<name>/. A crash input should be added to
# tests/fuzz/corpus/<name>/ as a regression seed once fixed (CI replays every seed).
# Usage: deploy/fuzz.sh [SECONDS_PER_TARGET (default 60)] [TARGET ...]
#   targets: pgm rig targets joints model frames_csv datagram blob_detector blob_file
# Environment: MOCAP_FUZZ_BUILD (build folder), MOCAP_FUZZ_JOBS (parallel fuzzing
# processes per target, default 1), MOCAP_FUZZ_NICE (nice level, default 10).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
if [ $# -gt 0 ]; then shift; fi
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || [ "$seconds" -lt 1 ]; then
  echo "fuzz.sh: the duration must be a whole number of seconds >= 1, got '$seconds'" >&2
  exit 2
fi
all_targets=(pgm rig targets joints model frames_csv datagram blob_detector blob_file)
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then targets=("${all_targets[@]}"); fi
for t in "${targets[@]}"; do
  if [ ! -d "$root/tests/fuzz/corpus/$t" ]; then
    echo "fuzz.sh: unknown target '$t' (one of: ${all_targets[*]})" >&2
    exit 2
  fi
done
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (bash deploy/install-deps.sh installs it; --for test does not)" >&2; exit 2; }

build="${MOCAP_FUZZ_BUILD:-$root/build-fuzz}"
jobs="${MOCAP_FUZZ_JOBS:-1}"
nice_level="${MOCAP_FUZZ_NICE:-10}"

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DMOCAP_FUZZ=ON -DMOCAP_SANITIZE="address;undefined" \
  -DMOCAP_BUILD_BENCH=OFF >/dev/null
nice -n "$nice_level" cmake --build "$build" --target mocap_fuzzers

failed=()
for t in "${targets[@]}"; do
  work="$build/fuzz-corpus/$t"
  findings="$build/fuzz-findings/$t"
  mkdir -p "$work" "$findings"
  echo "== fuzz_$t for ${seconds}s (corpus $work, findings $findings)"
  extra=()
  # -jobs writes each worker's log to ./fuzz-N.log: run from the build folder.
  if [ "$jobs" -gt 1 ]; then extra=(-jobs="$jobs" -workers="$jobs"); fi
  if ! (cd "$build" && nice -n "$nice_level" "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" \
      -max_len=65536 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "${extra[@]}" \
      -artifact_prefix="$findings/" "$work" "$root/tests/fuzz/corpus/$t" 2>"$build/fuzz-$t.log"); then
    failed+=("$t")
    echo "   FOUND A PROBLEM: see $build/fuzz-$t.log and $findings/"
  fi
  grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb|^#[0-9]+ *DONE" "$build/fuzz-$t.log" | sed 's/^/   /' || true
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: findings in: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz.sh: no crash in ${targets[*]} (${seconds}s each)"
