#!/usr/bin/env bash
# Fresh machine to a table in one command: set-up, build, the demo sweep on 2
# local MPI ranks (sweeps/demo.toml), then its median [IQR] tables.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
bash jobs/local.sh sweeps/demo.toml 2 "$@"
