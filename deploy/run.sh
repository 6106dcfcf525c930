#!/usr/bin/env bash
# The main job in one command: set-up (the programs' Debian packages + a Release build of
# the programs only, idempotent: deploy/setup.sh; the tests are deploy/test.sh's),
# then a full local training session on loopback — snapthread-server, snapthread-device
# (virtual hand pulled through the scene's snaps), a viewer (headless screenshot when
# there is no display), lcm-logger — followed by snapthread-report on the log.
# Arguments are passed to deploy/run_session.sh (e.g. --scene scenes/zeeman.yaml).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$here/deploy/setup.sh"
exec "$here/deploy/run_session.sh" "$@"
