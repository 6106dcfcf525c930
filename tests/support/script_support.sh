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
