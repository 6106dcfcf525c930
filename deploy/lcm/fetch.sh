#!/usr/bin/env bash
# Fetches LCM 1.3.1's source from Debian (the orig tarball of Debian's lcm package, the same
# version the system's liblcm-dev is built from) into a cache folder that is never committed,
# and checks its SHA-256 against the one Debian's .dsc lists. cmake/PatchedLcm.cmake builds
# the project's patched liblcm from it (deploy/lcm/build.sh).
#
# Usage: deploy/lcm/fetch.sh [CACHE_DIR]
#   CACHE_DIR defaults to $SNAPTHREAD_DEPS_DIR/lcm, else <repo>/.deps/lcm (gitignored).
# Needs root (or sudo) the first time: it adds a deb-src entry next to the system's
# debian.sources and runs apt-get update. Idempotent: a verified tarball is kept.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cache=${1:-${SNAPTHREAD_DEPS_DIR:-$here/.deps}/lcm}
package=lcm
orig=lcm_1.3.1+repack1.orig.tar.gz
# The tarball's SHA-256 as listed in Debian bookworm's lcm_1.3.1+repack1-3.dsc; checked
# again against the .dsc apt knows, below, whenever apt has the source index.
expected_sha256=abf293e54aff3d073cb4f9d4d5a261eab0e5ffea02e13fd601715c11612b85e8

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)

sha_of() { sha256sum "$1" | cut -d' ' -f1; }

mkdir -p "$cache"
if [ -f "$cache/$orig" ] && [ "$(sha_of "$cache/$orig")" = "$expected_sha256" ]; then
  echo "lcm-fetch: $cache/$orig present (SHA-256 verified)"
  exit 0
fi

# A deb-src twin of each Debian source in debian.sources (same URIs, suites and keys).
system_sources=/etc/apt/sources.list.d/debian.sources
src_sources=/etc/apt/sources.list.d/snapthread-deb-src.sources
if ! apt-cache showsrc "$package" 2>/dev/null | grep -q "^Package: $package"; then
  if [ ! -f "$src_sources" ]; then
    if [ ! -f "$system_sources" ]; then
      echo "lcm-fetch: no $system_sources to copy for a deb-src entry; add one for Debian's" \
           "main component by hand, then run this again" >&2
      exit 1
    fi
    echo "lcm-fetch: adding $src_sources (deb-src copy of $system_sources)"
    sed -E 's/^Types:.*/Types: deb-src/' "$system_sources" | "${sudo_cmd[@]}" tee "$src_sources" >/dev/null
  fi
  "${sudo_cmd[@]}" apt-get update -qq
fi

# The checksum Debian's .dsc lists for the tarball must be the one this script expects (a
# newer Debian revision with another tarball needs the patch re-checked first).
dsc_sha256=$(apt-cache showsrc "$package" | awk -v f="$orig" '
  /^Checksums-Sha256:/ { in_sums = 1; next }
  /^[^ ]/ { in_sums = 0 }
  in_sums && $3 == f { print $1; exit }')
if [ -z "$dsc_sha256" ]; then
  echo "lcm-fetch: apt-cache showsrc $package lists no $orig (another Debian release?)" >&2
  exit 1
fi
if [ "$dsc_sha256" != "$expected_sha256" ]; then
  echo "lcm-fetch: Debian's .dsc lists SHA-256 $dsc_sha256 for $orig, this script expects" \
       "$expected_sha256; refusing" >&2
  exit 1
fi

# --tar-only: Debian's packaging tarball is not served here, so a plain `apt-get source`
# fails; the orig tarball is all the build needs.
tmp=$(mktemp -d "$cache/.fetch.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
(cd "$tmp" && apt-get source --tar-only -qq -o APT::Sandbox::User=root "$package" >/dev/null)
if [ ! -f "$tmp/$orig" ]; then
  echo "lcm-fetch: apt-get source --tar-only $package brought no $orig" >&2
  exit 1
fi
got=$(sha_of "$tmp/$orig")
if [ "$got" != "$expected_sha256" ]; then
  echo "lcm-fetch: $orig has SHA-256 $got, the .dsc lists $expected_sha256; refusing" >&2
  exit 1
fi
mv "$tmp/$orig" "$cache/$orig"
echo "lcm-fetch: $cache/$orig (SHA-256 $got, as in Debian's .dsc)"
