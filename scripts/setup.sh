#!/usr/bin/env bash
# Installs every build and test dependency of hapticsim from Debian's archive, and three.js (the
# live view's 3-D drawing) from npm into web/view/node_modules, as web/view/package-lock.json pins
# it. Idempotent: what is already present is left alone. Runs as root or through sudo.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libboost-math-dev
  libssl-dev
  liblcm-dev liblcm-bin liblcm-java libjchart2d-java libspdlog-dev default-jdk-headless
  iproute2 util-linux systemd strace
  python3 universal-ctags
  python3-vtk9 python3-numpy
  libopenmpi-dev openmpi-bin
  chromium chromium-driver python3-selenium python3-pil
  xvfb
  clang libclang-rt-14-dev
  libnifti2-dev libassimp-dev
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# npm: Debian's, unless a Node.js that brings its own is installed already.
command -v npm >/dev/null || missing+=(npm)

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages already installed"
else
  if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# three.js for hapticsim view, compiled into the binary (tools/CMakeLists.txt): fetched once, again
# only when the lock file is newer than what npm last installed (its node_modules/.package-lock.json).
view="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/web/view"
if ! [ "$view/node_modules/.package-lock.json" -nt "$view/package-lock.json" ] ||
   ! [ -f "$view/node_modules/three/build/three.module.js" ]; then
  echo "setup: npm ci in web/view (three.js for hapticsim view)"
  npm ci --prefix "$view" --no-audit --no-fund --ignore-scripts --loglevel=error >/dev/null
fi
echo "setup: done"
