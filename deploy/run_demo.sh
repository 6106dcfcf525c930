#!/usr/bin/env bash
# The main-job demo on one machine: snapthread-server and snapthread-device (virtual-hand
# backend: a simulated hand pulled along the scene's path by a spring, feeling the
# thread's force) talk over loopback UDP multicast (ttl=0) under a unique session name
# for ~10 s; then both are stopped cleanly and a summary is printed.
#
# Builds nothing: expects the binaries from deploy/setup.sh in build/bin (or
# $SNAPTHREAD_BIN_DIR, or --bin-dir).
#
# usage: deploy/run_demo.sh [--scene scenes/curve2d_snap.yaml] [--duration 10]
#                           [--bin-dir DIR] [--out DIR] [--key FILE]
# Session key: --key FILE, else $SNAPTHREAD_KEY_FILE, else a new one in the output dir.
# exit: 0 ok, 1 a process failed / multicast route missing, 2 bad arguments
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# make_session_key
source "$here/deploy/lib/session_key.sh"

scene="$here/scenes/curve2d_snap.yaml"
duration=10
bin="${SNAPTHREAD_BIN_DIR:-$here/build/bin}"
out=""
key=""
url="udpm://239.255.76.67:7667?ttl=0"   # loopback only: the demo never leaves the host
usage() { sed -n '2,12p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
while (($#)); do
  case "$1" in
    --scene) [ $# -ge 2 ] || { echo "run_demo: --scene needs a file" >&2; exit 2; }; scene=$2; shift 2 ;;
    --duration) [ $# -ge 2 ] || { echo "run_demo: --duration needs seconds" >&2; exit 2; }; duration=$2; shift 2 ;;
    --bin-dir) [ $# -ge 2 ] || { echo "run_demo: --bin-dir needs a directory" >&2; exit 2; }; bin=$2; shift 2 ;;
    --key) [ $# -ge 2 ] || { echo "run_demo: --key needs a file" >&2; exit 2; }; key=$2; shift 2 ;;
    --out) [ $# -ge 2 ] || { echo "run_demo: --out needs a directory" >&2; exit 2; }; out=$2; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "run_demo: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
[[ "$duration" =~ ^[0-9]+([.][0-9]+)?$ ]] && awk -v d="$duration" 'BEGIN { exit !(d > 0) }' ||
  { echo "run_demo: --duration must be a positive number of seconds, got '$duration'" >&2; exit 2; }
[ -f "$scene" ] || { echo "run_demo: --scene: no such file '$scene'" >&2; exit 2; }
for b in snapthread-server snapthread-device snapthread-keygen; do
  [ -x "$bin/$b" ] || { echo "run_demo: $bin/$b missing (build first: deploy/setup.sh)" >&2; exit 1; }
done
command -v python3 >/dev/null || { echo "run_demo: python3 missing (prints the summary)" >&2; exit 1; }

# udpm needs a multicast route; multicast-route.sh adds one on lo when root, otherwise
# prints the command.
if ! "$here/deploy/multicast-route.sh"; then
  echo "run_demo: no multicast route for LCM; run as root: ip route add 224.0.0.0/4 dev lo" >&2
  exit 1
fi

session="DEMO_$$_${RANDOM}"
[ -n "$out" ] || out=$(mktemp -d "${TMPDIR:-/tmp}/snapthread-demo.XXXXXX")
mkdir -p "$out"
key="${key:-${SNAPTHREAD_KEY_FILE:-}}"
make_session_key run_demo "$out/session.key" "$out/keygen.log"
server_pid=""
device_pid=""
cleanup() {
  # Only our own children, by pid.
  [ -n "$device_pid" ] && kill "$device_pid" 2>/dev/null || true
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null || true
}
trap cleanup EXIT
trap 'echo "run_demo: interrupted" >&2; exit 1' INT TERM

echo "run_demo: scene $(basename "$scene"), session $session on $url, ${duration} s; logs in $out"
# The server's own --duration is only a safety net (stopped with SIGTERM after the
# device finishes): it never outlives the demo by more than a minute.
"$bin/snapthread-server" --key "$key" --scene "$scene" --session "$session" --lcm-url "$url" \
  --duration "$(awk -v d="$duration" 'BEGIN { print d + 60 }')" \
  --summary "$out/server.json" > "$out/server.log" 2>&1 &
server_pid=$!
# Wait until the server has loaded the scene and subscribed (it logs its session line).
for _ in $(seq 1 200); do
  grep -q "server: session" "$out/server.log" 2>/dev/null && break
  kill -0 "$server_pid" 2>/dev/null || break
  sleep 0.05
done
if ! grep -q "server: session" "$out/server.log" 2>/dev/null; then
  echo "run_demo: the server did not start:" >&2
  cat "$out/server.log" >&2
  exit 1
fi

"$bin/snapthread-device" --key "$key" --backend virtual-hand --scene "$scene" --session "$session" \
  --lcm-url "$url" --duration "$duration" --rate-hz 1000 --publish-divisor 1 \
  --model-timeout-ms 50 --no-rt --trace "$out/device_trace.csv" \
  --summary "$out/device.json" > "$out/device.log" 2>&1 &
device_pid=$!
device_rc=0
wait "$device_pid" || device_rc=$?
device_pid=""

kill -TERM "$server_pid" 2>/dev/null || true
server_rc=0
wait "$server_pid" || server_rc=$?
server_pid=""

if [ "$device_rc" -ne 0 ] || [ "$server_rc" -ne 0 ]; then
  echo "run_demo: device exit $device_rc, server exit $server_rc; logs:" >&2
  tail -n 20 "$out/device.log" "$out/server.log" >&2
  exit 1
fi

final_line=$(grep "final:" "$out/server.log" | tail -n 1 | sed 's/.*final: //')
python3 - "$out/device.json" "$out/server.json" "$final_line" <<'PY'
import json, sys
dev = json.load(open(sys.argv[1]))
srv = json.load(open(sys.argv[2]))
print("run_demo: summary")
print(f"  device  tick rate        {dev['tick_rate_hz']:.1f} Hz ({dev['ticks']} ticks)")
print(f"          lateness         p50 {dev['lateness_us_p50']:.0f} us, p99 {dev['lateness_us_p99']:.0f} us, max {dev['lateness_us_max']:.0f} us")
print(f"          round trip       p50 {dev['round_trip_us_p50']:.0f} us, p99 {dev['round_trip_us_p99']:.0f} us")
print(f"          models           {dev['models_received']} received, {dev['models_rejected']} rejected")
print(f"          snaps felt       {dev['snaps_felt']}")
print(f"          max force        {dev['max_force_n']:.3f} N")
print(f"          clamps           force {dev['force_clamps']}, stiffness {dev['stiffness_clamps']}, slew {dev['slew_limits']}, fade ticks {dev['fade_ticks']}")
print(f"          non-finite out   {dev['nonfinite_outputs']}")
print(f"  server  updates          {srv['updates']} ({srv['update_rate_hz']:.1f} /s)")
print(f"          solve            p50 {srv['solve_us_p50']:.1f} us, p99 {srv['solve_us_p99']:.1f} us")
print(f"          snaps            {srv['snaps']}, dropped poses {srv['dropped_poses']}, rejected messages {srv['rejected_messages']}")
print(f"  server final log line: {sys.argv[3]}")
PY
echo "run_demo: trace $out/device_trace.csv"
