#!/bin/sh
# The viewer's picture of a twisted rod in docs/images: rod_greenhill run
# along its path (the grasp rolled about the tangent) to ROW of STEPS, its shape built by
# the server's code (snapthread-scene-shape) and drawn by snapthread-viewer --screenshot
# under Xvfb: the dark stripe along the material director d1, the twist density as colour.
# usage: tools/rod/viewer_shot.sh [BUILD_BIN_DIR] [OUT_PNG] [ROW] [STEPS]
#        (xvfb-run from Debian's xvfb; a session key of its own, made here)
set -eu
here=$(cd "$(dirname "$0")/../.." && pwd)
bin=${1:-$here/build/bin}
png=${2:-$here/docs/images/viewer_rod_greenhill.png}
row=${3:-1600}
steps=${4:-2000}
work=$(mktemp -d)
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$work"' EXIT
"$bin/snapthread-keygen" --key "$work/session.key" > /dev/null
session="ROD_SHOT_$$"
url='udpm://239.255.76.67:7667?ttl=0'
"$bin/snapthread-scene-shape" --scene "$here/scenes/rod_greenhill.yaml" --steps "$steps" \
  --row "$row" --session "$session" --lcm-url "$url" --key "$work/session.key" --duration 120 \
  > "$work/publisher.txt" 2>&1 &
pid=$!
# The sweep runs before the first shape; the viewer waits for it.
xvfb-run -a -s "-screen 0 1280x800x24" "$bin/snapthread-viewer" --key "$work/session.key" \
  --session "$session" --lcm-url "$url" --screenshot "$png" --after-shapes 5 --timeout-s 110 \
  --width 1200 --height 720
cat "$work/publisher.txt"
