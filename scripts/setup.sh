#!/usr/bin/env bash
# Installs the Debian 12 packages ballpit needs, and only those missing. Run as root.
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libeigen3-dev libomp-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libassimp-dev assimp-testmodels
  libglfw3-dev libepoxy-dev libimgui-dev libegl-dev libgl1-mesa-dri libegl-mesa0 libpng-dev xvfb xauth
  libbullet-dev
  clang libclang-rt-14-dev
  python3-matplotlib
  python3-dev pybind11-dev python3-numpy python3-pytest
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[setup] installing: ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then
    echo "[setup] must run as root to install packages" >&2
    exit 1
  fi
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "[setup] all packages present"
fi
