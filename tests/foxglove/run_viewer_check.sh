#!/usr/bin/env bash
# Runs `mocap run --foxglove 127.0.0.1:PORT` (simulated cameras, 100 fps) and the
# reference-client check (viewer_check.mjs, @foxglove/ws-protocol) against it; in
# --hostile mode a viewer that never reads and floods of malformed frames run at the same
# time. Passes when the client's checks pass, `mocap run` exits 0, and the tracker kept
# its frame rate (>= 80 % of the 100 Hz triggers happened, >= 90 % of them published).
#   run_viewer_check.sh MOCAP NPM_DIR [--hostile]
set -euo pipefail
mocap=$1
dir=$2
mode=${3:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
port=$(free_port)
udp=$(free_port)
duration=6
"$mocap" run --foxglove "127.0.0.1:$port" --duration "$duration" --rate 100 --loop-frames 20 --no-iceoryx --no-realtime \
  --udp "127.0.0.1:$udp" --stats "$work/stats.json" >"$work/run.log" 2>&1 &
pid=$!
for _ in $(seq 1 600); do
  if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then break; fi
  if ! kill -0 "$pid" 2>/dev/null; then echo "FAIL mocap run exited early:"; cat "$work/run.log"; exit 1; fi
  sleep 0.1
done
status=0
node "$dir/viewer_check.mjs" "ws://127.0.0.1:$port" 3 30 $mode || status=1
mocap_status=0
wait "$pid" || mocap_status=$?
if [ "$mocap_status" -ne 0 ]; then
  echo "FAIL mocap run exited with $mocap_status"; cat "$work/run.log"; exit 1
fi
python3 - "$work/stats.json" <<'PY' || status=1
import json, sys
s = json.load(open(sys.argv[1]))
fps, published, triggered, duration = s["fps"], s["published"], s["triggered"], s["duration_s"]
print(f"mocap run: {published} of {triggered} frames published in {duration:.1f} s at {fps:.1f} fps")
if published < 0.9 * triggered or triggered < 0.8 * 100 * duration:
    print(f"FAIL the tracker did not keep its frame rate ({published} published, {fps} fps)")
    sys.exit(1)
PY
grep -i "foxglove" "$work/run.log" | head -5 || true
exit $status
