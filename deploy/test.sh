#!/usr/bin/env bash
# The whole test suite (what CI runs, issue 12 item 7):
#  1. set-up (packages + Release build: -O3 -DNDEBUG, warnings as errors), then every test;
#  2. a second build with AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/), then
#     every test but the multi-process ones under it (what is left out, and why, is below);
#  3. short libFuzzer runs of the scene loader and the message decoders (build-fuzz/, clang),
#     FUZZ_SECONDS each (default 30; docs on the long runs in the README's Tests section).
# Usage: deploy/test.sh [--quick]   (--quick: step 1 only, for a local edit-test loop)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$here/deploy/setup.sh"
cd "$here/build"
# Labels containing `open`: tests of work in progress not yet reliable (named in the README;
# today none: snap_ahead_process_test, issue 17, runs here as `process`).
ctest --output-on-failure -j2 --timeout 600 -LE open

if [ "${1:-}" != "--quick" ]; then
  echo "test: sanitizer build (ASan + UBSan) in build-asan/"
  # -Werror stays on the Release build: GCC 12 reports false maybe-uninitialized warnings
  # in libstdc++ under the sanitizers.
  # snapthread-web is left out: its tests are browser tests (process), not run here.
  cmake -S "$here" -B "$here/build-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSNAPTHREAD_SANITIZE=ON \
    -DSNAPTHREAD_WERROR=OFF -DSNAPTHREAD_BUILD_WEB=OFF >/dev/null
  cmake --build "$here/build-asan" -j"$(nproc)"
  cd "$here/build-asan"
  # Under the sanitizers: every in-process test of the labels unit, report and service (the
  # models, linear algebra, solvers, contact, knots, scenes, sweep, stability, auth,
  # messages, report, the in-process server and device over memq:// and udpm, and the
  # allocation counters, which count through ASan's malloc hook there). LCM subscriptions
  # go through messages::Subscribe (common/messages/subscribe.h): liblcm's own
  # member-function subscriptions trip a GCC 12 UBSan false report (see that header).
  # SNAPTHREAD_SPEED_SCALE: this build is slower, so wall-clock budgets that are about
  # speed (time_budget_test's 300 us) are multiplied by it; no safety bound is.
  # Left out, and why (OPEN, issue 12 item 7): the multi-process, soak and namespace tests
  # (labels process, soak, netns: they start the sanitized binaries over udpm; their timing
  # under the slowdown is not measured), the viewer tests (label viewer: Mesa and X11 under
  # LeakSanitizer not yet run) and DeviceServoLoopTest (it asserts a 1 kHz tick rate, a
  # speed figure the sanitized build is not meant to meet).
  SNAPTHREAD_SPEED_SCALE=4 ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --output-on-failure -j2 --timeout 900 -LE 'open|process|soak|netns|viewer' -E 'DeviceServoLoopTest'
fi

if [ "${1:-}" != "--quick" ]; then
  echo "test: libFuzzer smoke runs (clang) in build-fuzz/"
  cmake -S "$here" -B "$here/build-fuzz" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSNAPTHREAD_FUZZ=ON -DSNAPTHREAD_WERROR=OFF \
    -DSNAPTHREAD_BUILD_TESTS=OFF -DSNAPTHREAD_BUILD_WEB=OFF >/dev/null
  cmake --build "$here/build-fuzz" -j"$(nproc)" --target scene_fuzzer message_fuzzer
  seeds=$(mktemp -d)
  trap 'rm -rf "$seeds"' EXIT
  mkdir -p "$seeds/scene" "$seeds/messages"
  "$here/build/tests/message_seeds" "$seeds/messages"
  for f in scene message; do
    corpus=$here/tests/fuzz/corpus/${f/message/messages}
    "$here/build-fuzz/fuzz/${f}_fuzzer" -max_total_time="${FUZZ_SECONDS:-30}" -timeout=5 -rss_limit_mb=2048 \
      -print_final_stats=1 "$seeds/${f/message/messages}" "$corpus" 2>&1 | tail -n 12
  done
fi
