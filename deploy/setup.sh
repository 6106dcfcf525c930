#!/usr/bin/env bash
# Set-up in two parts (idempotent). Both install the Debian packages they need, make sure
# LCM's UDP multicast has a route and fetch LCM's source for the patched liblcm.
#   deploy/setup.sh            the programs only (deploy/run.sh): their packages, then a
#                              Release build of the programs into build/bin/ (no tests;
#                              snapthread-web only when Node.js >= 20 is already installed)
#   deploy/setup.sh --tests    also the test tools (GoogleTest, clang, Ceres, LAPACK,
#                              Chromium, Firefox ESR, Node.js, Java for lcm-spy, ...), for
#                              deploy/test.sh, which configures and builds the tests itself
# Usage: deploy/setup.sh [--tests] [--no-build]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
tests=0
build=1
for a in "$@"; do
  case "$a" in
    --tests) tests=1 ;;
    --no-build) build=0 ;;
    -h|--help) sed -n '2,10p' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) echo "setup: unknown argument $a (see --help)" >&2; exit 2 ;;
  esac
done

# What the programs need to build and run a session (deploy/run.sh).
packages=(
  build-essential cmake pkg-config git
  liblcm-dev liblcm-bin libglib2.0-dev
  libeigen3-dev libsuitesparse-dev libspdlog-dev
  libyaml-cpp-dev libcli11-dev libsodium-dev
  libglfw3-dev libepoxy-dev xvfb xauth libstb-dev libpng-dev libgl1-mesa-dri
  gnuplot-nox python3 ccache ninja-build
  iproute2 procps
  # the Python module (python/, docs/python.md): pybind11 and NumPy for Debian's python3
  python3-dev pybind11-dev python3-numpy
  # liblcm is built from Debian's LCM source with the project's patch (deploy/lcm/).
  autoconf automake libtool autopoint dpkg-dev
)
# What the tests and the developer tools add (deploy/test.sh).
test_packages=(
  libgtest-dev libgmock-dev xdotool graphviz
  # the fuzzers (libFuzzer) and snapthread-bench's comparisons (Ceres Solver, LAPACK's banded
  # Cholesky)
  clang libclang-rt-14-dev
  libceres-dev liblapack-dev
  # lcm-spy with the project's types (docs/lcm-spy.md)
  liblcm-java default-jdk-headless libjchart2d-java
  # the Python module's tests and example (docs/python.md)
  python3-pytest python3-matplotlib
  # snapthread-web: Boost.Beast (header-only) for its HTTP/WebSocket server, and Debian's
  # Chromium and Firefox ESR for its browser tests (driven by playwright-core and
  # puppeteer-core from the page's npm install; Firefox's WebGL runs on the tests' Xvfb).
  libboost-dev chromium firefox-esr
)

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
NodeMajor() { node -p 'process.versions.node.split(".")[0]' 2>/dev/null || echo 0; }
HaveNode20() { command -v node >/dev/null && command -v npm >/dev/null && [ "$(NodeMajor)" -ge 20 ]; }

# snapthread-web's page is bundled at build time (`npm ci` from web/page/package-lock.json:
# three.js, uPlot, esbuild, playwright-core for Chromium, puppeteer-core for Firefox over
# WebDriver BiDi) with Node.js >= 20. The programs' set-up builds it only when such a
# Node.js is already installed (Debian 12's own is 18); the tests' set-up needs it.
web=OFF
if ((tests)); then
  packages+=("${test_packages[@]}")
  web=ON
elif HaveNode20; then
  packages+=(libboost-dev)
  web=ON
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all Debian packages present"
fi

"$here/deploy/multicast-route.sh" || true

# LCM's source (Debian's orig tarball, SHA-256 checked) for the patched liblcm the build makes.
"$here/deploy/lcm/fetch.sh"

if ((tests)); then
  # The machine's Node.js is used; Debian's (nodejs + npm) only when there is none.
  if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
    echo "setup: installing Debian's nodejs and npm (snapthread-web's page needs Node.js >= 20)"
    DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends nodejs npm
  fi
  if ! HaveNode20; then
    echo "setup: Node.js $(node --version) is older than 20; snapthread-web's page and browser tests need >= 20" >&2
    echo "setup: install a newer Node.js, or configure with -DSNAPTHREAD_BUILD_WEB=OFF" >&2
    exit 1
  fi
elif [ "$web" = OFF ]; then
  echo "setup: no Node.js >= 20 here: building without snapthread-web (deploy/test.sh sets it up)"
fi

if ((build)); then
  # A new build directory: Release, Ninja, no tests (deploy/test.sh turns them on). One that
  # exists keeps its settings; either way only the programs are built (the target
  # snapthread-programs: every executable outside tests/).
  if [ -f "$here/build/CMakeCache.txt" ]; then
    cmake -S "$here" -B "$here/build"
  else
    cmake -G Ninja -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release \
      -DSNAPTHREAD_BUILD_TESTS=OFF -DSNAPTHREAD_BUILD_WEB="$web"
  fi
  cmake --build "$here/build" -j"$(nproc)" --target snapthread-programs
fi
