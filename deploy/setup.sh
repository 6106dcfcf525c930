#!/usr/bin/env bash
# One-command set-up: installs the Debian packages snapthread needs (idempotent), makes
# sure LCM's UDP multicast has a route, and builds Release into build/ (binaries in
# build/bin/). Usage: deploy/setup.sh [--no-build]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

packages=(
  build-essential cmake pkg-config git
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev default-jdk-headless libjchart2d-java
  libeigen3-dev libsuitesparse-dev libspdlog-dev libgtest-dev libgmock-dev
  libyaml-cpp-dev libcli11-dev libsodium-dev
  libglfw3-dev libepoxy-dev xvfb xauth libstb-dev libpng-dev libgl1-mesa-dri xdotool
  gnuplot-nox graphviz python3 ccache ninja-build
  clang libclang-rt-14-dev
  libceres-dev liblapack-dev
  iproute2 procps
  # The Python module (python/, docs/python.md): pybind11 and NumPy to build it for Debian's
  # python3; pytest and matplotlib for its tests and example.
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib
  # snapthread-web: Boost.Beast (header-only) for its HTTP/WebSocket server, and Debian's
  # Chromium and Firefox ESR for its browser tests (driven by playwright-core and
  # puppeteer-core from the page's npm install; Firefox's WebGL runs on the tests' Xvfb).
  libboost-dev chromium firefox-esr
  # liblcm is built from Debian's LCM source with the project's patch (deploy/lcm/).
  autoconf automake libtool autopoint dpkg-dev
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all Debian packages present"
fi

"$here/deploy/multicast-route.sh" || true

# LCM's source (Debian's orig tarball, SHA-256 checked) for the patched liblcm the build makes.
"$here/deploy/lcm/fetch.sh"

# snapthread-web's page is bundled at build time: the build runs `npm ci` from
# web/page/package-lock.json (three.js, uPlot, esbuild, playwright-core for Chromium, puppeteer-core
# for Firefox over WebDriver BiDi) with Node.js >= 20.
# The machine's Node.js is used; Debian's (nodejs + npm) only when there is none.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "setup: installing Debian's nodejs and npm (snapthread-web's page needs Node.js >= 20)"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends nodejs npm
fi
node_major=$(node -p 'process.versions.node.split(".")[0]')
if [ "$node_major" -lt 20 ]; then
  echo "setup: Node.js $(node --version) is older than 20; snapthread-web's page and browser tests need >= 20" >&2
  echo "setup: install a newer Node.js, or configure with -DSNAPTHREAD_BUILD_WEB=OFF" >&2
  exit 1
fi

if [ "${1:-}" != "--no-build" ]; then
  cmake -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release
  cmake --build "$here/build" -j"$(nproc)"
fi
