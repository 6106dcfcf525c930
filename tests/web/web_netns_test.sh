#!/usr/bin/env bash
# snapthread-web off loopback, as an observer on another machine sees it: two network
# namespaces joined by a veth pair with the project's test addresses (10.213.x.0/24, as
# deploy/netns/two_host_test.sh): the session host (snapthread-server, a sim-path
# snapthread-device and snapthread-web bound to the veth address, token from
# --token-file, LCM on udpm ttl=0 inside that namespace) and the observer host (headless
# Chromium driven by remote_check.mjs). Nothing in the root namespace changes but the
# creation and deletion of these namespaces.
#
# Asserts: with the printed URL the page loads (every file 200), the token leaves the
# address bar (a redirect and an HttpOnly, SameSite=Strict cookie), the page receives
# shapes and draws the thread (tube pixels of its status colour on a screenshot), and no
# Content-Security-Policy violation; without the token the page, its script and style
# sheets get 401 and no script runs.
#
# usage: web_netns_test.sh BIN_DIR SCENE NODE_MODULES REMOTE_CHECK_MJS
# exit: 0 pass, 1 fail, 77 skipped (not root / ip netns not permitted), with the reason.
set -u
bin=${1:?BIN_DIR}
scene=${2:?SCENE}
modules=${3:?NODE_MODULES}
check=${4:?REMOTE_CHECK_MJS}
skip=77

if [ "$(id -u)" -ne 0 ]; then
  echo "SKIPPED: the off-loopback page test needs root for ip netns (running as uid $(id -u))"
  exit $skip
fi
command -v ip >/dev/null || { echo "SKIPPED: ip (iproute2) not installed"; exit $skip; }
[ -x /usr/bin/chromium ] || { echo "FAIL: Debian chromium missing: run deploy/setup.sh"; exit 1; }

tag=$$
subnet="10.213.$(( $$ % 250 + 1 ))"
ns_srv="st_wsrv_$tag"
ns_obs="st_wobs_$tag"
all_ns=("$ns_srv" "$ns_obs")
url="udpm://239.255.76.67:7667?ttl=0"
session="WEBNETNS_$tag"
work=$(mktemp -d /tmp/snapthread-webnetns-XXXXXX)
pids=()
passed=0

cleanup() {
  netns_kill "${all_ns[@]}"
  [ $passed -eq 1 ] && rm -rf "$work"  # kept when the test fails, for its outputs
}
trap cleanup EXIT

# fail, json, make_key, netns_kill, netns_start
source "$(dirname "$0")/../support/script_support.sh"
make_key
# The bridge serves the observers on an observer credential.
observer="$work/observer.cred"
"$bin/snapthread-keygen" --key "$key" --role observer --out "$observer" > "$work/keygen_observer.txt" 2>&1 \
    || fail "snapthread-keygen --role observer failed"
netns_start '^st_(wsrv|wobs)_[0-9]+$' "$ns_srv"
set -e
ip netns add "$ns_obs"
ip link add "wa$tag" netns "$ns_srv" type veth peer name "wb$tag" netns "$ns_obs"
ip -n "$ns_srv" link set lo up
ip -n "$ns_obs" link set lo up
ip -n "$ns_srv" addr add "$subnet.1/24" dev "wa$tag"
ip -n "$ns_obs" addr add "$subnet.2/24" dev "wb$tag"
ip -n "$ns_srv" link set "wa$tag" up
ip -n "$ns_obs" link set "wb$tag" up
# LCM's multicast stays on the session host (ttl=0 loops back), routed by its interface.
ip -n "$ns_srv" route add 224.0.0.0/4 dev "wa$tag"
set +e
echo "namespaces: session host $ns_srv ($subnet.1), observer $ns_obs ($subnet.2)"

token_file="$work/observer.token"
( umask 077; head -c 24 /dev/urandom | od -An -tx1 | tr -d ' \n' > "$token_file" )

ip netns exec "$ns_srv" "$bin/snapthread-server" --key "$key" --scene "$scene" --session "$session" \
    --lcm-url "$url" --duration 150 > "$work/server.txt" 2>&1 &
for _ in $(seq 600); do grep -q "server: session" "$work/server.txt" && break; sleep 0.1; done
grep -q "server: session" "$work/server.txt" || fail "the server did not start"
ip netns exec "$ns_srv" "$bin/snapthread-device" --key "$key" --backend sim-path --scene "$scene" \
    --session "$session" --lcm-url "$url" --duration 120 --no-rt > "$work/device.txt" 2>&1 &
ip netns exec "$ns_srv" "$bin/snapthread-web" --key "$observer" --bind "$subnet.1" --port 0 \
    --token-file "$token_file" --session "$session" --lcm-url "$url" > "$work/web.txt" 2>&1 &
for _ in $(seq 300); do grep -q " at http://" "$work/web.txt" && break; sleep 0.1; done
page=$(grep -o 'http://[^ ]*' "$work/web.txt" | head -n 1)
[ -n "$page" ] || fail "snapthread-web printed no URL"
case "$page" in
  "http://$subnet.1:"*"/?token=$(cat "$token_file")") ;;
  *) fail "unexpected URL $page" ;;
esac
echo "snapthread-web ($ns_srv) serves $page"

ip netns exec "$ns_obs" node "$check" "$modules" "$page" "$work" > "$work/remote.json" 2> "$work/remote_err.txt"
check_rc=$?
cat "$work/remote.json"
[ $check_rc -eq 0 ] || fail "remote_check.mjs exited $check_rc: $(tail -n 5 "$work/remote_err.txt")"

r="$work/remote.json"
py() { python3 -c "import json,sys; r=json.load(open(sys.argv[1])); $1" "$r"; }
py "
w=r['without']
assert w['http'] == 401, f'page without the token: {w[\"http\"]}'
assert w['shapes'] is None, 'a script ran on the refused page'
assert (w['app_js'], w['style_css'], w['uplot_css']) == (401, 401, 401), f'files without the token: {w}'
assert w['ws'] == 'refused', 'the WebSocket opened without the token'
" || fail "without the token the observer got more than nothing"
echo "observer without the token: 401 for the page, app.js, style.css and uplot.css; WebSocket refused"
py "
t=r['with_token']
assert t['http'] == 200, t['http']
assert 'token' not in t['final_url'], 'the token stayed in the address bar: ' + t['final_url']
for f in ('/', '/app.js', '/style.css', '/uplot.css'):
    assert t['files'].get(f) == 200, f'{f}: {t[\"files\"].get(f)}'
c=[c for c in t['cookie'] if c['name'].startswith('snapthread_token_')]
assert c and c[0]['httpOnly'] and c[0]['sameSite'] == 'Strict', f'cookie {t[\"cookie\"]}'
assert t['shapes_per_s'] > 0 and t['frames_per_s'] > 0, 'the page does not follow the session'
assert 300 < t['tube_pixels'] < t['pixels'] / 2, f'tube pixels {t[\"tube_pixels\"]}'
assert t['csp_violations'] == [], t['csp_violations']
" || fail "the observer with the token did not get the live page"
echo "observer with the token: $(py "t=r['with_token']; print(f\"final URL {t['final_url']}, {t['shapes_per_s']:.0f} shapes/s, {t['frames_per_s']:.0f} frames/s, {t['tube_pixels']} tube pixels\")")"
echo "PASS: the page works off loopback with the token and gives nothing without it"
passed=1
exit 0
