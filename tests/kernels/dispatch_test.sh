#!/usr/bin/env bash
# tests/kernels/dispatch_test.sh PHNN PYTHON — the same bits under every CPU
# dispatch setting this machine can run (docs/METHOD.md "Deterministic
# kernels"): one small Duffing cell (seeds 0-1, 200 Adam steps) of every model
# x integrator and of each regularizer (and DG4 with CN: its hand-written
# step's order-2 jet heads with the penalty's field jet), three float32 cells
# (LibTorch's float kernels replaced by pinned ones), and six cells of the
# 4-state coupled Duffing system file (DG: the LU Newton; DG4: the
# hand-written step's order-2 jet heads, ordered products at inference; CN
# and SR: the op-by-op jets' ordered broadcast sums, Eigen's spectra), trained
# under OPENBLAS_CORETYPE
# (default / Haswell), ATEN_CPU_CAPABILITY (default / avx2 / avx512) and
# PHNN_KERNEL_ISA (avx512 / avx2 / baseline); the per-run MSEs, validation
# losses, trajectory errors and final weights must be bitwise equal to the
# first setting's. Data sets (built-in and pendulum file, with measurement
# noise) must be bitwise equal under glibc's two libm variants. Exit 77
# (skip) without h5py.
set -euo pipefail
PHNN=$1
PYTHON=${2:-/usr/bin/python3}
"$PYTHON" -c "import h5py, numpy" 2>/dev/null || { echo "skip: no h5py/numpy"; exit 77; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

CELLS="node-rk2 node-rk4 phnn-s-rk2 phnn-s-dg phnn-s-rk4 phnn-s-dg4 phnn-jr-rk2 phnn-jr-dg
       phnn-jr-rk4 phnn-jr-dg4 phnn-jr-rk2:cn phnn-s-dg:sn phnn-s-rk2:sr phnn-jr-dg4:cn
       phnn-s-dg::coupled phnn-jr-dg4::coupled node-rk4::coupled
       phnn-s-rk2:cn:coupled phnn-jr-rk2:sr:coupled phnn-s-dg4::coupled
       phnn-jr-rk2:cn::float32 phnn-s-dg:sr::float32 node-rk4:::float32"
COUPLED="$(cd "$(dirname "$0")/../.." && pwd)/sweeps/systems/coupled-duffing.toml"
# OPENBLAS_CORETYPE:ATEN_CPU_CAPABILITY:PHNN_KERNEL_ISA; the first is the reference.
SETTINGS="Haswell:avx2:avx2 default:default:avx512 default:avx512:avx512 default:avx512:baseline"

train() {  # setting cell
  local ob at isa model reg system precision
  IFS=: read -r ob at isa <<< "$1"
  IFS=: read -r model reg system precision <<< "$2"
  [ "$system" = coupled ] && system=$COUPLED || system=duffing
  local env=(ATEN_CPU_CAPABILITY="$at" PHNN_KERNEL_ISA="$isa")
  [ "$ob" = default ] || env+=(OPENBLAS_CORETYPE="$ob")
  env "${env[@]}" "$PHNN" train --system "$system" --model "$model" --reg "${reg:-none}" \
      --steps 200 --eval-every 100 --seeds 0-1 --n-train 25 --precision "${precision:-float64}" --quiet \
      --out "$WORK/$1-$2.h5" > "$WORK/$1-$2.log" 2>&1 ||
    { cat "$WORK/$1-$2.log"; echo "FAIL: phnn train under $1 for $2"; exit 1; }
}

for s in $SETTINGS; do
  for c in $CELLS; do
    # The baseline kernels without FMA hardware are slow: three cells only.
    if [[ $s == *baseline && $c != node-rk2 && $c != phnn-jr-rk2:cn && $c != phnn-s-dg &&
          $c != phnn-jr-rk2:cn::float32 ]]; then
      continue
    fi
    train "$s" "$c"
  done
done

# Data generation under both of glibc's libm variants (its FMA/AVX2 ones and
# the SSE2 ones a CPU without FMA gets): initial states, measurement noise and
# the pendulum file's cos/sin are correctly rounded (common/cr_math.h), so the
# data sets must be bitwise equal. (The C library's own sin, cos, log give
# different bits here: docs/METHOD.md "Deterministic kernels".)
PENDULUM="$(dirname "$COUPLED")/pendulum.toml"
for d in harmonic self-sustained "$PENDULUM:--noise 0.01"; do
  IFS=: read -r system extra <<< "$d"
  name=$(basename "$system" .toml)
  # shellcheck disable=SC2086  # $extra is one option and its value
  "$PHNN" data --system "$system" $extra --out "$WORK/data-default-$name.h5" > /dev/null
  # shellcheck disable=SC2086
  GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA "$PHNN" data --system "$system" $extra \
    --out "$WORK/data-nofma-$name.h5" > /dev/null
done
"$PYTHON" - "$WORK" <<'PY'
import glob, os, sys
import h5py, numpy as np
failures, compared = 0, 0
for ref_path in sorted(glob.glob(os.path.join(sys.argv[1], "data-default-*.h5"))):
    with h5py.File(ref_path, "r") as a, h5py.File(ref_path.replace("-default-", "-nofma-"), "r") as b:
        def visit(name, obj):
            global failures, compared
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
                compared += 1
                if obj[...].tobytes() != b[name][...].tobytes():
                    failures += 1
                    print(f"DIFFERS: {os.path.basename(ref_path)} {name} without glibc's FMA variants")
        a.visititems(visit)
print(f"{compared} data sets compared bit for bit under glibc's two libm variants; {failures} differences")
sys.exit(1 if failures or compared == 0 else 0)
PY

"$PYTHON" - "$WORK" $SETTINGS <<'PY'
import glob, os, sys
import h5py, numpy as np
work, settings = sys.argv[1], sys.argv[2:]
ref_setting, failures, compared = settings[0], 0, 0
def load(path):
    with h5py.File(path, "r") as f:
        r = f["runs"]
        return {"mse": r["mse"][...], "best_validation_loss": r["best_validation_loss"][...],
                "trajectory_errors": r["trajectory_errors"][...], "weights": f["weights"][...]}
for ref_path in sorted(glob.glob(os.path.join(work, ref_setting + "-*.h5"))):
    cell = os.path.basename(ref_path)[len(ref_setting) + 1:-3]
    ref = load(ref_path)
    for s in settings[1:]:
        path = os.path.join(work, s + "-" + cell + ".h5")
        if not os.path.exists(path):
            continue
        got, compared = load(path), compared + 1
        for key in ref:
            if ref[key].shape != got[key].shape or ref[key].tobytes() != got[key].tobytes():
                failures += 1
                print(f"DIFFERS: {cell} {key} under {s} vs {ref_setting}")
print(f"{compared} cells compared bit for bit against {ref_setting}; {failures} differences")
sys.exit(1 if failures or compared == 0 else 0)
PY
