#!/usr/bin/env python3
"""Figures from a phnn-sweep results file (h5py + matplotlib, Debian packages).

    python3 analysis/plot_results.py results/paper.h5 figures/

Writes, per system:
  mse_boxplot_<study>_<system>.png    inference MSE per model and study column
                                      (paper Figures 6, 8, 11)
  jacobian_trace_<system>.png         mean kappa / sigma_max / rho per validation
                                      step over seeds, min-max band (Figures 10, 12)
  trajectories_<system>.png           predicted vs reference trajectory from
                                      H(x0) = 0.5 J (Figures 7, 9), seed 0
Only finished runs (status done) are drawn; the file may be partial.
"""
import os
import sys
from collections import defaultdict

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

STATUS_DONE = 1
MODEL_ORDER = ["NODE-RK2", "PHNN-JR-DG", "PHNN-JR-RK2", "PHNN-S-DG", "PHNN-S-RK2"]


def text(column):
    return [v.decode() if isinstance(v, bytes) else str(v) for v in column]


def label(model, integrator):
    return {"node": "NODE", "phnn-s": "PHNN-S", "phnn-jr": "PHNN-JR"}[model] + "-" + integrator.upper()


def load(path):
    with h5py.File(path, "r") as f:
        if f.attrs.get("format", b"") not in (b"phnn-results", "phnn-results"):
            sys.exit(f"{path}: not a phnn results file (no format = phnn-results attribute)")
        r = f["runs"]
        runs = {
            "system": text(r["system"][()]),
            "model": [label(m, i) for m, i in zip(text(r["model"][()]), text(r["integrator"][()]))],
            "size": text(r["size"][()]),
            "regularizer": text(r["regularizer"][()]),
            "n_train": r["n_train"][()],
            "seed": r["seed"][()],
            "studies": text(r["studies"][()]),
            "status": r["status"][()],
            "mse": r["mse"][()],
            "trace": r["trace"][()],
            "trace_length": r["trace_length"][()],
            "prediction_05": r["figure/prediction_05"][()],
            "reference_05": r["figure/reference_05"][()],
        }
    return runs


def study_axis(runs, rows):
    for axis in ("n_train", "size", "regularizer"):
        if len({str(runs[axis][i]) for i in rows}) > 1:
            return axis
    return None


def boxplots(runs, out):
    by_study = defaultdict(list)
    for i, studies in enumerate(runs["studies"]):
        for s in studies.split(","):
            if s:
                by_study[s].append(i)
    for study, rows in by_study.items():
        axis = study_axis(runs, rows)
        for system in sorted({runs["system"][i] for i in rows}):
            sel = [i for i in rows if runs["system"][i] == system and runs["status"][i] == STATUS_DONE]
            if not sel:
                continue
            columns = sorted({str(runs[axis][i]) for i in sel}, key=lambda c: (len(c), c)) if axis else ["all"]
            models = [m for m in MODEL_ORDER if any(runs["model"][i] == m for i in sel)]
            fig, ax = plt.subplots(figsize=(1.6 + 1.4 * len(columns) * len(models) / 3, 4))
            data, positions, colors = [], [], []
            for c, column in enumerate(columns):
                for m, model in enumerate(models):
                    values = [runs["mse"][i] for i in sel if runs["model"][i] == model
                              and (axis is None or str(runs[axis][i]) == column)]
                    values = [v for v in values if np.isfinite(v)]
                    if values:
                        data.append(values)
                        positions.append(c * (len(models) + 1) + m)
                        colors.append(f"C{m}")
            box = ax.boxplot(data, positions=positions, widths=0.8, patch_artist=True)
            for patch, color in zip(box["boxes"], colors):
                patch.set_facecolor(color)
            ax.set_yscale("log")
            ax.set_xticks([c * (len(models) + 1) + (len(models) - 1) / 2 for c in range(len(columns))])
            ax.set_xticklabels(columns)
            ax.set_xlabel(axis or "")
            ax.set_ylabel("inference MSE")
            ax.set_title(f"study {study}: {system}")
            ax.legend([plt.Rectangle((0, 0), 1, 1, color=f"C{m}") for m in range(len(models))], models,
                      fontsize=7)
            fig.tight_layout()
            fig.savefig(os.path.join(out, f"mse_boxplot_{study}_{system}.png"), dpi=120)
            plt.close(fig)


def jacobian_traces(runs, out):
    for system in sorted(set(runs["system"])):
        fig, axes = plt.subplots(1, 3, figsize=(13, 3.5))
        for m, model in enumerate(MODEL_ORDER):
            sel = [i for i in range(len(runs["system"])) if runs["system"][i] == system
                   and runs["model"][i] == model and runs["status"][i] == STATUS_DONE
                   and runs["regularizer"][i] == "none" and runs["size"][i] == "small"
                   and runs["n_train"][i] == 25]
            if not sel:
                continue
            n = int(min(runs["trace_length"][i] for i in sel))
            traces = np.stack([runs["trace"][i][:n] for i in sel])  # [seeds, n, 7]
            steps = traces[0, :, 0]
            for a, (col, name) in enumerate([(4, "condition number"), (5, "spectral norm"),
                                             (6, "stiffness ratio")]):
                values = traces[:, :, col]
                axes[a].plot(steps, values.mean(0), color=f"C{m}", label=model)
                axes[a].fill_between(steps, values.min(0), values.max(0), color=f"C{m}", alpha=0.2)
                axes[a].set_yscale("log")
                axes[a].set_xlabel("optimizer step")
                axes[a].set_title(name)
        axes[0].legend(fontsize=7)
        fig.suptitle(f"{system}: small models, N_train = 25, no regularizer")
        fig.tight_layout()
        fig.savefig(os.path.join(out, f"jacobian_trace_{system}.png"), dpi=120)
        plt.close(fig)


def trajectories(runs, out):
    for system in sorted(set(runs["system"])):
        fig, ax = plt.subplots(figsize=(5, 4))
        reference_drawn = False
        for m, model in enumerate(MODEL_ORDER):
            sel = [i for i in range(len(runs["system"])) if runs["system"][i] == system
                   and runs["model"][i] == model and runs["status"][i] == STATUS_DONE
                   and runs["seed"][i] == 0 and runs["regularizer"][i] == "none"]
            if not sel:
                continue
            i = sel[0]
            if not reference_drawn:
                ref = runs["reference_05"][i]
                ax.plot(ref[:, 0], ref[:, 1], "k-", lw=2, label="reference (DG, 400 Hz)")
                reference_drawn = True
            pred = runs["prediction_05"][i]
            ax.plot(pred[:, 0], pred[:, 1], color=f"C{m}", lw=1, label=model)
        ax.set_xlabel("q [m]")
        ax.set_ylabel("p [kg m/s]")
        ax.set_title(f"{system}: from H(x0) = 0.5 J, seed 0")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(out, f"trajectories_{system}.png"), dpi=120)
        plt.close(fig)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    path, out = sys.argv[1], sys.argv[2]
    if not os.path.exists(path):
        sys.exit(f"{path}: no such file; run `phnn sweep` first")
    os.makedirs(out, exist_ok=True)
    runs = load(path)
    boxplots(runs, out)
    jacobian_traces(runs, out)
    trajectories(runs, out)
    print(f"figures written to {out}/")


if __name__ == "__main__":
    main()
