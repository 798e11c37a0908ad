#!/bin/sh
# analysis/sines_to_chirp.sh — models trained on pendulum data driven by a sum
# of sines, then rolled out on trajectories driven by a chirp (the
# time-varying-inputs test of docs/RESULTS.md): `phnn eval --data` takes the
# trained runs to the chirp's data set, whose states and inputs are the same.
#   sh analysis/sines_to_chirp.sh [OUT_DIR]     (build/phnn must exist)
set -eu
PHNN=${PHNN:-build/phnn}
PY=${PY:-/usr/bin/python3}
OUT=${1:-results/sines-to-chirp}
SINES=sweeps/systems/pendulum-forced.toml
mkdir -p "$OUT"
"$PHNN" data --system "$SINES" --n-train 100 --out "$OUT/sines.h5"
"$PHNN" data --system sweeps/systems/pendulum-chirp.toml --n-train 1 --out "$OUT/chirp.h5"
for model in phnn-s-dg phnn-jr-dg node-rk2; do
  "$PHNN" train --data "$OUT/sines.h5" --model "$model" --n-train 100 --seeds 0-9 --quiet \
      --out "$OUT/$model.h5"
  "$PHNN" eval "$OUT/$model.h5" --data "$OUT/chirp.h5" --errors "$OUT/$model-chirp.csv" > /dev/null
done
"$PY" analysis/plot_eval_errors.py "$OUT"/*-chirp.csv --out "$OUT/chirp-errors"
echo "results in $OUT: <model>.h5 (sines inference), <model>-chirp.csv (chirp inference), chirp-errors.pdf"
