#!/usr/bin/env bash
# Installs the dependencies (scripts/setup.sh) and builds phnn into build/.
#   scripts/build.sh           everything: phnn, the tests and the benchmarks
#   scripts/build.sh --demo    phnn alone (what the demo runs): fewer packages, ~1/3 of the build
set -euo pipefail
cd "$(dirname "$0")/.."
demo=${1:-}
bash scripts/setup.sh $demo
MPI_PREFLAGS="--oversubscribe"
if [[ $(id -u) -eq 0 ]]; then MPI_PREFLAGS="--allow-run-as-root;--oversubscribe"; fi
parts=ON
if [[ $demo == --demo ]]; then parts=OFF; fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DPHNN_BUILD_TESTS=$parts -DPHNN_BUILD_BENCH=$parts \
      "-DMPIEXEC_PREFLAGS=${MPI_PREFLAGS}" > build-configure.log 2>&1 \
  || { cat build-configure.log; exit 1; }
cmake --build build -j "${PHNN_BUILD_JOBS:-2}"
