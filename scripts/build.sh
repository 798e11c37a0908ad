#!/usr/bin/env bash
# Installs the dependencies (scripts/setup.sh) and builds phnn into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
MPI_PREFLAGS="--oversubscribe"
if [[ $(id -u) -eq 0 ]]; then MPI_PREFLAGS="--allow-run-as-root;--oversubscribe"; fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
      "-DMPIEXEC_PREFLAGS=${MPI_PREFLAGS}" > build-configure.log 2>&1 \
  || { cat build-configure.log; exit 1; }
cmake --build build -j "${PHNN_BUILD_JOBS:-2}"
