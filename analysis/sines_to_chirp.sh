#!/bin/sh
# analysis/sines_to_chirp.sh — models trained on pendulum data driven by a sum
# of sines, then evaluated on inference trajectories driven by a chirp (the
# time-varying-inputs test of docs/RESULTS.md). The two data sets share their
# pair draws (same trajectory ids, same system name on import), so one
# import of the sines' training and validation trajectories with the chirp's
# inference trajectories trains exactly the models of the sines set.
#   sh analysis/sines_to_chirp.sh [OUT_DIR]     (build/phnn must exist)
set -eu
PHNN=${PHNN:-build/phnn}
OUT=${1:-results/sines-to-chirp}
SINES=sweeps/systems/pendulum-forced.toml
mkdir -p "$OUT"
"$PHNN" data --system "$SINES" --n-train 100 --out "$OUT/sines.h5" --csv "$OUT/sines.csv"
"$PHNN" data --system sweeps/systems/pendulum-chirp.toml --n-train 1 --out "$OUT/chirp.h5" \
    --csv "$OUT/chirp.csv"
# Ids below 2900 (training, validation) from the sines, 2900 and above
# (inference: num_train_max 400 + num_validation 2500) from the chirp.
awk -F, 'FNR == 1 && /^#/ { next }
         /^trajectory,/ { if (!header) print; header = 1; next }
         (FILENAME ~ /sines/ && $1 < 2900) || (FILENAME ~ /chirp/ && $1 >= 2900)' \
    "$OUT/sines.csv" "$OUT/chirp.csv" > "$OUT/sines-chirp.csv"
"$PHNN" import "$OUT/sines-chirp.csv" --system "$SINES" --num-validation 2500 --num-inference 100 \
    --out "$OUT/sines-chirp.h5"
for model in phnn-s-dg phnn-jr-dg node-rk2; do
  for data in sines sines-chirp; do
    "$PHNN" train --system "$SINES" --model "$model" --n-train 100 --seeds 0-9 --quiet \
        --data "$OUT/$data.h5" --out "$OUT/$model-$data.h5"
  done
done
echo "results in $OUT: <model>-sines.h5 (sines inference), <model>-sines-chirp.h5 (chirp inference)"
