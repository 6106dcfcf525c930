#!/usr/bin/env bash
# Every program follows docs/cli.md's exit codes on its command line: --help exits 0 and
# an unknown flag exits 2 (bad arguments). The programs are the CMake targets outside
# tests/ that are in BIN_DIR (TARGET_LIST_FILE: <build>/snapthread_targets.txt), so a new
# program is held to the convention without being listed here. Deadlines (exit 3) are tested
# where they happen: ctl_process_test, viewer_screenshot_test.
# Usage: exit_codes_test.sh BIN_DIR TARGET_LIST_FILE
set -uo pipefail
bin=$1
targets=$2
required=(snapthread-server snapthread-device snapthread-viewer snapthread-logger snapthread-sweep
  snapthread-stability snapthread-bench snapthread-report snapthread-keygen snapthread-ctl)
fail=0
for p in "${required[@]}"; do
  [ -x "$bin/$p" ] || { echo "FAIL: $bin/$p missing"; fail=1; }
done
checked=0
while read -r p; do
  path=$bin/$p
  [ -n "$p" ] && [ -x "$path" ] && [ -f "$path" ] || continue
  want=2
  err=$(timeout 10 "$path" --no-such-flag 2>&1 >/dev/null)
  rc=$?
  if [ "$rc" -ne "$want" ]; then
    echo "FAIL: $p --no-such-flag exited $rc, expected $want: $err"; fail=1
  elif [ -z "$err" ]; then
    echo "FAIL: $p --no-such-flag: nothing on standard error"; fail=1
  fi
  timeout 10 "$path" --help >/dev/null 2>&1
  rc=$?
  [ "$rc" -eq 0 ] || { echo "FAIL: $p --help exited $rc, expected 0"; fail=1; }
  checked=$((checked + 1))
done <"$targets"
echo "exit_codes_test: $checked programs checked"
exit $fail
