#!/usr/bin/env python3
"""A results file as a pandas DataFrame: one row per run, one column per configuration key and per
result.

    /usr/bin/python3 -c "from analysis.results import load; \\
        print(load('results/tiny.h5').groupby(['model_label', 'n_train']).mse.median())"

    from analysis.results import load, traces
    runs = load("results/paper.h5")              # every run, pending ones included (of an
                                                 # adaptive or search sweep: those its rounds asked for)
    done = runs[runs.status == "done"]
    done.groupby(["system", "model_label", "n_train"]).mse.median()
    t = traces("results/paper.h5")              # one row per validation point of every run
    w = weights("results/paper.h5", "3f2a")      # {"l_h.0.weight": array (2, 16), ...}

The columns are those of `phnn reduce FILE --per-run --format csv` (docs/RESULTS_FORMAT.md,
"Per-run CSV"): `run_id`; every setting of the run (`system`, `model`, `integrator`, `size`,
`n_train`, `regularizer`, `seed`, the system's physics, data and training settings, each its own
column); `model_label` (e.g. `PHNN-JR-RK2`); `status` (a category: pending, done, diverged,
failed); the results (`mse`, `best_step`, `wall_time_s`, ...) and `message`. Numbers are exact
(the CSV's text reads back to the stored double, and is read so), integers are int64,
missing values NaN. The reducer reads the file, so every file phnn can read loads here, old ones
included. The phnn binary: $PHNN, else build/phnn of this repository.
"""
import argparse
import io
import os
import subprocess
import sys

STATUSES = ["pending", "done", "diverged", "failed"]
# Columns that hold text, never numbers (a system file's name may look like one).
TEXT = {"run_id", "studies", "model_label", "system", "model", "integrator", "size", "regularizer",
        "status", "message"}


def _phnn():
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return os.environ.get("PHNN", os.path.join(here, "build", "phnn"))


def _reduce(path, *args):
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such results file")
    done = subprocess.run([_phnn(), "reduce", path, "--per-run", "--format", "csv", *args],
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"phnn reduce {path} failed ({done.returncode}): {done.stderr.strip()}")
    return done.stdout


def load(path):
    """Every run of the results file `path` as a DataFrame (one row per run)."""
    import pandas as pd
    text = _reduce(path)
    header = text.split("\n", 1)[0].split(",")
    # round_trip: pandas' default parser is fast but can be off in the last bit.
    frame = pd.read_csv(io.StringIO(text), dtype={c: str for c in header if c in TEXT},
                        float_precision="round_trip",
                        keep_default_na=False, na_values={c: ["", "nan"] for c in header
                                                          if c not in TEXT})
    frame["status"] = pd.Categorical(frame["status"], categories=STATUSES)
    return frame


def traces(path):
    """The training logs: one row per validation point of every run (`run_id`, `step`,
    `elapsed_s`, `train_loss`, `validation_loss`, `kappa`, `sigma_max`, `rho`), read with h5py
    from /runs/trace (docs/RESULTS_FORMAT.md)."""
    import h5py
    import numpy as np
    import pandas as pd
    with h5py.File(path, "r") as f:
        runs = f["runs"]
        ids = [s.decode().rstrip("\0") for s in runs["id"][:]]
        trace = runs["trace"][:]
        lengths = runs["trace_length"][:]
        names = runs["trace"].attrs["columns"]  # "step, elapsed_s, ..."
        names = names.decode() if isinstance(names, bytes) else str(names)
        columns = [c.strip() for c in names.split(",")]
    parts = []
    for row, n in enumerate(lengths):
        if n > 0:
            part = pd.DataFrame(trace[row, :n, :], columns=columns)
            part.insert(0, "run_id", ids[row])
            parts.append(part)
    if not parts:
        return pd.DataFrame(columns=["run_id", *columns])
    out = pd.concat(parts, ignore_index=True)
    out["step"] = out["step"].astype(np.int64)
    return out


def weights(path, run_id):
    """One run's stored weights (the best-validation weights inference used) as a dict of named
    numpy arrays in storage order, e.g. {"l_h.0.weight": (2, 16) array, "l_h.0.bias": (16,), ...}:
    per network layer its weight [fan_in, fan_out] (x @ W + b) and bias. `run_id` may be a unique
    prefix. Reads /weights and /runs/weights_layout with h5py (docs/RESULTS_FORMAT.md)."""
    import h5py
    import numpy as np
    with h5py.File(path, "r") as f:
        runs = f["runs"]
        ids = [s.decode().rstrip("\0") for s in runs["id"][:]]
        rows = [k for k, i in enumerate(ids) if i.startswith(run_id)]
        if len(rows) != 1:
            raise KeyError(f"{path}: {len(rows)} runs match id {run_id!r}; give a unique prefix")
        row = rows[0]
        if "weights_layout" not in runs:
            raise KeyError(f"{path}: written before weight names and shapes were stored; "
                           "`phnn eval` reloads its weights")
        length = int(runs["weights_length"][row])
        if length == 0:
            raise KeyError(f"{path}: run {ids[row]} has no stored weights (status "
                           f"{int(runs['status'][row])})")
        offset = int(runs["weights_offset"][row])
        flat = f["weights"][offset:offset + length]
        layout = runs["weights_layout"][row].decode().rstrip("\0")
    out, at = {}, 0
    for entry in layout.split("; "):
        name, shape_text = entry.split(" ")
        shape = tuple(int(d) for d in shape_text.split("x"))
        n = int(np.prod(shape))
        out[name] = np.asarray(flat[at:at + n]).reshape(shape)
        at += n
    if at != length:
        raise ValueError(f"{path}: run {ids[row]}: the layout holds {at} weights, the row {length}")
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description="Print a results file's runs as pandas sees "
                                     "them: one row per run, one column per setting and result.")
    parser.add_argument("results", help="results file written by `phnn sweep`")
    parser.add_argument("--columns", action="store_true", help="list the columns and their types")
    args = parser.parse_args(argv)
    frame = load(args.results)
    if args.columns:
        print(frame.dtypes.to_string())
    else:
        print(frame.to_string(max_rows=40, max_cols=12))
    return 0


if __name__ == "__main__":
    sys.exit(main())
