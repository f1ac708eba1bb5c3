#!/usr/bin/env bash
# Installs every Debian package tetcollapse needs to build, test and benchmark.
# Idempotent: when everything is there it installs nothing and does not touch apt.
#   scripts/setup.sh              build + test dependencies (with the gmsh and tetgen programs,
#                                 which some I/O tests run)
#   scripts/setup.sh --with-tools also what scripts/ and bench/ use (gmsh's Python module,
#                                 matplotlib, VTK and Xvfb for the renderings, clang for fuzzing;
#                                 MMG3D, which Debian does not
#                                 package, from PyPI's mmgpy wheel for the peers benchmark; PyVista,
#                                 which Debian does not package either, from PyPI over Debian's VTK)
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers pocl-opencl-icd clinfo
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev zlib1g-dev libcli11-dev
  googletest libgtest-dev libbenchmark-dev
  python3 python3-meshio          # independent reader used by the cross-read tests
  python3-dev pybind11-dev python3-numpy  # the Python module and its tests
  gmsh tetgen                     # the tests that read files these programs write, and vice versa
  libopenmpi-dev openmpi-bin libmetis-dev  # tetcollapse-mpi (mpi/) and its tests
)
if [[ "${1:-}" == "--with-tools" ]]; then
  packages+=(python3-gmsh python3-matplotlib python3-vtk9 xvfb clang libclang-rt-14-dev llvm-14)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# MMG3D (bench/peers.py): not in Debian; the mmgpy wheel on PyPI ships the mmg3d_O3 binary
install_mmg() {
  [[ "${1:-}" == "--with-tools" ]] || return 0
  command -v mmg3d_O3 >/dev/null && return 0
  echo "setup: installing MMG3D (PyPI mmgpy 0.17.1) into /opt/mmgpy"
  /usr/bin/python3 -m pip install -q --no-deps --target /opt/mmgpy mmgpy==0.17.1 &&
    ln -sf /opt/mmgpy/mmgpy/bin/mmg3d_O3 /usr/local/bin/mmg3d_O3 ||
    echo "setup: MMG3D not installed (the peers benchmark will skip it)" >&2
}

# PyVista (the Python module's from_pyvista / to_pyvista): pure Python over Debian's VTK, so
# without its dependencies from PyPI (Debian's numpy, matplotlib, pillow serve)
install_pyvista() {
  [[ "${1:-}" == "--with-tools" ]] || return 0
  /usr/bin/python3 -c "import pyvista" 2>/dev/null && return 0
  echo "setup: installing PyVista (PyPI pyvista 0.44.0, scooby, pooch) for /usr/bin/python3"
  /usr/bin/python3 -m pip install -q --break-system-packages --no-deps pyvista==0.44.0 scooby==0.12.1 pooch==1.9.0 ||
    echo "setup: PyVista not installed (its test will skip)" >&2
}

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  install_mmg "${1:-}"
  install_pyvista "${1:-}"
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
install_mmg "${1:-}"
install_pyvista "${1:-}"
echo "setup: done"
