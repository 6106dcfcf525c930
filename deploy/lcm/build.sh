#!/usr/bin/env bash
# Builds snapthread's liblcm: LCM 1.3.1 from Debian's orig tarball (deploy/lcm/fetch.sh)
# with the project's patches (deploy/lcm/*.patch), installed into PREFIX. cmake/PatchedLcm.cmake
# calls it at configure time; it can also be run by hand.
#
# Usage: deploy/lcm/build.sh TARBALL WORK_DIR PREFIX FLAVOR CC
#   FLAVOR  release: shared liblcm (-O2 -g) plus lcm-logger and lcm-logplayer;
#           asan:    shared liblcm and the two tools with -fsanitize=address,undefined
#                    (CC is the project's compiler, so its sanitizer runtime is the one linked);
#           fuzz:    static liblcm with -fsanitize=fuzzer-no-link,address,undefined (CC: clang),
#                    linked into the libFuzzer targets.
# lcm-gen is not built: the system's lcm-gen (liblcm-bin, the same 1.3.1) generates the types.
set -euo pipefail
if [ $# -ne 5 ]; then
  echo "usage: $0 TARBALL WORK_DIR PREFIX FLAVOR CC" >&2
  exit 2
fi
tarball=$1 work=$2 prefix=$3 flavor=$4 cc=$5
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

case "$flavor" in
  release) cflags="-O2 -g"; sanitize=""; libs=(--enable-shared --disable-static) ;;
  asan) cflags="-O1 -g -fno-omit-frame-pointer"
        sanitize="-fsanitize=address,undefined -fno-sanitize-recover=undefined"
        libs=(--enable-shared --disable-static) ;;
  fuzz) cflags="-O1 -g -fno-omit-frame-pointer"
        sanitize="-fsanitize=fuzzer-no-link,address,undefined"
        libs=(--disable-shared --enable-static --with-pic) ;;
  *) echo "lcm-build: unknown flavor '$flavor' (release, asan, fuzz)" >&2; exit 2 ;;
esac
for tool in autoreconf aclocal libtoolize autopoint make patch; do
  if ! command -v "$tool" >/dev/null; then
    echo "lcm-build: $tool is missing; deploy/setup.sh installs autoconf automake libtool" \
         "autopoint (Debian)" >&2
    exit 1
  fi
done

rm -rf "$work" "$prefix"
mkdir -p "$work" "$prefix"
tar -C "$work" -xzf "$tarball"
src=$work/lcm-1.3.1
[ -d "$src" ] || { echo "lcm-build: $tarball has no lcm-1.3.1/" >&2; exit 1; }
for p in "$here"/*.patch; do
  echo "lcm-build: applying $(basename "$p")"
  patch -d "$src" -p1 --quiet --forward < "$p"
done

cd "$src"
start=$(date +%s)
log=$work/build.log
run() {
  if ! "$@" >>"$log" 2>&1; then
    echo "lcm-build: '$*' failed; the end of $log:" >&2
    tail -n 30 "$log" >&2
    exit 1
  fi
}
# The sanitizer flags go into CC: libtool drops unknown -f flags from a link line, but keeps
# the compiler command, so the shared library is linked with the sanitizer runtime too.
run ./bootstrap.sh
run ./configure --prefix="$prefix" --without-java --without-python --without-lua \
  "${libs[@]}" CC="$cc${sanitize:+ $sanitize}" CFLAGS="$cflags"
jobs=$(nproc 2>/dev/null || echo 2)
run make -C lcm -j"$jobs"
run make -C lcm install
if [ "$flavor" != fuzz ]; then
  # lcm-logger receives datagrams too: the tests that record a session use this one.
  run make -C lcm-logger -j"$jobs"
  run make -C lcm-logger install
fi
echo "lcm-build: $flavor liblcm in $prefix ($(( $(date +%s) - start )) s; log $log)"
