#!/usr/bin/env bash
# A/B measurement of the Foxglove live view's cost on the tracker (docs/performance.md):
# alternating runs of `mocap run --rate 100 --duration D --stats` without the live view
# (A) and with `--foxglove` plus one reference viewer subscribed to every channel (B;
# tests/foxglove/viewer_check.mjs). Prints one line per run and the trigger-to-publish
# p50/p99 of each. Needs the npm packages of tests/foxglove (ctest -R foxglove_npm_ci).
# With ROS2_READER=build/bench/publish/ros2_reader in the environment (and --ros2 among
# the B flags), a ROS 2-style DDS subscriber (ROS_DOMAIN_ID) reads /joint_states and /tf
# during every B run, so that the DDS writer has a matched reader.
# With HOUSEKEEPING_CPU=N, mocap starts under `taskset -c N` (as the service's
# CPUAffinity= does), so its non-real-time threads (main, DDS, Foxglove server and
# encoder) run on CPU N, and so do the viewer and the DDS reader, in A and B alike; the
# real-time stages pin themselves to the stage table's CPUs.
#   bench/foxglove/viewer_ab.sh MOCAP NPM_DIR [PAIRS=3] [DURATION_S=20] [EXTRA_B_FLAGS...]
set -euo pipefail
mocap=$1
npm_dir=$2
pairs=${3:-3}
duration=${4:-20}
shift $(( $# < 4 ? $# : 4 ))
extra_b=("$@")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
p99() {
  python3 - "$1" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
p = s["stages"]["publish"]
w = s["stages"].get("sink_work", {"p50_us": float("nan"), "p99_us": float("nan")})
c = s.get("counters", {})
fox = "/".join(str(c.get(k, "-")) for k in ("output_foxglove_published", "output_foxglove_dropped"))
each = " ".join(f'{k[10:]} {v["p99_us"]:.0f}/{v["max_us"]:.0f}'
                for k, v in s["stages"].items() if k.startswith("sink_work_"))
iw = s["stages"].get("identify_work", {"p99_us": float("nan")})
print(f'{s["published"]}/{s["triggered"]} p50 {p["p50_us"]:.0f} p99 {p["p99_us"]:.0f} '
      f'p99.9 {p["p999_us"]:.0f} max {p["max_us"]:.0f} identify_work p99 {iw["p99_us"]:.0f} '
      f'sink_work p50 {w["p50_us"]:.0f} p99 {w["p99_us"]:.0f} (p99/max per sink: {each}) '
      f'foxglove published/dropped {fox}')
PY
}
pin=()
[[ -n "${HOUSEKEEPING_CPU:-}" ]] && pin=(taskset -c "$HOUSEKEEPING_CPU")
for i in $(seq 1 "$pairs"); do
  udp=$(free_port)
  "${pin[@]}" "$mocap" run --rate 100 --loop-frames 50 --duration "$duration" --no-iceoryx --stats-interval 0 --udp "127.0.0.1:$udp" \
    --stats "$work/a.json" >"$work/a.log" 2>&1
  echo "A-$i: $(p99 "$work/a.json")"
  port=$(free_port)
  "${pin[@]}" "$mocap" run --rate 100 --loop-frames 50 --duration "$duration" --no-iceoryx --stats-interval 0 --udp "127.0.0.1:$udp" \
    --foxglove "127.0.0.1:$port" "${extra_b[@]}" --stats "$work/b.json" >"$work/b.log" 2>&1 &
  pid=$!
  for _ in $(seq 1 100); do (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null && break; sleep 0.1; done
  reader_pid=
  : >"$work/reader.log"
  if [[ -n "${ROS2_READER:-}" ]]; then
    "${pin[@]}" "$ROS2_READER" $((duration - 3)) >"$work/reader.log" 2>&1 &
    reader_pid=$!
  fi
  "${pin[@]}" node "$npm_dir/viewer_check.mjs" "ws://127.0.0.1:$port" $((duration - 3)) 30 >"$work/viewer.log" 2>&1 || true
  [[ -n "$reader_pid" ]] && wait "$reader_pid" || true
  wait "$pid"
  echo "B-$i: $(p99 "$work/b.json")  viewer: $(tr '\n' ' ' <"$work/viewer.log") $(cat "$work/reader.log")"
done
