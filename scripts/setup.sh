#!/usr/bin/env bash
# Installs every Debian package tetcollapse needs to build, test and benchmark.
# Idempotent: when everything is there it installs nothing and does not touch apt.
#   scripts/setup.sh              build + test dependencies
#   scripts/setup.sh --with-tools also the mesh tools used by scripts/ (gmsh + its Python module, tetgen, matplotlib)
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers pocl-opencl-icd clinfo
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev zlib1g-dev libcli11-dev
  googletest libgtest-dev libbenchmark-dev
  python3 python3-meshio          # independent reader used by the cross-read tests
)
if [[ "${1:-}" == "--with-tools" ]]; then
  packages+=(gmsh python3-gmsh tetgen python3-matplotlib python3-numpy clang libclang-rt-14-dev llvm-14)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
