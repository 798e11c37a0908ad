#!/usr/bin/env bash
# Fresh machine to a table in one command: set-up and build of phnn alone
# (scripts/build.sh --demo: no tests, no benchmarks), the demo sweep on 2
# local MPI ranks (sweeps/demo.toml), then its median [IQR] tables and the
# time it all took.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
bash scripts/build.sh --demo
built=$(date +%s)
bash jobs/local.sh sweeps/demo.toml 2 "$@"
end=$(date +%s)
echo "demo: set-up and build $(( (built - start) / 60 )) min $(( (built - start) % 60 )) s," \
     "sweep and tables $(( end - built )) s, first table after $(( (end - start) / 60 )) min $(( (end - start) % 60 )) s"
