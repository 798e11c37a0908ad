#!/usr/bin/env bash
# Installs every dependency of phnn-sweep from Debian packages. Idempotent:
# packages already present are skipped by apt. Needs root (or sudo).
#   scripts/setup.sh           everything: phnn, its tests, benchmarks, analysis
#   scripts/setup.sh --demo    what `phnn` and the demo need (no GoogleTest, no PyTorch)
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config
  libtorch-dev                       # LibTorch (CPU)
  libeigen3-dev                      # Eigen: the double-precision physics core
  libopenmpi-dev openmpi-bin         # Open MPI
  libhdf5-openmpi-dev hdf5-tools     # parallel HDF5 + h5dump
  libboost-mpi-dev                   # Boost.MPI (environment, communicator)
  libopenblas0-pthread               # fast BLAS behind libblas.so.3 (LibTorch uses it)
  libblas-dev                        # libblas.so to link dgemm_ (src/kernels/stacked_matmul.cpp)
  libjemalloc-dev                    # allocator: glibc malloc costs ~16 % of a step
  libtomlplusplus-dev                # toml++: the TOML parser of sweep files
  libcli11-dev                       # CLI11: the command-line parser of `phnn`
  libginac-dev                       # GiNaC: parses and differentiates system-file expressions
  libmuparser-dev                    # muParser: evaluates them fast (bytecode)
  libmpfr-dev                        # GNU MPFR: correctly rounded sin, cos, exp, ... (same bits on every CPU)
  python3-h5py python3-numpy python3-matplotlib python3-pandas  # analysis/ only
)
if [[ ${1:-} != --demo ]]; then
  PACKAGES+=(
    libgtest-dev libgmock-dev googletest   # the tests
    python3-torch                          # bench/pytorch_step.py only
  )
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#PACKAGES[@]} packages present"
fi
