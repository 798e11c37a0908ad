#!/usr/bin/env python3
"""Errors of trained runs on another data set (the CSV of `phnn eval RESULTS --data FILE
--errors ERRORS.csv`): a table of each model's median error per inference trajectory and MSE
over seeds, and a figure of the errors per model (every trajectory of every seed) as PDF and PNG.

    build/phnn eval sines.h5 --data chirp.h5 --errors chirp.csv
    /usr/bin/python3 analysis/plot_eval_errors.py chirp.csv --out fig/chirp [--title "..."]

Several CSVs (one per training set, say) are labelled by their file stems.
"""
import argparse
import os
import sys

import numpy as np
import pandas as pd

COLUMNS = ["run_id", "system", "model", "integrator", "size", "n_train", "regularizer", "seed",
           "trajectory", "position", "error", "mse"]


def load(paths):
    """One frame of every CSV, with `source` = the file stem and `label` = MODEL-INTEGRATOR."""
    frames = []
    for path in paths:
        frame = pd.read_csv(path)
        missing = [c for c in COLUMNS if c not in frame.columns]
        if missing:
            sys.exit(f"{path}: not a `phnn eval --errors` CSV (missing {', '.join(missing)})")
        frame["source"] = os.path.splitext(os.path.basename(path))[0]
        frame["label"] = frame.model.str.upper() + "-" + frame.integrator.str.upper()
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def summary(frame):
    """Per source and model: seeds, trajectories, the median error per trajectory (all seeds'
    trajectories pooled) and the median and IQR of the runs' MSE."""
    rows = []
    for (source, label), group in frame.groupby(["source", "label"], sort=True):
        mse = group.drop_duplicates("run_id").mse.to_numpy()
        q25, q75 = np.percentile(mse, [25, 75])
        rows.append({"source": source, "model": label, "seeds": group.run_id.nunique(),
                     "trajectories": group.trajectory.nunique(),
                     "median_error": float(np.median(group.error)),
                     "median_mse": float(np.median(mse)), "iqr_mse": float(q75 - q25)})
    return pd.DataFrame(rows)


def markdown(table):
    lines = ["| data | model | seeds | trajectories | median error per trajectory | MSE median [IQR] |",
             "|---|---|---|---|---|---|"]
    for r in table.itertuples():
        lines.append(f"| {r.source} | {r.model} | {r.seeds} | {r.trajectories} | "
                     f"{r.median_error:.3e} | {r.median_mse:.3e} [{r.iqr_mse:.2e}] |")
    return "\n".join(lines)


def plot(frame, out, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    groups = [(f"{s}\n{m}" if frame.source.nunique() > 1 else m, g.error.to_numpy())
              for (s, m), g in frame.groupby(["source", "label"], sort=True)]
    fig, ax = plt.subplots(figsize=(1.2 + 1.1 * len(groups), 3.2))
    ax.boxplot([np.log10(np.maximum(e, 1e-300)) for _, e in groups], whis=(5, 95), showfliers=False)
    ax.set_xticks(range(1, len(groups) + 1), [name for name, _ in groups], fontsize=8)
    ax.set_ylabel("log10 error per trajectory")
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    os.makedirs(os.path.dirname(out) or ".", exist_ok=True)
    for ext in ("pdf", "png"):
        fig.savefig(f"{out}.{ext}", dpi=150)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("csv", nargs="+", help="CSV files of `phnn eval --data ... --errors`")
    parser.add_argument("--out", help="figure path without extension (writes .pdf and .png)")
    parser.add_argument("--title", default="errors on another data set (boxes: quartiles, "
                        "whiskers: 5-95 %)")
    args = parser.parse_args(argv)
    frame = load(args.csv)
    print(markdown(summary(frame)))
    if args.out:
        plot(frame, args.out, args.title)


if __name__ == "__main__":
    main()
