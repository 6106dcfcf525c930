#!/usr/bin/env bash
# The full local session on loopback: snapthread-logger, snapthread-server, snapthread-device
# (virtual-hand backend) and a viewer (a window when $DISPLAY is set, otherwise under
# xvfb-run taking a screenshot), for ~10 s; then snapthread-report on the log.
# Outputs: out/session-<UTC time>/ (log, report/, summaries, viewer.png, process logs).
# Session key (docs/security.md): --key FILE, else $SNAPTHREAD_KEY_FILE, else a new key
# for this run in the outputs folder (snapthread-keygen).
#
# usage: deploy/run_session.sh [--duration S] [--scene FILE] [--session NAME]
#                              [--lcm-url URL] [--bin-dir DIR] [--out-root DIR] [--key FILE]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# make_session_key
source "$here/deploy/lib/session_key.sh"

duration=10
scene="$here/scenes/curve2d_snap.yaml"
session="RUN_$(date -u +%Y%m%d_%H%M%S)_$$"
url="udpm://239.255.76.67:7667?ttl=0"   # loopback only: a local session never leaves the host
bin="${SNAPTHREAD_BIN_DIR:-$here/build/bin}"
out_root="$here/out"
key="${SNAPTHREAD_KEY_FILE:-}"
while (($#)); do
  case "$1" in
    --duration) duration=$2; shift 2 ;;
    --scene) scene=$2; shift 2 ;;
    --session) session=$2; shift 2 ;;
    --lcm-url) url=$2; shift 2 ;;
    --bin-dir) bin=$2; shift 2 ;;
    --out-root) out_root=$2; shift 2 ;;
    --key) key=$2; shift 2 ;;
    -h|--help) sed -n '2,11p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) echo "run_session: unknown argument $1" >&2; exit 2 ;;
  esac
done
for b in snapthread-server snapthread-device snapthread-viewer snapthread-logger snapthread-report snapthread-keygen; do
  [ -x "$bin/$b" ] || { echo "run_session: $bin/$b missing (build first: deploy/setup.sh)" >&2; exit 1; }
done
"$here/deploy/multicast-route.sh" >/dev/null 2>&1 || true

out="$out_root/session-$(date -u +%Y%m%d-%H%M%S)"
mkdir -p "$out"
log="$out/session.lcmlog"
make_session_key run_session "$out/session.key" "$out/keygen.txt"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
}
trap cleanup EXIT

echo "run_session: session $session on $url, ${duration} s, outputs in $out"
# Logger first, so the log holds every sequence number from 0. No raised priority:
# snapthread-logger queues what arrives while it is off the CPU (logger/session_logger.h).
"$bin/snapthread-logger" -q -c "${session}_.*" --lcm-url "$url" -f "$log" > "$out/logger.txt" 2>&1 &
logger_pid=$!
pids+=("$logger_pid")
sleep 0.3
"$bin/snapthread-server" --key "$key" --scene "$scene" --session "$session" --lcm-url "$url" \
    --duration $((duration + 3)) --summary "$out/server.json" > "$out/server.txt" 2>&1 &
server_pid=$!
pids+=("$server_pid")
sleep 0.5

if [ -n "${DISPLAY:-}" ]; then
  "$bin/snapthread-viewer" --key "$key" --session "$session" --lcm-url "$url" --duration-s "$((duration + 2))" \
      > "$out/viewer.txt" 2>&1 &
  viewer_mode="window on $DISPLAY"
else
  # Headless: a screenshot about a third of the way in (shapes come at ~60 Hz).
  xvfb-run -a -s "-screen 0 1280x720x24" "$bin/snapthread-viewer" --key "$key" --session "$session" \
      --lcm-url "$url" --screenshot "$out/viewer.png" --after-shapes $((20 * duration)) \
      --timeout-s $((duration + 5)) > "$out/viewer.txt" 2>&1 &
  viewer_mode="xvfb screenshot"
fi
viewer_pid=$!
pids+=("$viewer_pid")

device_rc=0
"$bin/snapthread-device" --key "$key" --backend virtual-hand --scene "$scene" --session "$session" \
    --lcm-url "$url" --duration "$duration" --summary "$out/device.json" \
    --trace "$out/device_trace.csv" > "$out/device.txt" 2>&1 || device_rc=$?
server_rc=0
wait "$server_pid" || server_rc=$?
viewer_rc=0
wait "$viewer_pid" || viewer_rc=$?
kill -INT "$logger_pid" 2>/dev/null || true
wait "$logger_pid" 2>/dev/null || true

report_rc=0
"$bin/snapthread-report" "$log" --out "$out/report" --session "$session" > "$out/report.txt" 2>&1 \
    || report_rc=$?

echo
echo "run_session: exit codes: device $device_rc, server $server_rc, viewer ($viewer_mode) $viewer_rc, report $report_rc"
echo "  log:            $log"
echo "  report:         $out/report/summary.txt"
echo "  plots:          $(cd "$out/report" 2>/dev/null && ls -1 *.png 2>/dev/null | tr '\n' ' ')"
[ -f "$out/viewer.png" ] && echo "  viewer:         $out/viewer.png"
echo "  summaries:      $out/server.json $out/device.json"
echo "  process output: $out/{server,device,viewer,report,logger}.txt"
echo
sed -n '/^channels/,/^$/p' "$out/report/summary.txt" 2>/dev/null || true
sed -n '/^force:/,$p' "$out/report/summary.txt" 2>/dev/null | grep -v '^  snap at' || true
if [ -f "$out/device.json" ]; then
  echo "device summary ($out/device.json):"
  grep -E '"(tick_rate_hz|lateness_us_p50|lateness_us_p99|round_trip_us_p50|round_trip_us_p99|snaps_felt|max_force_n|force_clamps|stiffness_clamps|slew_limits|fade_ticks|nonfinite_outputs|realtime)"' \
      "$out/device.json" | tr -d ' ,"' | sed 's/^/  /'
fi
if ((device_rc || server_rc || viewer_rc || report_rc)); then
  echo "run_session: FAILED (see the process output files above)" >&2
  exit 1
fi
echo "run_session: OK"
