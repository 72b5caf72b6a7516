#!/usr/bin/env bash
# Installs the dependencies, builds `mocap` (Release) and runs the tracker on its
# simulated default: renders recordings of the built-in shoulder rig with ground truth,
# calibrates the joints, tracks offline through the same stages as the live pipeline
# (printing the accuracy against the ground truth and the per-stage timings), then runs
# the live pipeline on simulated cameras for 5 s and prints its latency statistics; then
# the same with 4 cameras around the robot (offline tracking and 3 s of the live pipeline);
# then the whole robot: the 15-body humanoid on 8 cameras, calibrated, tracked, discovered
# from an exploration recording, and 3 s of the live pipeline on its simulated cameras.
# This is the README's first command.
# Usage: bash deploy/demo.sh [OUTPUT_DIR]     (default: ./out/demo)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bash deploy/install-deps.sh

out=${1:-out/demo}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DMOCAP_BUILD_TESTS=OFF -DMOCAP_BUILD_BENCH=OFF >/dev/null
cmake --build build-release -j"$jobs" --target mocap
mocap=build-release/mocap

rm -rf "$out"
mkdir -p "$out"
echo "== mocap simulate (built-in shoulder rig, smooth motion, 300 frames)"
"$mocap" simulate --out "$out/rec" --frames 300 --motion smooth
echo "== mocap calibrate (22 distinct static poses)"
"$mocap" simulate --out "$out/cal" --motion poses --poses 22 >/dev/null
"$mocap" calibrate "$out/cal" --targets "$out/cal/targets.yaml" --joints "$out/cal/joints.yaml" \
  --out "$out/model.yaml" --urdf "$out/robot.urdf"
echo "== mocap track"
"$mocap" track "$out/rec" --targets "$out/rec/targets.yaml" --model "$out/model.yaml" \
  --out "$out/track" --stats "$out/track/stats.json" --truth "$out/rec/gt"
echo "== outputs in $out/track: points.csv poses.csv angles.csv stats.json"
echo "== mocap run (live pipeline on simulated cameras, UDP to 127.0.0.1:7755, 5 s)"
"$mocap" run --duration 5 --stats "$out/run-stats.json"
echo "== 4 cameras around the robot: mocap simulate --cameras 4, mocap track (same robot and model)"
"$mocap" simulate --out "$out/rec4" --frames 100 --motion smooth --cameras 4
"$mocap" track "$out/rec4" --targets "$out/rec4/targets.yaml" --model "$out/model.yaml" \
  --out "$out/track4" --truth "$out/rec4/gt"
echo "== mocap run on 4 simulated cameras (a 60-frame loop, 3 s)"
printf 'sim:\n  cameras: 4\n  loop_frames: 60\n' >"$out/run4.yaml"
"$mocap" run --config "$out/run4.yaml" --duration 3 --stats-interval 0
echo "== the whole robot: a 15-body humanoid on a ring of 8 cameras (mocap simulate --scene humanoid)"
"$mocap" simulate --scene humanoid --out "$out/hum_cal" --motion poses --poses 22 --frames 110 >/dev/null
"$mocap" calibrate "$out/hum_cal" --targets "$out/hum_cal/targets.yaml" \
  --joints "$out/hum_cal/joints.yaml" --out "$out/hum_model.yaml" --urdf "$out/humanoid.urdf"
"$mocap" simulate --scene humanoid --out "$out/hum" --frames 150
"$mocap" track "$out/hum" --targets "$out/hum/targets.yaml" --model "$out/hum_model.yaml" \
  --out "$out/hum_track" --stats "$out/hum_track/stats.json" --truth "$out/hum/gt"
echo "== mocap discover on the humanoid exploring its joints (300 frames, no targets, no joints)"
"$mocap" simulate --scene humanoid --out "$out/hum_explore" --motion explore --frames 300 >/dev/null
"$mocap" discover "$out/hum_explore" --out "$out/hum_discovered"
echo "== mocap run on the humanoid's 8 simulated cameras (a 60-frame loop, 3 s)"
printf 'sim:\n  scene: humanoid\n  loop_frames: 60\n' >"$out/run_humanoid.yaml"
"$mocap" run --config "$out/run_humanoid.yaml" --duration 3 --stats-interval 0
