#!/usr/bin/env bash
# The whole test suite: set-up (packages + Release build), then ctest.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$here/deploy/setup.sh"
cd "$here/build"
ctest --output-on-failure -j2 --timeout 600
