#!/usr/bin/env python3
"""Learning work-precision: training cost against inference MSE at step budgets.

    phnn sweep sweeps/time-vs-error.toml
    /usr/bin/python3 analysis/time_vs_error.py results/time-vs-error.h5 OUTDIR

Reads the checkpoints of a results file whose sweep set `[training] checkpoints`.
Each run stores, for every budget s:
- the inference MSE (Eq. 31) of its best-validation weights up to step s, which is bitwise the
  MSE of a run trained for s steps;
- the training wall time spent to reach s, as this run's share of its stack, with inference
  excluded.

Writes:
- OUTDIR/time_vs_error.md: per system, n_train and model, the median [IQR] MSE over the done
  seeds at every budget, with the median core-seconds per run. The models on the Pareto front
  (no other model both cheaper and better at some budget) are marked with *.
- OUTDIR/time_vs_error_<system>.png: one panel per n_train. Median core-seconds per run against
  median MSE, one line per model through its budgets, bars for the IQR, and the same fixed colour
  per model as analysis/plot_results.py.

Runs are grouped by (system, n_train, model label). Only runs with status done or diverged are
used. A diverged rollout has MSE +inf, which the medians keep: a median of +inf is printed as inf
and is left off the plot.
"""
import argparse
import math
import os
import sys
from collections import defaultdict

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

STATUS_DONE, STATUS_DIVERGED = 1, 2
COLOURS = {
    "NODE-RK2": "#7f7f7f", "PHNN-JR-DG": "#d62728", "PHNN-JR-RK2": "#1f77b4",
    "PHNN-S-DG": "#ff7f0e", "PHNN-S-RK2": "#2ca02c", "NODE-RK4": "#bcbd22",
    "PHNN-JR-DG4": "#8c564b", "PHNN-JR-RK4": "#17becf", "PHNN-S-DG4": "#e377c2",
    "PHNN-S-RK4": "#9467bd",
}


def text(column):
    return [v.decode() if isinstance(v, bytes) else str(v) for v in column]


def label(model, integrator):
    name = {"node": "NODE", "phnn-s": "PHNN-S", "phnn-jr": "PHNN-JR"}[model]
    return name + "-" + integrator.upper()


def load(path):
    with h5py.File(path, "r") as f:
        runs = f["runs"]
        if "checkpoint_mse" not in runs:
            sys.exit(f"{path}: no /runs/checkpoint_mse; the sweep must set [training] checkpoints "
                     "(see sweeps/time-vs-error.toml)")
        steps = runs["checkpoint_steps"][()]
        status = runs["status"][()]
        used = [r for r in range(len(status)) if status[r] in (STATUS_DONE, STATUS_DIVERGED)]
        budgets = sorted({tuple(int(s) for s in steps[r] if s > 0) for r in used})
        if len(budgets) > 1:
            sys.exit(f"{path}: runs have different checkpoints {budgets}; one set per file")
        return {
            "budgets": list(budgets[0]) if budgets else [],
            "system": text(runs["system"][()]),
            "model": [label(m, i) for m, i in zip(text(runs["model"][()]),
                                                  text(runs["integrator"][()]))],
            "n_train": runs["n_train"][()],
            "status": status,
            "mse": runs["checkpoint_mse"][()],
            "seconds": runs["checkpoint_train_seconds"][()],
        }


def quantiles(values):
    """Median and IQR with +inf kept exact (numpy's linear quantile, inf-safe)."""
    v = np.sort(np.asarray(values, dtype=float))
    def q(p):
        pos = p * (len(v) - 1)
        lo, hi = math.floor(pos), math.ceil(pos)
        if lo == hi or v[lo] == v[hi]:
            return float(v[lo])
        if math.isinf(v[hi]):
            return math.inf
        return float(v[lo] + (pos - lo) * (v[hi] - v[lo]))
    return q(0.5), q(0.25), q(0.75)


def summarize(runs):
    groups = defaultdict(list)
    for r, status in enumerate(runs["status"]):
        if status in (STATUS_DONE, STATUS_DIVERGED):
            groups[(runs["system"][r], int(runs["n_train"][r]), runs["model"][r])].append(r)
    table = {}
    for key, rows in groups.items():
        per_budget = []
        for k in range(len(runs["budgets"])):
            med, q25, q75 = quantiles([runs["mse"][r][k] for r in rows])
            seconds = float(np.median([runs["seconds"][r][k] for r in rows]))
            per_budget.append({"median": med, "q25": q25, "q75": q75, "seconds": seconds})
        table[key] = {"n": len(rows), "budgets": per_budget}
    return table


def pareto(entries):
    """Keys of the (seconds, median) points no other point beats in both."""
    front = set()
    for key, e in entries.items():
        if not any(o["seconds"] <= e["seconds"] and o["median"] < e["median"] or
                   o["seconds"] < e["seconds"] and o["median"] <= e["median"]
                   for k, o in entries.items() if k != key):
            front.add(key)
    return front


def write_markdown(table, budgets, path):
    lines = []
    for system in sorted({k[0] for k in table}):
        for n_train in sorted({k[1] for k in table if k[0] == system}):
            models = sorted(k[2] for k in table if k[:2] == (system, n_train))
            points = {(m, b): table[(system, n_train, m)]["budgets"][b]
                      for m in models for b in range(len(budgets))}
            front = pareto(points)
            lines.append(f"### {system}, N_train = {n_train}\n")
            lines.append("| model | n | " + " | ".join(f"{s} steps" for s in budgets) + " |")
            lines.append("|---|---|" + "---|" * len(budgets))
            for m in models:
                e = table[(system, n_train, m)]
                cells = []
                for b, p in enumerate(e["budgets"]):
                    mark = " *" if (m, b) in front else ""
                    cells.append(f"{p['median']:.2e} [{p['q75'] - p['q25']:.1e}], "
                                 f"{p['seconds']:.3g} s{mark}")
                lines.append(f"| {m} | {e['n']} | " + " | ".join(cells) + " |")
            lines.append("")
    lines.append("Cell: median [IQR] inference MSE over seeds, median training core-seconds per "
                 "run; * = on the Pareto front of (core-seconds, median MSE) over every model "
                 "and budget of the panel.")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def plot(table, budgets, outdir):
    for system in sorted({k[0] for k in table}):
        n_values = sorted({k[1] for k in table if k[0] == system})
        fig, axes = plt.subplots(1, len(n_values), figsize=(6 * len(n_values), 4.5), squeeze=False)
        for ax, n_train in zip(axes[0], n_values):
            for m in sorted(k[2] for k in table if k[:2] == (system, n_train)):
                pts = [p for p in table[(system, n_train, m)]["budgets"]
                       if math.isfinite(p["median"])]
                if not pts:
                    continue
                x = [p["seconds"] for p in pts]
                y = [p["median"] for p in pts]
                lo = [p["median"] - p["q25"] for p in pts]
                hi = [p["q75"] - p["median"] if math.isfinite(p["q75"]) else 0 for p in pts]
                ax.errorbar(x, y, yerr=[lo, hi], fmt="o-", color=COLOURS.get(m, "k"),
                            label=f"{m} (n = {table[(system, n_train, m)]['n']})",
                            markersize=4, capsize=2)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("training core-seconds per run (median)")
            ax.set_ylabel("inference MSE (median, bars: IQR)")
            ax.set_title(f"{system}, N_train = {n_train}; budgets "
                         + ", ".join(str(b) for b in budgets) + " steps", fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, f"time_vs_error_{system}.png"), dpi=120)
        plt.close(fig)


def main():
    parser = argparse.ArgumentParser(
        description="Training cost against inference MSE at each step budget of a results file "
        "of sweeps/time-vs-error.toml: a Markdown table and one figure per system.")
    parser.add_argument("results", help="results file with [training] checkpoints")
    parser.add_argument("outdir", help="directory for the table and figures (created)")
    args = parser.parse_args()
    sys.argv[1:] = [args.results, args.outdir]
    runs = load(sys.argv[1])
    os.makedirs(sys.argv[2], exist_ok=True)
    table = summarize(runs)
    if not table:
        sys.exit(f"{sys.argv[1]}: no finished runs yet")
    write_markdown(table, runs["budgets"], os.path.join(sys.argv[2], "time_vs_error.md"))
    plot(table, runs["budgets"], sys.argv[2])
    print(f"wrote {sys.argv[2]}/time_vs_error.md and time_vs_error_<system>.png")


if __name__ == "__main__":
    main()
