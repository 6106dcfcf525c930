#!/usr/bin/env bash
# The whole test suite (what CI runs, issue 12 item 7):
#  1. set-up (packages + Release build: -O3 -DNDEBUG, warnings as errors), then every test;
#  2. a second build with AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/), then
#     every test again under it (the viewer's ones without the leak check: why, below);
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
  cmake -S "$here" -B "$here/build-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSNAPTHREAD_SANITIZE=ON \
    -DSNAPTHREAD_WERROR=OFF >/dev/null
  cmake --build "$here/build-asan" -j"$(nproc)"
  cd "$here/build-asan"
  # Every test again, the same as above, on the sanitized binaries: the in-process ones and
  # the multi-process, soak, namespace, viewer and browser ones, which start the sanitized
  # server, device, viewer, logger and web bridge. LCM subscriptions go through
  # messages::Subscribe (common/messages/subscribe.h): liblcm's own member-function
  # subscriptions trip a GCC 12 UBSan false report (see that header).
  # SNAPTHREAD_SPEED_SCALE=16: the rod's sweep takes 14x the CPU time in this build, so
  # thresholds that are about speed (a time budget, start-up-and-refusal time, models per
  # servo tick, shapes and frames per second) are divided by it (tests/support/environment.h); no
  # safety property is.
  export SNAPTHREAD_SPEED_SCALE=16 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
    ctest --output-on-failure -j2 --timeout 900 -LE 'open|viewer|soak|netns'
  # The tests that start the viewer (OpenGL under Xvfb: labels viewer, soak, netns) run with
  # ASan and UBSan but without LeakSanitizer: Mesa's llvmpipe driver (22.3) leaks two 56-byte
  # blocks that it frees never and whose module it unloads (dlclose) before the exit-time
  # check, so no suppression can name them (an LSan suppression matches a module or
  # function name; these frames have neither). The viewer's own code (decoding, the
  # receiver, the frames, the renderer's geometry) is leak-checked in-process above
  # (viewer_core_test).
  ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
    ctest --output-on-failure -j2 --timeout 900 -L 'viewer|soak|netns' -LE open
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
