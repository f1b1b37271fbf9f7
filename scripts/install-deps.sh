#!/usr/bin/env bash
# Installs every build and test dependency of tetseg from Debian 12 packages.
# Run as root (or with sudo). Safe to run again: already-installed packages are skipped.
set -euo pipefail

packages=(
  build-essential cmake ninja-build ccache pkg-config
  libcgal-dev libcgal-demo libgmp-dev libmpfr-dev libboost-dev   # preprocess (CGAL, GPL)
  libeigen3-dev libassimp-dev libomp-dev                           # preprocess
  libtbb-dev                                                       # parallel Mesh_3 (--threads)
  libcereal-dev                                                    # asset payload (header-only)
  libcli11-dev libpng-dev                                          # command-line tools
  catch2                                                           # tests
  clang libclang-rt-14-dev                                         # libFuzzer target
  clang-format                                                     # scripts/check-format.sh
  python3                                                          # test helpers
  pybind11-dev python3-dev python3-numpy                           # Python package (python/)
  python3-pytest python3-venv python3-pip python3-setuptools python3-wheel  # its tests, pip install
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "install-deps: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "install-deps: all ${#packages[@]} packages present"
fi
