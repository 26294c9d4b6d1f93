#!/usr/bin/env bash
# Installs the Debian 12 packages meshquilt builds against, skipping those already present.
set -euo pipefail
packages=(build-essential cmake ninja-build pkg-config
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers clinfo
  libtbb-dev libeigen3-dev libembree-dev libtet1.5-dev libboost-graph-dev
  libpng-dev libgtest-dev libbenchmark-dev libtinygltf-dev python3
  clang libclang-rt-14-dev clang-format-14 clang-tidy-14)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
