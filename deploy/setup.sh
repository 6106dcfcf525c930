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
  gnuplot-nox graphviz python3 ccache
  clang libclang-rt-14-dev
  libceres-dev liblapack-dev
  iproute2 procps
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

if [ "${1:-}" != "--no-build" ]; then
  cmake -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release
  cmake --build "$here/build" -j"$(nproc)"
fi
