#!/usr/bin/env bash
# Camera nodes on loopback (issue 29): what two `mocap node` processes add to the
# trigger-to-publish latency of the same recording tracked in one process.
#   (a) one process: `mocap run` with the recording's 8 cameras as local replay cameras;
#   (b) two nodes of 4 replay cameras each (`trigger: central`) and a central `mocap run`
#       with 8 `backend: node` cameras;
# both `pipeline: {pacing: lockstep}` at 100 Hz, so every frame of the recording is
# published, and both print `publish (end to end)` (p50, p99, p99.9, max in us), camera 0's
# frame's software trigger -> the frame's publication, in both on the tracker's
# CLOCK_MONOTONIC from the trigger's instant: in (a) the replay stamps its frame with its
# trigger() call (hal/replay_camera.h); in (b) the node camera with the trigger's instant,
# at which the nodes fire (node.trigger_lead_us ahead of it the central sent the trigger;
# with LEAD 0 the central's trigger() call, and the trigger's way to the node counts), so
# (b) adds the node's replay and detection (and the wait of a trigger that came after its
# instant), the blob message's way back and the central's hand-over of the blobs instead
# of the detection. The central's report also splits (b) into its
# legs (`node_trigger_leg`, `node_work`, `node_transit`).
# Usage: bash bench/pipeline/node_latency.sh [MOCAP] REC [OUT] [RUNS] [REALTIME] [DETECT] [LEAD]
#   REC: an 8-camera recording with targets.yaml and gt/model_true.yaml, e.g.
#        `mocap simulate --scene humanoid --cameras 8 --frames 200 --out REC`;
#   DETECT: each node's node.detect_threads, or `default` (min(4, CPUs)); 1 by default:
#        two nodes sharing this PC's cores split them as a lab splits a shared PC
#        (docs/operations.md), and (b) detects as (a) does: 4 cameras after one another on
#        each of the 2 cores;
#   LEAD: the central's node.trigger_lead_us (the nodes fire at the trigger's instant, the
#        trigger sent that long ahead; 0: they fire when it arrives, and its way counts),
#        or `default` (the configuration's default, 1000);
#   defaults: build/mocap, -, /tmp/node_latency, 3 runs, realtime false, 1, default.
# docs/performance.md records the figures with the machine.
set -euo pipefail
mocap=$(realpath "${1:-build/mocap}")
rec=$(realpath "$2")
out=${3:-/tmp/node_latency}
runs=${4:-3}
realtime=${5:-false}
detect=${6:-1}
workers=$([ "$detect" = default ] || echo ", detect_threads: $detect")
lead=${7:-default}
lead_key=$([ "$lead" = default ] || echo ", trigger_lead_us: $lead")
domain=$((100 + $$ % 100))
mkdir -p "$out"
rm -f "$out/added.txt"

tracker_keys() {
  printf 'targets: %s/targets.yaml\nmodel: %s/gt/model_true.yaml\n' "$rec" "$rec"
  printf 'pipeline: {pacing: lockstep, trigger_rate_hz: 100, realtime: %s}\n' "$realtime"
  printf 'outputs: {iceoryx: false}\n'
}

{
  echo "cameras:"
  for c in 0 1 2 3 4 5 6 7; do echo "  - {backend: replay, device: $rec, trigger: software}"; done
  tracker_keys
} >"$out/single.yaml"
for n in 0 1; do
  {
    printf 'node: {name: n%s, domain_id: %s%s}\npipeline: {realtime: %s}\ncameras:\n' "$n" "$domain" \
      "$workers" "$realtime"
    for c in $((4 * n)) $((4 * n + 1)) $((4 * n + 2)) $((4 * n + 3)); do
      echo "  - {backend: replay, device: $rec, camera: cam$c, trigger: central}"
    done
  } >"$out/node$n.yaml"
done
{
  printf 'node: {domain_id: %s, wait_s: 20, timeout_ms: 2000%s}\nrig: %s/rig.yaml\ncameras:\n' "$domain" \
    "$lead_key" "$rec"
  for c in 0 1 2 3 4 5 6 7; do echo "  - {backend: node, device: n$((c / 4))/cam$c}"; done
  tracker_keys
} >"$out/central.yaml"

e2e() { grep -E "publish \(end to end\)|^run:" "$1" | tr -s ' '; }
pct() { grep -E "publish \(end to end\)" "$1" | tr -s ' ' | awk '{print $6, $7}'; }  # p50 p99
for r in $(seq 1 "$runs"); do
  "$mocap" run --config "$out/single.yaml" --stats-interval 0 >"$out/single$r.txt" 2>&1
  echo "(a) one process, run $r: $(e2e "$out/single$r.txt" | tr '\n' ' ')"
  "$mocap" node --config "$out/node0.yaml" >"$out/node0_$r.txt" 2>&1 &
  n0=$!
  "$mocap" node --config "$out/node1.yaml" >"$out/node1_$r.txt" 2>&1 &
  n1=$!
  "$mocap" run --config "$out/central.yaml" --stats-interval 0 >"$out/central$r.txt" 2>&1 || true
  kill "$n0" "$n1" 2>/dev/null || true
  wait "$n0" "$n1" 2>/dev/null || true
  echo "(b) two nodes + central, run $r: $(e2e "$out/central$r.txt" | tr '\n' ' ')"
  # What (b) adds in this run (b - a, the same run's back-to-back pair).
  paste <(pct "$out/single$r.txt") <(pct "$out/central$r.txt") |
    awk -v r="$r" '{printf "added, run %s: p50 %+d us, p99 %+d us\n", r, $3 - $1, $4 - $2}' |
    tee -a "$out/added.txt"
  grep -E "^ *node_(trigger_leg|work|transit) " "$out/central$r.txt" || true
done
# The medians over the runs (the figure to compare between machines and commits).
median() { sort -n | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
echo "added, median of $runs runs: p50 $(awk '{print $5}' "$out/added.txt" | tr -d '+' | median) us," \
  "p99 $(awk '{print $8}' "$out/added.txt" | tr -d '+' | median) us"
