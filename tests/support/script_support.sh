# Shell helpers of the whole-service test scripts (tests/viewer/soak_test.sh,
# deploy/netns/two_host_test.sh). Source it after setting $work (the outputs folder).

# lcm-logger closes its log on SIGINT; never wait for it forever.
stop_logger() {
  kill -INT "$1" 2>/dev/null
  for _ in $(seq 50); do kill -0 "$1" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$1" 2>/dev/null
  wait "$1" 2>/dev/null
}
# Prints the reason and the tail of every output in $work, exits 1.
fail() { echo "FAIL: $*"; echo "--- outputs in $work"; for f in "$work"/*.txt; do echo "== $f"; tail -n 15 "$f"; done; exit 1; }
# json FILE "['key']": a field of a JSON file.
json() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))$2)" "$1"; }
# start_xvfb NAME [SCREEN]: a virtual X display for windows of this test; sets $display
# (":N") and appends Xvfb's pid to pids. Xvfb picks a free display itself and writes its
# number to -displayfd once it accepts connections, so there is no display-number race
# with other tests and no sleep (xvfb-run's -a guesses a number from lock files and waits
# for a SIGUSR1 that can arrive before it waits).
start_xvfb() {
  local f="$work/$1.display"
  : > "$f"
  Xvfb -displayfd 3 -screen 0 "${2:-640x480x24}" -nolisten tcp 3> "$f" > "$work/$1.txt" 2>&1 &
  pids+=("$!")
  for _ in $(seq 300); do grep -q '^[0-9][0-9]*$' "$f" && break; sleep 0.1; done
  grep -q '^[0-9][0-9]*$' "$f" || fail "Xvfb did not start within 30 s"
  display=":$(cat "$f")"
}
# make_key: a session key for this run in $work/session.key (sets $key; every binary
# gets --key "$key").
make_key() {
  key="$work/session.key"
  "$bin/snapthread-keygen" --key "$key" > "$work/keygen.txt" 2>&1 || fail "snapthread-keygen failed"
}
# run_session SERVER_PREFIX DEVICE_PREFIX: snapthread-server (summary in $work/server.json,
# $duration + 2 s) in the background, then snapthread-device (virtual hand, $duration s,
# $work/device.json) to its end, both on $scene, $session, $url from $bin. Sets server_pid
# (also appended to pids, which a cleanup trap may kill) and device_rc. A prefix is a
# command such as "ip netns exec NS" or "nice -n -5", or empty.
run_session() {
  $1 "$bin/snapthread-server" --key "$key" --scene "$scene" --session "$session" --lcm-url "$url" \
      --duration $((duration + 2)) --summary "$work/server.json" > "$work/server.txt" 2>&1 &
  server_pid=$!; pids+=("$server_pid")
  sleep 0.5
  $2 "$bin/snapthread-device" --key "${device_key:-$key}" --backend virtual-hand --scene "$scene" --session "$session" --lcm-url "$url" \
      --duration "$duration" --no-rt --summary "$work/device.json" > "$work/device.txt" 2>&1
  device_rc=$?
}
# end_session LOGGER_PID: after run_session (and after waiting for the other processes,
# such as viewers), waits for the server (sets server_rc), stops the logger and fails
# unless the device and the server exited 0.
end_session() {
  wait "$server_pid"; server_rc=$?
  stop_logger "$1"
  [ $device_rc -eq 0 ] || fail "device exited $device_rc"
  [ $server_rc -eq 0 ] || fail "server exited $server_rc"
}

# Network-namespace tests (deploy/netns/two_host_test.sh, tests/web/web_netns_test.sh).
# netns_kill NS...: ends the processes started in these namespaces (ip netns pids lists
# exactly those; TERM, then KILL after 0.3 s) and deletes the namespaces.
netns_kill() {
  local ns p
  for ns in "$@"; do
    for p in $(ip netns pids "$ns" 2>/dev/null); do kill "$p" 2>/dev/null || true; done
  done
  sleep 0.3
  for ns in "$@"; do
    for p in $(ip netns pids "$ns" 2>/dev/null); do kill -9 "$p" 2>/dev/null || true; done
    ip netns del "$ns" 2>/dev/null || true
  done
}
# netns_remove_stale REGEX: namespaces left by an earlier run killed before its trap ran,
# named REGEX_<pid of that run> (e.g. '^st_(br|srv)_[0-9]+$'), whose run is gone.
netns_remove_stale() {
  local ns owner
  for ns in $(ip netns list 2>/dev/null | awk '{print $1}' | grep -E "$1"); do
    owner=${ns##*_}
    if ! kill -0 "$owner" 2>/dev/null; then
      netns_kill "$ns"
      echo "removed stale namespace $ns"
    fi
  done
}
# netns_start STALE_REGEX NS: removes the stale namespaces of earlier runs (as
# netns_remove_stale), then adds NS, the run's first namespace; where that is not
# permitted (not root, no CAP_SYS_ADMIN) prints SKIPPED and exits 77, ctest's skip code.
netns_start() {
  netns_remove_stale "$1"
  if ! ip netns add "$2" 2>"$work/netns_err.txt"; then
    echo "SKIPPED: ip netns add not permitted here: $(cat "$work/netns_err.txt")"
    exit 77
  fi
}
