#!/usr/bin/env bash
# Two-host test with network namespaces: three "hosts" (server, device, observers) joined
# by a bridge that lives in a fourth namespace, addresses in 10.213.x.0/24 private to them,
# each with its own multicast route and LCM on udpm ttl=1. Nothing in the root namespace is
# changed except creating/deleting these namespaces, and no traffic leaves them.
#
#   server host:   snapthread-server
#   device host:   snapthread-device --backend virtual-hand
#   observer host: snapthread-logger, snapthread-viewer (xvfb screenshot), snapthread-viewer --print-rates
#
# Asserts: the device received force models; both observers received shapes; the log holds
# every sequence number the server published (FORCE_MODEL 0..updates-1, no gaps) and every
# pose the device published (DEVICE_STATE 0..last, no gaps).
#
# usage: two_host_test.sh BIN_DIR SCENE [DURATION_S]
# exit: 0 pass, 1 fail, 77 skipped (not root / ip netns not permitted), with the reason.
set -u
bin=${1:?BIN_DIR}
scene=${2:?SCENE}
duration=${3:-8}
skip=77

if [ "$(id -u)" -ne 0 ]; then
  echo "SKIPPED: the two-host test needs root for ip netns (running as uid $(id -u))"
  exit $skip
fi
command -v ip >/dev/null || { echo "SKIPPED: ip (iproute2) not installed"; exit $skip; }

tag=$$
subnet="10.213.$(( $$ % 250 + 1 ))"
ns_br="st_br_$tag"
ns_srv="st_srv_$tag"
ns_dev="st_dev_$tag"
ns_obs="st_obs_$tag"
all_ns=("$ns_srv" "$ns_dev" "$ns_obs" "$ns_br")
url="udpm://239.255.76.67:7667?ttl=1"
session="NETNS_$tag"
work=$(mktemp -d /tmp/snapthread-netns-XXXXXX)

cleanup() { netns_kill "${all_ns[@]}"; }
trap cleanup EXIT

# fail, json, make_key, run_session, end_session, netns_kill, netns_start
source "$(dirname "$0")/../../tests/support/script_support.sh"
make_key
netns_start '^st_(br|srv|dev|obs)_[0-9]+$' "$ns_br"
set -e
ip -n "$ns_br" link set lo up
ip -n "$ns_br" link add br0 type bridge
# No IGMP snooping on the test bridge: there is no querier, so flood multicast to all ports.
ip -n "$ns_br" link set br0 type bridge mcast_snooping 0
ip -n "$ns_br" link set br0 up
i=1
for ns in "$ns_srv" "$ns_dev" "$ns_obs"; do
  ip netns add "$ns"
  ip -n "$ns" link set lo up
  ip link add "v$tag" netns "$ns" type veth peer name "p$i" netns "$ns_br"
  ip -n "$ns_br" link set "p$i" master br0
  ip -n "$ns_br" link set "p$i" up
  ip -n "$ns" addr add "$subnet.$i/24" dev "v$tag"
  ip -n "$ns" link set "v$tag" up
  ip -n "$ns" route add 224.0.0.0/4 dev "v$tag"
  i=$((i + 1))
done
set +e
echo "namespaces: server $ns_srv ($subnet.1), device $ns_dev ($subnet.2), observers $ns_obs ($subnet.3), bridge in $ns_br"

# Started with ip netns exec directly (not through a shell function), so $! is the process
# itself and the logger gets the SIGINT that makes it close the log.

# The logger at normal priority, as in the soak test (logger/session_logger.h).
ip netns exec "$ns_obs" "$bin/snapthread-logger" -q -c "${session}_.*" --lcm-url "$url" -f "$work/session.lcmlog" > "$work/logger.txt" 2>&1 &
logger_pid=$!
ip netns exec "$ns_obs" "$bin/snapthread-viewer" --key "$key" --print-rates --session "$session" --lcm-url "$url" \
    --duration-s $((duration + 3)) > "$work/observer_rates.txt" 2>&1 &
rates_pid=$!
ip netns exec "$ns_obs" xvfb-run -a -n $((100 + tag % 800)) -s "-screen 0 640x480x24" "$bin/snapthread-viewer" --key "$key" \
    --session "$session" --lcm-url "$url" --screenshot "$work/observer.png" --after-shapes 30 \
    --timeout-s $((duration + 10)) --width 640 --height 480 > "$work/observer_viewer.txt" 2>&1 &
viewer_pid=$!
sleep 0.5
run_session "ip netns exec $ns_srv" "ip netns exec $ns_dev"
wait "$viewer_pid"; viewer_rc=$?
wait "$rates_pid"; rates_rc=$?
end_session "$logger_pid"
models=$(json "$work/device.json" "['models_received']") || fail "no models_received in device.json"
[ "$models" -gt 0 ] || fail "device received no force models across namespaces"
echo "device ($ns_dev) received $models force models from the server ($ns_srv)"

[ $viewer_rc -eq 0 ] || fail "viewer in $ns_obs did not get 30 shapes (exit $viewer_rc)"
echo "viewer ($ns_obs): $(cat "$work/observer_viewer.txt" | grep wrote)"
[ $rates_rc -eq 0 ] || fail "print-rates observer exited $rates_rc"
shapes=$(awk -v c="${session}_SHAPE" '$1 == "TOTAL" && $2 == c {print $3}' "$work/observer_rates.txt")
[ "${shapes:-0}" -gt 0 ] || fail "print-rates observer saw no ${session}_SHAPE"
echo "print-rates observer ($ns_obs): $shapes shapes"

"$bin/snapthread-report" "$work/session.lcmlog" --out "$work/report" --session "$session" --no-plots \
    > "$work/report.txt" 2>&1 || fail "snapthread-report failed"
summary="$work/report/summary.txt"
updates=$(json "$work/server.json" "['updates']") || fail "no updates in server.json"
fm=$(grep "^channel ${session}_FORCE_MODEL " "$summary")
ds=$(grep "^channel ${session}_DEVICE_STATE " "$summary")
echo "log: $fm"
echo "log: $ds"
# Server and device number their messages from 0.
echo "$fm" | grep -q " messages $updates .* seq 0\.\.$((updates - 1)) missing 0 gaps 0 out_of_order 0" \
    || fail "log does not hold FORCE_MODEL seq 0..$((updates - 1)) without gaps (server published $updates)"
echo "$ds" | grep -q " seq 0\.\.[0-9]* missing 0 gaps 0 out_of_order 0" \
    || fail "log misses DEVICE_STATE sequence numbers"
echo "PASS: two-host session across network namespaces"
exit 0
