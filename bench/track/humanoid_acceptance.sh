#!/usr/bin/env bash
# The whole robot, measured end to end with the mocap CLI: renders the built-in humanoid
# (15 bodies, 14 joints, 71 markers) and prints every figure of the whole-robot
# acceptance on our own renders:
#   1. `mocap track --truth --stats` with the true model on 8 and 6 cameras (smooth,
#      150 frames at 100 fps): bodies found, wrong identities, joint coverage, angle
#      errors, frame p50/p99;
#   2. `mocap calibrate` on 22 static poses (8 cameras) against the true model;
#   3. `mocap discover` on 300 frames of the exploration motion (8 cameras);
#   4. `mocap run` on 8 replay cameras of the 8-camera recording, lockstep at 100 fps
#      (every frame published, trigger-to-publish and identify-stage latencies);
#   5. `mocap run` on the built-in humanoid's 8 simulated cameras at 100 fps and at
#      250 fps for DURATION seconds (frames dropped, latencies), and at 250 fps with the
#      newest frame first (`pipeline.catch_up_ms: 0`).
# Usage: bash bench/track/humanoid_acceptance.sh [MOCAP] [OUT] [DURATION]
#   (defaults: build/mocap, /tmp/humanoid_acceptance, 60)
# Figures go to OUT/*.txt; docs/performance.md records them with the machine.
set -euo pipefail
mocap=${1:-build/mocap}
out=${2:-/tmp/humanoid_acceptance}
duration=${3:-60}
seed=${SEED:-1}
mkdir -p "$out"

render() {  # render NAME ARGS...: once per output folder
  local name=$1
  shift
  [ -f "$out/$name/frames.csv" ] || "$mocap" simulate --scene humanoid --seed "$seed" --out "$out/$name" "$@"
}

echo "== 1. track with the true model"
for cams in 8 6; do
  render "smooth$cams" --cameras "$cams" --frames 150
  "$mocap" track "$out/smooth$cams" --targets "$out/smooth$cams/targets.yaml" \
    --model "$out/smooth$cams/gt/model_true.yaml" --out "$out/track$cams" \
    --stats "$out/track$cams/stats.json" --truth "$out/smooth$cams/gt" 2>&1 |
    grep -v "warning: targets" | tee "$out/track$cams.txt"
done

echo "== 2. calibrate on 22 static poses"
render poses --motion poses --poses 22 --frames 110
"$mocap" calibrate "$out/poses" --targets "$out/poses/targets.yaml" --joints "$out/poses/joints.yaml" \
  --out "$out/model.yaml" >/dev/null
"$mocap" evaluate calibration --targets "$out/poses/targets.yaml" --model "$out/model.yaml" \
  --true-model "$out/poses/gt/model_true.yaml" --header | tee "$out/calibrate.txt"

echo "== 3. discover on the exploration motion"
render explore --motion explore --frames 300
"$mocap" discover "$out/explore" --out "$out/discovered" 2>&1 | tail -n 30 | tee "$out/discover.txt"

echo "== 4. mocap run on 8 replay cameras, lockstep at 100 fps"
{
  echo "cameras:"
  for k in 0 1 2 3 4 5 6 7; do echo "  - {backend: replay, device: $out/smooth8, trigger: software}"; done
  echo "targets: $out/smooth8/targets.yaml"
  echo "model: $out/smooth8/gt/model_true.yaml"
  echo "pipeline: {pacing: lockstep, trigger_rate_hz: 100}"
} >"$out/replay8.yaml"
"$mocap" run --config "$out/replay8.yaml" --stats-interval 0 --stats "$out/replay8.json" 2>&1 |
  grep -v "^  [a-z_0-9]*=" | tee "$out/replay8.txt"

echo "== 5. mocap run on the built-in humanoid's 8 simulated cameras"
for rate in 100 250; do
  printf 'sim: {scene: humanoid, loop_frames: 100}\npipeline: {trigger_rate_hz: %s}\n' "$rate" \
    >"$out/sim$rate.yaml"
  "$mocap" run --config "$out/sim$rate.yaml" --duration "$duration" --stats-interval 0 \
    --stats "$out/sim$rate.json" 2>&1 | grep -v "^  [a-z_0-9]*=" | tee "$out/sim$rate.txt"
done
# The same 250 fps with the newest frame first (pipeline.catch_up_ms: 0: a stall drops the
# frames it held back), the baseline of the default catch-up in the same run.
printf 'sim: {scene: humanoid, loop_frames: 100}\npipeline: {trigger_rate_hz: 250, catch_up_ms: 0}\n' \
  >"$out/sim250n.yaml"
"$mocap" run --config "$out/sim250n.yaml" --duration "$duration" --stats-interval 0 \
  --stats "$out/sim250n.json" 2>&1 | grep -v "^  [a-z_0-9]*=" | tee "$out/sim250n.txt"
echo "== figures in $out"
