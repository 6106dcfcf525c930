#!/usr/bin/env bash
# Regenerates docs/diagrams/layers.dot from the build system and renders both diagrams of
# docs/architecture.md with Graphviz (Debian package graphviz: dot, tred).
# Usage: tools/architecture/render.sh
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake -S "$here" -B "$tmp/b" -DSNAPTHREAD_SYSTEM_LCM=ON --graphviz="$tmp/deps.dot" >/dev/null
/usr/bin/python3 "$here/tools/architecture/layers.py" "$tmp/deps.dot" > "$here/docs/diagrams/layers.dot"
tred "$here/docs/diagrams/layers.dot" | dot -Tsvg -o "$here/docs/images/architecture_layers.svg"
dot -Tsvg "$here/docs/diagrams/pose_path.dot" -o "$here/docs/images/architecture_pose_path.svg"
echo "wrote docs/diagrams/layers.dot, docs/images/architecture_layers.svg, docs/images/architecture_pose_path.svg"
