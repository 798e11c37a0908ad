#!/usr/bin/env python3
"""Figures from one phnn-sweep results file (Debian h5py + matplotlib + numpy).

    /usr/bin/python3 analysis/plot_results.py results/paper.h5 figures/

Writes into OUTDIR, per system <sys> and study <st> (the file's [study.*] tables; a file without
studies has one pseudo-study, e.g. "grid"), each figure as <name>.png (300 dpi), <name>.pdf
(vector) and <name>.caption.txt (a one-line title is on the figure; the details are in the
caption):

  mse_<st>_<sys>.png          inference MSE (Eq. 31) per model and study column (paper Figs. 6, 8,
                              11): box = quartiles of the finite MSEs, every seed a jittered point,
                              diverged runs (status diverged or MSE = +inf) as triangles at the top
                              edge with their count, n per box under it; failed/pending runs counted
                              in the title.
  trajectories_<sys>.png      paper Figs. 7/9: q(t), p(t) and the phase portrait from H(x0) = 0.5 J
                              and 0.75 J (a system file: every state against t by its name and
                              unit, and one phase portrait per pair of its [plots] phase, along
                              inference trajectories 0 and 1), reference vs NODE-RK2 and the best
                              PHNN of the cell
                              (lowest median MSE); the seed drawn is the one with the median MSE
                              of its cell (lower median for even n), named in the legend.  Cell:
                              the file's most common size (small in paper.toml), no regularizer,
                              N_train 25 / 100 / 25 for harmonic / Duffing / self-sustained (the
                              nearest available N_train otherwise, said in the title).
  trajectories_sizes_<sys>.png  paper Fig. 9: the same two trajectories for the DG model of the
                              family the paper finds best on the system (PHNN-S-DG on harmonic and
                              Duffing, PHNN-JR-DG on self-sustained) at each model size (line
                              style per size), no regularizer, N_train 25 (nearest with more than
                              one size), each size at its median-MSE seed; written only when the
                              file has more than one size (Study II).
  jacobian_<sys>.png          paper Figs. 10/12: kappa [1], sigma_max [1/s], rho [1] of the learned
                              field's Jacobian at each validation point, median over seeds with the
                              interquartile band; one row per regularizer present (Study III),
                              most common size at the regularized runs' N_train (small, 25 in
                              paper.toml).  Study I/II columns get no trace figure.
  loss_<sys>.png              training and validation loss L_d (+ regularizer term) per validation
                              point, median over seeds with the interquartile band, same runs as
                              jacobian_<sys>.png.
  time_vs_error_<sys>.png     wall time per run against inference MSE, every finished run a point,
                              a model's median over all its runs as a diamond, diverged runs at the
                              top edge.  The trainer trains the seeds of a cell
                              as one stacked model and stores wall time / members, so a run's time
                              is its share of the stack, not a time measured alone.

Colours are fixed per model label (model + "-" + integrator, e.g. PHNN-S-DG4) in every figure;
columns follow the study's order (the sweep file's order; numeric for N_train, small < medium <
large, none < cn < sn < sr).  Pending runs (status 0) are skipped and counted; a figure with no
finished run is not written, and the script says so.
Tests: tests/analysis/plot_results_smoke.sh (synthetic file with every status) and
tests/analysis/test_plot_results.py.

  energy_<sys>.png            the learned energy H_theta against the true H [J] along the figure
                              trajectories from H(x0) = 0.5 J and 0.75 J, for the best PHNN of the
                              trajectories_<sys>.png cell at its median-MSE seed: H and H_theta
                              along the model's rollout and along the reference.  Made by
                              `phnn eval RESULTS --run ID --out CSV` from the run's stored weights
                              (the binary: $PHNN, else build/phnn next to analysis/); files
                              written before weights were stored get none, and the script says so.

  profile_<sys>.png           performance profiles: per model, the share of its runs on the system
                              with inference MSE <= tau over a log grid of tau, with a 95 %
                              bootstrap band over seeds; values in profile_<sys>.csv
                              (analysis/plot_comparisons.py).
  pimprove_<st>_<sys>.png     per column of the study, the matrix P(row model < column model)
                              from `phnn reduce --comparisons` (needs the binary; skipped without
                              it) (analysis/plot_comparisons.py).

The integrator work-precision figure comes from bench/ via analysis/plot_work_precision.py, not
from a results file.
"""
import argparse
import os
import subprocess
import sys
import textwrap
import warnings
from collections import Counter

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker as ticker  # noqa: E402
import numpy as np  # noqa: E402

try:
    import tomllib  # Python >= 3.11 (Debian bookworm)
except ImportError:  # study titles/order then come from the known orders only
    tomllib = None

PENDING, DONE, DIVERGED, FAILED = 0, 1, 2, 3
# One colour per model label, in every figure (tab10; the RK4/DG4 variants get the other five).
MODEL_COLOURS = {
    "NODE-RK2": "#1f77b4", "PHNN-JR-DG": "#ff7f0e", "PHNN-JR-RK2": "#2ca02c",
    "PHNN-S-DG": "#d62728", "PHNN-S-RK2": "#9467bd", "NODE-RK4": "#17becf",
    "PHNN-JR-RK4": "#bcbd22", "PHNN-S-RK4": "#8c564b", "PHNN-JR-DG4": "#e377c2",
    "PHNN-S-DG4": "#7f7f7f",
}
MODEL_ORDER = list(MODEL_COLOURS)
KNOWN_ORDER = {"size": ["small", "medium", "large"], "regularizer": ["none", "cn", "sn", "sr"],
               "system": ["harmonic", "duffing", "self-sustained"]}
STUDY_KEYS = {"n_train": "n_train", "sizes": "size", "regularizers": "regularizer"}
AXIS_LABEL = {"n_train": r"$N_\mathrm{train}$ (training pairs)", "size": "model size",
              "regularizer": "Jacobian regularizer"}
TRAJECTORY_N_TRAIN = {"harmonic": 25, "duffing": 100, "self-sustained": 25}
# Paper Fig. 9: the DG model of the family that does best on each system, across sizes, N_train 25.
SIZE_TRAJECTORY_MODEL = {"harmonic": "PHNN-S-DG", "duffing": "PHNN-S-DG",
                         "self-sustained": "PHNN-JR-DG"}
SIZE_STYLES = {"small": "--", "medium": "-.", "large": ":"}
TRACE_COLUMNS = {"kappa": 4, "sigma_max": 5, "rho": 6, "train": 2, "validation": 3}
DPI = 300  # PNG; every figure is also written as PDF (vector)


def text(column):
    return [v.decode().rstrip("\0") if isinstance(v, bytes) else str(v) for v in column]


def model_label(model, integrator):
    name = {"node": "NODE", "phnn-s": "PHNN-S", "phnn-jr": "PHNN-JR"}.get(model, model.upper())
    return name + "-" + integrator.upper()


def colour(label):
    return MODEL_COLOURS.get(label, "black")


def ordered_models(labels):
    present = set(labels)
    return [m for m in MODEL_ORDER if m in present] + sorted(present - set(MODEL_ORDER))


# --------------------------------------------------------------------------------------- loading
def load(path, round_k=None):
    """All of /runs as numpy arrays/lists, plus the sweep's name and its parsed TOML text; of an
    adaptive sweep only the runs its rounds asked for (up to round `round_k` when given)."""
    with h5py.File(path, "r") as f:
        if f.attrs.get("format", b"") not in (b"phnn-results", "phnn-results"):
            sys.exit(f"{path}: not a phnn results file (no format = phnn-results attribute)")
        r = f["runs"]
        runs = {k: text(r[k][()]) for k in ("system", "size", "regularizer", "studies", "canonical")}
        runs["id"] = text(r["id"][()]) if "id" in r else [""] * len(runs["system"])
        runs["has_weights"] = "weights" in f and "id" in r
        runs["model"] = [model_label(m, i) for m, i in zip(text(r["model"][()]),
                                                           text(r["integrator"][()]))]
        for k in ("n_train", "seed", "status", "mse", "wall_time_s", "trace", "trace_length"):
            runs[k] = r[k][()]
        for k in ("prediction_05", "prediction_075", "reference_05", "reference_075", "length"):
            runs[k] = r["figure/" + k][()]
        runs["n_x"] = r["n_x"][()] if "n_x" in r else np.full(len(runs["system"]), 2)
        runs["states"] = {name: system_states(f, name) for name in set(runs["system"])}
        name = text([f.attrs.get("sweep_name", b"")])[0]
        sweep = parse_sweep(text([f.attrs.get("sweep_text", b"")])[0])
    runs["mse"] = np.where(runs["status"] == DIVERGED, np.inf, runs["mse"])
    runs["rows"] = np.arange(len(runs["status"]))
    if "adaptive" in sweep:  # only the runs its rounds asked for (phnn reduce --per-run)
        from phnn_tool import run_csv
        extra = ("--round", str(round_k)) if round_k is not None else ()
        asked = {r["run_id"] for r in run_csv("reduce", path, "--per-run", *extra)}
        keep = np.array([i in asked for i in runs["id"]], dtype=bool)
        runs = {k: (v if k in ("states", "has_weights") else
                    v[keep] if isinstance(v, np.ndarray) else [x for x, k2 in zip(v, keep) if k2])
                for k, v in runs.items()}
        runs["rows"] = np.arange(len(runs["status"]))  # positions in the kept arrays
    return runs, name, sweep


def system_states(f, name):
    """A system's state names, units, phase pairs (indices), whether it is a system file, the
    initial energies of its figure trajectories, whether its data are recorded (`phnn import`:
    a data set with a `split` attribute, or a structure-only system file without H) and, for
    recorded or generated time-varying inputs on inference trajectories 0 and 1 (no figure
    energies), those inputs: from /data/<name> (a group of format_version 2 has state_names and
    its system file's text with [plots] phase and energies; the paper's three have energies 0.5
    and 0.75 J); a group of format_version 1 (files written before 2026-11-28) is a built-in
    system: q [m], p [kg m/s], 0.5 and 0.75 J."""
    group = f["data"][name] if "data" in f and name in f["data"] else None
    if group is None or "state_names" not in group.attrs:
        return {"names": ["q", "p"], "units": ["m", "kg m/s"], "pairs": [(0, 1)], "file": False,
                "energies": [0.5, 0.75], "recorded": False, "inputs": None}
    names = text([group.attrs["state_names"]])[0].split(",")
    units = text([group.attrs["state_units"]])[0].split(",")
    pairs = [(i, i + 1 if i + 1 < len(names) else 0) for i in range(0, len(names), 2)]
    if len(names) == 1:
        pairs = []
    system_file = parse_sweep(text([group.attrs.get("system_file", b"")])[0])
    plots = system_file.get("plots", {})
    if plots.get("phase"):
        pairs = [(names.index(a), names.index(b)) for a, b in plots["phase"]]
    energies = list(plots.get("energies", []))
    inputs = None
    if not energies and "inference" in group and "inputs" in group["inference"]:
        input_names = text([group.attrs.get("input_names", b"")])[0].split(",")
        inputs = {"names": input_names, "values": np.asarray(group["inference"]["inputs"][:2])}
    return {"names": names, "units": units, "pairs": pairs, "file": True, "energies": energies,
            "recorded": "split" in group.attrs or "H" not in system_file, "inputs": inputs}


def state_label(states, k):
    """Mathtext: the state's name in italics (a subscript after "_"), its unit upright."""
    name = states["names"][k]
    base, _, sub = name.partition("_")
    math = f"${base}_{{{sub}}}$" if sub else (f"${name}$" if name.isalnum() else name)
    return f"{math} [{states['units'][k]}]"


def figure_label(states, energy):
    """Row label of a figure trajectory: its initial energy, or the inference trajectory."""
    k = 0 if energy == "05" else 1
    if not states["energies"]:
        return f"inference trajectory {k}"
    return f"$H(x_0)$ = {states['energies'][min(k, len(states['energies']) - 1)]:g} J"


def parse_sweep(sweep_text):
    """The sweep file stored in the results file, as a dict ({} if unreadable)."""
    if tomllib is None:
        return {}
    try:
        return tomllib.loads(sweep_text)
    except tomllib.TOMLDecodeError:
        return {}


def axis_value(runs, axis, i):
    return int(runs[axis][i]) if axis == "n_train" else runs[axis][i]


def column_order(runs, axis, rows, sweep, study):
    """The study column values in the study's order (sweep file first, then known order)."""
    values = {axis_value(runs, axis, i) for i in rows}
    key = {v: k for k, v in STUDY_KEYS.items()}[axis]
    declared = sweep.get("study", {}).get(study, {}).get(key, [])
    first = [v for v in declared if v in values]
    rest = values - set(first)
    known = KNOWN_ORDER.get(axis, [])
    rest = sorted(rest, key=lambda v: (known.index(v) if v in known else len(known), v))
    return first + rest


def studies(runs, sweep):
    """{study: (title, rows, axis or None)} from the per-run study lists."""
    out = {}
    names = []
    for s in runs["studies"]:
        names += [n for n in s.split(",") if n and n not in names]
    for name in names:
        rows = [i for i in runs["rows"] if name in runs["studies"][i].split(",")]
        axis = None
        for a in ("n_train", "size", "regularizer"):
            if len({axis_value(runs, a, i) for i in rows}) > 1:
                axis = a
                break
        title = sweep.get("study", {}).get(name, {}).get("title", "")
        out[name] = (title, rows, axis)
    return out


def status_note(runs, rows):
    """'k of n runs drawn, ... diverged, ... failed, ... pending' for a figure title."""
    c = Counter(int(runs["status"][i]) for i in rows)
    parts = [f"{c[DONE] + c[DIVERGED]} of {len(rows)} runs drawn"]
    if c[DIVERGED]:
        parts.append(f"{c[DIVERGED]} diverged in training")
    inf = sum(runs["status"][i] == DONE and np.isinf(runs["mse"][i]) for i in rows)
    if inf:
        parts.append(f"{inf} with a diverged rollout (MSE = +inf)")
    nan = sum(runs["status"][i] == DONE and np.isnan(runs["mse"][i]) for i in rows)
    if nan:
        parts.append(f"{nan} done without an MSE (NaN, not drawn)")
    if c[FAILED]:
        parts.append(f"{c[FAILED]} failed (not drawn)")
    if c[PENDING]:
        parts.append(f"{c[PENDING]} pending (not drawn)")
    return ", ".join(parts)


def seeds_per_cell(runs, rows):
    return len({int(runs["seed"][i]) for i in rows})


def drawable(runs, rows):
    return [i for i in rows if runs["status"][i] in (DONE, DIVERGED)]


# ----------------------------------------------------------------------------- MSE box plots
def mse_boxplots(runs, name, sweep, out):
    """Paper Figs. 6, 8, 11: one figure per (study, system)."""
    written = []
    for study, (title, rows, axis) in studies(runs, sweep).items():
        for system in ordered_systems(runs, rows):
            sel = [i for i in rows if runs["system"][i] == system]
            if not drawable(runs, sel):
                continue
            cols = column_order(runs, axis, sel, sweep, study) if axis else [None]
            fig = mse_box_figure(runs, sel, axis, cols)
            suptitle(fig, f"{name}: {system}, study {study}" + (f" ({title})" if title else ""),
                     f"inference MSE per seed (points), box = quartiles of the finite MSEs, "
                     f"n = {seeds_per_cell(runs, sel)} seeds per cell; {status_note(runs, sel)}")
            path = save(fig, out, f"mse_{study}_{system}.png")
            written.append(path)
    return written


def study_names(runs, rows):
    """'study I, III' for the studies the rows belong to (in first-seen order)."""
    names = []
    for i in rows:
        names += [n for n in runs["studies"][i].split(",") if n and n not in names]
    return ("studies " if len(names) > 1 else "study ") + ", ".join(names) if names else "no study"


def save(fig, out, filename):
    """Lays out and writes OUTDIR/filename (PNG, 300 dpi), the same figure as PDF (vector) and its
    caption (the details suptitle() keeps out of the title) as <stem>.caption.txt; closes the
    figure; returns the PNG's path."""
    fig.tight_layout()
    path = os.path.join(out, filename)
    stem = os.path.splitext(path)[0]
    fig.savefig(path, dpi=DPI)
    fig.savefig(stem + ".pdf")
    caption = getattr(fig, "phnn_caption", "")
    if caption:
        with open(stem + ".caption.txt", "w") as f:
            f.write(caption + "\n")
    plt.close(fig)
    return path


def suptitle(fig, *lines):
    """A title (the first line, wrapped to the figure's width); every line goes to the caption
    file save() writes."""
    fig.suptitle(textwrap.fill(lines[0], width=max(60, int(fig.get_figwidth() * 13))), fontsize=10)
    fig.phnn_caption = "\n".join(lines)


def ordered_systems(runs, rows):
    present = {runs["system"][i] for i in rows}
    known = KNOWN_ORDER["system"]
    return [s for s in known if s in present] + sorted(present - set(known))


def mse_box_figure(runs, sel, axis, cols):
    """Boxes of the finite MSEs per (column, model), seeds as jittered points, diverged runs as
    triangles at the top edge with their count, drawn runs per box in grey at the bottom."""
    models = ordered_models(runs["model"][i] for i in sel)
    width = len(models) + 1
    fig, ax = plt.subplots(figsize=(max(8.0, 1.0 + 0.42 * width * len(cols)), 4.8))
    rng = np.random.default_rng(0)
    cells = []
    for c, col in enumerate(cols):
        for m, model in enumerate(models):
            cell = [i for i in drawable(runs, sel) if runs["model"][i] == model
                    and (axis is None or axis_value(runs, axis, i) == col)]
            cells.append((c * width + m, model, [runs["mse"][i] for i in cell]))
    finite_all = [v for _, _, vals in cells for v in vals if np.isfinite(v)]
    for x, model, vals in cells:
        draw_cell(ax, rng, x, model, vals)
    ax.set_yscale("log")
    label_minor_log_ticks(ax.yaxis)
    any_diverged = any(np.isinf(v) for _, _, vals in cells for v in vals)
    if finite_all:
        lo, hi = min(finite_all), max(finite_all)
        ax.set_ylim(lo / 3, hi * (30 if any_diverged else 3))  # headroom for diverged markers
    for x, model, vals in cells:
        ndiv = sum(np.isinf(v) for v in vals)
        if ndiv:
            ax.plot([x], [0.97], marker="^", ms=9, color=colour(model), mec="black",
                    transform=ax.get_xaxis_transform(), clip_on=False)
            ax.text(x, 0.91, f"{ndiv}", ha="center", va="top", fontsize=7,
                    transform=ax.get_xaxis_transform())
        ax.text(x, 0.01, f"{len(vals)}", ha="center", va="bottom", fontsize=6, color="0.4",
                transform=ax.get_xaxis_transform())
    ax.set_xticks([c * width + (len(models) - 1) / 2 for c in range(len(cols))])
    ax.set_xticklabels(["all runs" if c is None else str(c) for c in cols])
    for c in range(1, len(cols)):
        ax.axvline(c * width - 1, color="0.85", lw=0.8)
    ax.set_xlim(-1, len(cols) * width - 1)
    ax.set_xlabel(AXIS_LABEL.get(axis, "") + ("  (grey numbers: seeds per box)" if axis else
                                              "grey numbers: seeds per box"))
    ax.set_ylabel(r"inference MSE $\mathcal{E}$ [m², (kg m/s)² mixed]")
    # Legend entries only for what is drawn: models with runs, the marker if a run diverged.
    shown = [m for m in models if any(model == m and vals for _, model, vals in cells)]
    handles = [plt.Rectangle((0, 0), 1, 1, fc=colour(m), alpha=0.5, ec=colour(m)) for m in shown]
    labels = list(shown)
    if any_diverged:
        handles.append(plt.Line2D([], [], marker="^", ls="", color="0.5", mec="black"))
        labels.append("diverged (count below)")
    ax.legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return fig


def label_minor_log_ticks(axis):
    """Label 2x and 5x ticks too when a log axis spans fewer than ~3 decades."""
    axis.set_minor_formatter(ticker.LogFormatterSciNotation(labelOnlyBase=False,
                                                            minor_thresholds=(3, 1.2)))


def draw_cell(ax, rng, x, model, vals):
    """One box (quartiles, whiskers 1.5 IQR, no fliers: every seed is a point anyway)."""
    finite = [v for v in vals if np.isfinite(v)]
    if not finite:
        return
    box = ax.boxplot([finite], positions=[x], widths=0.75, patch_artist=True, showfliers=False,
                     medianprops={"color": "black"})
    box["boxes"][0].set(facecolor=colour(model), alpha=0.45, edgecolor=colour(model))
    jitter = rng.uniform(-0.22, 0.22, len(finite))
    ax.scatter(x + jitter, finite, s=12, color=colour(model), edgecolor="black", lw=0.4, zorder=3)


# ------------------------------------------------------------------------- trajectories (7/9)
def canonical_value(runs, i, key, default):
    for part in runs["canonical"][i].split(";"):
        k, _, v = part.partition("=")
        if k == key:
            return v
    return default


def baseline(runs, rows):
    """Rows at the most common size and regularizer 'none' (Study I/II/III share this cell)."""
    size = Counter(runs["size"][i] for i in rows).most_common(1)[0][0]
    sel = [i for i in rows if runs["size"][i] == size and runs["regularizer"][i] == "none"]
    return sel or rows


def median_seed_row(runs, cell):
    """The run with the median MSE of its cell (lower median for even n; +inf sorts last)."""
    done = [i for i in cell if runs["status"][i] in (DONE, DIVERGED)]
    if not done:
        return None
    done.sort(key=lambda i: (np.nan_to_num(runs["mse"][i], nan=np.inf), runs["seed"][i]))
    return done[(len(done) - 1) // 2]


def trajectory_cell(runs, system):
    """The baseline rows at the paper's N_train for this system (nearest available one)."""
    rows = baseline(runs, [i for i in runs["rows"] if runs["system"][i] == system])
    available = sorted({int(runs["n_train"][i]) for i in rows})
    target = TRAJECTORY_N_TRAIN.get(system, available[0])
    n_train = min(available, key=lambda n: (abs(n - target), n))
    return [i for i in rows if runs["n_train"][i] == n_train], n_train, target


def chosen_models(runs, cell):
    """NODE-RK2 and the PHNN label with the lowest median MSE over the cell's finished runs."""
    medians = {}
    for m in ordered_models(runs["model"][i] for i in cell):
        v = [runs["mse"][i] for i in cell if runs["model"][i] == m and runs["status"][i] in
             (DONE, DIVERGED)]
        if v:
            medians[m] = float(np.median(np.nan_to_num(v, nan=np.inf)))
    phnn = [m for m in medians if m.startswith("PHNN")]
    picks = [m for m in medians if m.startswith("NODE")][:1]
    if phnn:
        picks.append(min(phnn, key=lambda m: medians[m]))
    return picks, medians


def trajectories(runs, name, out):
    """Paper Figs. 7/9 for each system; see the module docstring."""
    written = []
    for system in ordered_systems(runs, runs["rows"]):
        cell, n_train, target = trajectory_cell(runs, system)
        picks, medians = chosen_models(runs, cell)
        if not picks:
            print(f"  skipped trajectories_{system}.png: no finished run at N_train = {n_train}")
            continue
        states = runs["states"][system]
        fig, axes = trajectory_axes(states)
        for r, energy in enumerate(("05", "075")):
            draw_reference(runs, axes[r], median_seed_row(runs, cell), energy)
            for m in picks:
                i = median_seed_row(runs, [j for j in cell if runs["model"][j] == m])
                draw_prediction(runs, axes[r], i, energy, m, medians[m])
            axes[r, 0].set_ylabel(f"{figure_label(states, energy)}\n{state_label(states, 0)}")
        figure_legend(axes)
        seeds = seeds_per_cell(runs, cell)
        note = "" if n_train == target else f" (paper: {target}, not in this file)"
        suptitle(fig, f"{name}: {system}, {study_names(runs, cell)}, {runs['size'][cell[0]]}, "
                 f"no regularizer, N_train = {n_train}{note}; n = {seeds} seeds per model",
                 f"reference vs NODE and the best PHNN (lowest median MSE), each at its "
                 f"median-MSE seed (named in the legend); {status_note(runs, cell)}")
        path = save(fig, out, f"trajectories_{system}.png")
        written.append(path)
    return written


def size_trajectory_rows(runs, system):
    """Paper Fig. 9's runs: {size: rows} of SIZE_TRAJECTORY_MODEL[system], no regularizer, at the
    N_train nearest 25 that has more than one size; ({}, None) when no size varies."""
    model = SIZE_TRAJECTORY_MODEL.get(system)
    rows = [i for i in runs["rows"] if runs["system"][i] == system and runs["model"][i] == model
            and runs["regularizer"][i] == "none"]
    by_n = {}
    for i in rows:
        by_n.setdefault(int(runs["n_train"][i]), set()).add(runs["size"][i])
    candidates = [n for n, sizes in by_n.items() if len(sizes) > 1]
    if not candidates:
        return {}, None
    n_train = min(candidates, key=lambda n: (abs(n - 25), n))
    rows = [i for i in rows if runs["n_train"][i] == n_train]
    sizes = column_order(runs, "size", rows, {}, "")
    return {z: [i for i in rows if runs["size"][i] == z] for z in sizes}, n_train


def size_trajectories(runs, name, out):
    """Paper Fig. 9: one model's median-MSE seed at each size, from H(x0) = 0.5 and 0.75 J."""
    written = []
    for system in ordered_systems(runs, runs["rows"]):
        groups, n_train = size_trajectory_rows(runs, system)
        picks = {z: median_seed_row(runs, rows) for z, rows in groups.items()}
        picks = {z: i for z, i in picks.items() if i is not None}
        if len(picks) < 2:
            continue
        model = SIZE_TRAJECTORY_MODEL[system]
        states = runs["states"][system]
        fig, axes = trajectory_axes(states)
        for r, energy in enumerate(("05", "075")):
            draw_reference(runs, axes[r], next(iter(picks.values())), energy)
            for size, i in picks.items():
                cell = [runs["mse"][j] for j in groups[size]
                        if runs["status"][j] in (DONE, DIVERGED)]
                median = float(np.median(np.nan_to_num(cell, nan=np.inf)))
                draw_prediction(runs, axes[r], i, energy, model, median,
                                label_prefix=f"{size}: ", linestyle=SIZE_STYLES.get(size, "--"))
            axes[r, 0].set_ylabel(f"{figure_label(states, energy)}\n{state_label(states, 0)}")
        figure_legend(axes)
        rows = [i for r in groups.values() for i in r]
        suptitle(fig, f"{name}: {system}, {model} at each model size, no regularizer, "
                 f"N_train = {n_train} (paper Fig. 9); n = {seeds_per_cell(runs, rows)} seeds per size",
                 f"reference vs the model at its median-MSE seed per size (named in the legend); "
                 f"{status_note(runs, rows)}")
        written.append(save(fig, out, f"trajectories_sizes_{system}.png"))
    return written


def trajectory(runs, i, key, column):
    """Figure trajectory `key` of row i: [points, n_x] (its valid points and states)."""
    length = int(runs["length"][i][column])
    return runs[key][i][:length, :int(runs["n_x"][i])]


def trajectory_axes(states):
    """Two rows (the figure trajectories); a column per state against t, then one per phase
    pair: q(t), p(t), (q, p) for the built-in systems."""
    columns = len(states["names"]) + len(states["pairs"]) + (1 if states.get("inputs") else 0)
    return plt.subplots(2, columns, figsize=(max(13, 3.3 * columns), 7), squeeze=False)


def plot_states(runs, axes, i, data, t, style):
    """Each state of `data` against t, then each phase pair of row i's system."""
    states = runs["states"][runs["system"][i]]
    n = len(states["names"])
    for k in range(n):
        axes[k].plot(t, data[:, k], **style)
    for c, (a, b) in enumerate(states["pairs"]):
        axes[n + c].plot(data[:, a], data[:, b], **style)


def figure_legend(axes):
    """The trajectories' legend (first axis: recording or reference, the rollouts; then the
    inputs' lines of an input column) right of the first row's last axis."""
    handles, labels = axes[0, 0].get_legend_handles_labels()
    if axes.shape[1] > 1:
        more = axes[0, -1].get_legend_handles_labels()
        handles += [h for h, lab in zip(*more) if lab not in labels]
        labels += [lab for lab in more[1] if lab not in labels]
    axes[0, -1].legend(handles, labels, fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))


def draw_reference(runs, axes, i, energy):
    """Reference states against t and phase portraits of row i (energy '05' or '075'), axis
    labels."""
    ref = trajectory(runs, i, "reference_" + energy, 2 if energy == "05" else 3)
    t = np.arange(len(ref)) / float(canonical_value(runs, i, "sample_rate", 100))
    states = runs["states"][runs["system"][i]]
    style = {"color": "black", "lw": 2.2,
             "label": "recording" if states.get("recorded") else "reference (data generator)"}
    plot_states(runs, axes, i, ref, t, style)
    n = len(states["names"])
    if states.get("inputs"):  # the input held over each sample, in the last column
        u = states["inputs"]["values"][0 if energy == "05" else 1][:len(t)]
        for k, input_name in enumerate(states["inputs"]["names"]):
            axes[-1].step(t[:len(u)], u[:, k], where="post", lw=1.2, label=f"input {input_name}")
        axes[-1].set_xlabel("t [s]")
        axes[-1].set_ylabel("input u(t)")
        axes[-1].grid(alpha=0.3)
    labels = [("t [s]", None if k == 0 else state_label(states, k)) for k in range(n)]
    labels += [(state_label(states, a), state_label(states, b)) for a, b in states["pairs"]]
    for ax, (xl, yl) in zip(axes, labels):
        ax.set_xlabel(xl)
        if yl:
            ax.set_ylabel(yl)
        ax.grid(alpha=0.3)
    # Phase portraits: the reference's extent (+15 %), equal aspect; a prediction that leaves it
    # is clipped there rather than shrinking the reference to a dot.
    for ax, (a, b) in zip(axes[n:], states["pairs"]):
        finite = ref[np.all(np.isfinite(ref[:, [a, b]]), axis=1)]
        if len(finite) == 0:
            continue
        lo, hi = finite[:, [a, b]].min(axis=0), finite[:, [a, b]].max(axis=0)
        pad = 0.15 * np.maximum(hi - lo, 1e-12)
        ax.set_xlim(lo[0] - pad[0], hi[0] + pad[0])
        ax.set_ylim(lo[1] - pad[1], hi[1] + pad[1])
        ax.set_autoscale_on(False)
        ax.set_aspect("equal", adjustable="box")


def draw_prediction(runs, axes, i, energy, model, median, label_prefix="", linestyle="--"):
    """Model rollout of row i; a rollout that turns non-finite is drawn up to there and noted."""
    pred = trajectory(runs, i, "prediction_" + energy, 0 if energy == "05" else 1)
    t = np.arange(len(pred)) / float(canonical_value(runs, i, "sample_rate", 100))
    finite = np.all(np.isfinite(pred), axis=1)
    label = (f"{label_prefix}{model}, seed {int(runs['seed'][i])} (MSE {runs['mse'][i]:.2g}; "
             f"cell median {median:.2g})")
    style = {"color": colour(model), "lw": 1.3, "ls": linestyle, "label": label}
    plot_states(runs, axes, i, pred[finite], t[finite], style)
    if not finite.all():
        axes[0].text(0.02, 0.02, f"{model}: rollout non-finite after t = {t[~finite][0]:.2f} s",
                     transform=axes[0].transAxes, fontsize=7, color=colour(model))


# ------------------------------------------------------------------ learned energy (phnn eval)
def phnn_binary():
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    return os.environ.get("PHNN", os.path.join(here, "build", "phnn"))


def eval_energies(path, run_id, out):
    """`phnn eval` of one run into a CSV; its rows as a numpy record array, or None."""
    csv = os.path.join(out, f".energy_{run_id}.csv")
    done = subprocess.run([phnn_binary(), "eval", path, "--run", run_id, "--out", csv],
                          capture_output=True, text=True)
    if done.returncode != 0 or not os.path.exists(csv):
        print(f"  phnn eval {run_id} failed ({done.returncode}): {done.stderr.strip()}")
        return None
    data = np.genfromtxt(csv, delimiter=",", names=True)
    os.remove(csv)
    return data


def energies(runs, path, name, out):
    """energy_<sys>.png; see the module docstring."""
    if not runs["has_weights"]:
        print("  skipped energy_*.png: this file stores no weights (written before they were)")
        return []
    written = []
    for system in ordered_systems(runs, runs["rows"]):
        cell, n_train, _ = trajectory_cell(runs, system)
        picks = [m for m in chosen_models(runs, cell)[0] if m.startswith("PHNN")]
        if not picks:
            continue
        i = median_seed_row(runs, [j for j in cell if runs["model"][j] == picks[0]])
        data = eval_energies(path, runs["id"][i], out)
        if data is None:
            continue
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), sharey=False)
        states = runs["states"][system]
        for ax, energy in zip(axes, ("05", "075")):
            # The CSV's first column: h0 (figure energies) or the inference trajectory.
            k = 0 if energy == "05" else 1
            rows = (data[np.isclose(data["h0"], states["energies"][min(k, len(states["energies"]) - 1)])]
                    if states["energies"] else data[data["trajectory"] == k])
            c = colour(picks[0])
            reference = "recording" if states.get("recorded") else "reference"
            lines = [("H_true_ref", {"color": "black", "lw": 2.2}, f"H along the {reference}"),
                     ("H_model_ref", {"color": "grey", "lw": 1.3, "ls": ":"},
                      rf"$H_\theta$ along the {reference}"),
                     ("H_true", {"color": c, "lw": 1.3, "ls": "--"}, f"H along the {picks[0]} rollout"),
                     ("H_model", {"color": c, "lw": 1.3, "ls": ":"},
                      rf"$H_\theta$ along the {picks[0]} rollout")]
            for column, style, label in lines:  # a structure-only system has no true H: not drawn
                if np.isfinite(rows[column]).any():
                    ax.plot(rows["t"], rows[column], label=label, **style)
            ax.set_title(figure_label(states, energy))
            ax.set_xlabel("t [s]")
            ax.set_ylabel(r"energy $H$, $H_\theta$ [J]")
            ax.grid(alpha=0.3)
        axes[1].legend(fontsize=7)
        suptitle(fig, f"{name}: {system}, N_train = {n_train}: learned vs true energy",
                 f"{picks[0]}, seed {int(runs['seed'][i])} (median-MSE seed, MSE "
                 f"{runs['mse'][i]:.2g}), reloaded from its stored weights by phnn eval")
        p = save(fig, out, f"energy_{system}.png")
        written.append(p)
    return written


# ------------------------------------------------------------- Jacobian (10/12) and loss traces
def trace_runs(runs, system):
    """Small-size runs of a system at the N_train the regularized runs use: {regularizer: rows}."""
    rows = [i for i in runs["rows"] if runs["system"][i] == system]
    size = Counter(runs["size"][i] for i in rows).most_common(1)[0][0]
    rows = [i for i in rows if runs["size"][i] == size]
    regularized = [i for i in rows if runs["regularizer"][i] != "none"] or rows
    n_train = Counter(int(runs["n_train"][i]) for i in regularized).most_common(1)[0][0]
    rows = [i for i in rows if runs["n_train"][i] == n_train]
    regs = column_order(runs, "regularizer", rows, {}, "")
    return {r: [i for i in rows if runs["regularizer"][i] == r] for r in regs}, size, n_train


def trace_stats(runs, rows, column):
    """steps, median, 25 % and 75 % over the rows' traces (NaN-padded; diverged points skipped)."""
    length = max(int(runs["trace_length"][i]) for i in rows)
    values = np.full((len(rows), length), np.nan)
    steps = None
    for k, i in enumerate(rows):
        n = int(runs["trace_length"][i])
        values[k, :n] = runs["trace"][i][:n, column]
        if n == length:
            steps = runs["trace"][i][:n, 0]
    values[~np.isfinite(values)] = np.nan
    with warnings.catch_warnings():  # all-NaN columns (every seed diverged there) give NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        q = np.nanpercentile(values, [25, 50, 75], axis=0)
    return steps, q[1], q[0], q[2]


def trace_figure(runs, name, system, out, panels, stem, what):
    """One row per regularizer, one column per (trace column, axis label, log scale allowed);
    a panel is drawn on a log axis only when its data span more than a factor of 30."""
    groups, size, n_train = trace_runs(runs, system)
    groups = {r: [i for i in drawable(runs, rows) if runs["trace_length"][i] > 0]
              for r, rows in groups.items()}
    groups = {r: rows for r, rows in groups.items() if rows}
    if not groups:
        print(f"  skipped {stem}_{system}.png: no finished {size} run at N_train = {n_train}")
        return None
    fig, axes = plt.subplots(len(groups), len(panels), squeeze=False,
                             figsize=(4.3 * len(panels) + 1.8, 2.9 * len(groups) + 0.9))
    for row, (reg, rows) in enumerate(groups.items()):
        for m in ordered_models(runs["model"][i] for i in rows):
            sel = [i for i in rows if runs["model"][i] == m and runs["trace_length"][i] > 0]
            for col, (key, ylabel, log) in enumerate(panels):
                if not sel:
                    continue
                steps, med, lo, hi = trace_stats(runs, sel, TRACE_COLUMNS[key])
                ax = axes[row, col]
                ax.plot(steps, med, color=colour(m), lw=1.3, label=f"{m} (n = {len(sel)})")
                ax.fill_between(steps, lo, hi, color=colour(m), alpha=0.18, lw=0)
        for col, (key, ylabel, log) in enumerate(panels):
            ax = axes[row, col]
            lo, hi = ax.dataLim.y0, ax.dataLim.y1
            ax.set_yscale("log" if log and lo > 0 and hi / lo > 30 else "linear")
            if ax.get_yscale() == "log":
                label_minor_log_ticks(ax.yaxis)
            ax.set_ylabel(ylabel, fontsize=8)
            ax.set_title(f"regularizer: {reg}", fontsize=8)
            ax.grid(alpha=0.3)
            if row == len(groups) - 1:
                ax.set_xlabel("Adam step")
        axes[row, -1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    all_rows = [i for rows in trace_runs(runs, system)[0].values() for i in rows]
    suptitle(fig, f"{name}: {system}, {study_names(runs, all_rows)}, {size} models, "
             f"N_train = {n_train}, one row per regularizer: {what}",
             f"median over seeds (n per model in legend), band = interquartile range; "
             f"{status_note(runs, all_rows)}")
    path = save(fig, out, f"{stem}_{system}.png")
    return path


def jacobian_traces(runs, name, out):
    """Paper Figs. 10/12: kappa, sigma_max and rho of the learned field's Jacobian."""
    panels = [("kappa", r"condition number $\kappa$ [1]", True),
              ("sigma_max", r"spectral norm $\sigma_{\max}$ [1/s]", True),
              ("rho", r"stiffness ratio $\rho$ [1]", False)]
    return [p for s in ordered_systems(runs, runs["rows"]) if (p := trace_figure(
        runs, name, s, out, panels, "jacobian", "Jacobian of the learned field at validation points"))]


def loss_curves(runs, name, out):
    """Training and validation loss L_d per validation point (the regularizer term included)."""
    panels = [("train", r"training loss $L_d$", True), ("validation", r"validation loss $L_d$", True)]
    return [p for s in ordered_systems(runs, runs["rows"]) if (p := trace_figure(
        runs, name, s, out, panels, "loss",
        "training / validation loss, L_d = mean |x_{n+1} − x̂_{n+1}| / h (m/s and kg m/s² mixed; "
        "+ the regularizer's term where one is used)"))]


# ------------------------------------------------------------------------------ time vs error
def time_vs_error(runs, name, out):
    """Wall time per run against inference MSE, per system; diverged runs at the top edge."""
    written = []
    for system in ordered_systems(runs, runs["rows"]):
        rows = [i for i in runs["rows"] if runs["system"][i] == system]
        sel = drawable(runs, rows)
        if not sel:
            continue
        fig, ax = plt.subplots(figsize=(8, 4.8))
        for m in ordered_models(runs["model"][i] for i in sel):
            mine = [i for i in sel if runs["model"][i] == m]
            t = np.array([runs["wall_time_s"][i] for i in mine])
            e = np.array([runs["mse"][i] for i in mine])
            ok, div = np.isfinite(e), np.isinf(e)
            ax.scatter(t[ok], e[ok], s=10, color=colour(m), alpha=0.6, lw=0)
            ax.scatter(t[div], np.full(div.sum(), 0.97), marker="^", color=colour(m),
                       edgecolor="black", transform=ax.get_xaxis_transform(), clip_on=False)
            ax.scatter([np.median(t)], [np.median(e[~np.isnan(e)]) if ok.any() else np.nan], s=90,
                       color=colour(m), edgecolor="black", marker="D",
                       label=f"{m}: {len(mine)} runs, {div.sum()} diverged")
        ax.set_xscale("log")  # seconds at 1, 2, 5 x 10^k, in plain numbers
        ax.xaxis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(ticker.NullFormatter())
        if any(np.isfinite(runs["mse"][i]) for i in sel):
            ax.set_yscale("log")
            label_minor_log_ticks(ax.yaxis)
        ax.set_xlabel("wall time per run [s] (stack time / seeds trained together)")
        ax.set_ylabel(r"inference MSE $\mathcal{E}$ [m², (kg m/s)² mixed]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
        suptitle(fig, f"{name}: {system}, all studies: wall time vs inference MSE, every run a "
                 f"point, diamonds = a model's medians over all its runs",
                 f"n = {seeds_per_cell(runs, rows)} seeds per cell; {status_note(runs, rows)}")
        path = save(fig, out, f"time_vs_error_{system}.png")
        written.append(path)
    return written


def main():
    parser = argparse.ArgumentParser(
        description="The figures of a results file (the module's docstring lists them).")
    parser.add_argument("results", help="results file written by `phnn sweep` or `phnn train`")
    parser.add_argument("outdir", help="directory for the figures (created)")
    parser.add_argument("--round", type=int, default=None, metavar="K",
                        help="adaptive sweeps: the runs of rounds 0..K only (0: every cell's "
                        "first seeds)")
    args = parser.parse_args()
    if args.round is not None and args.round < 0:
        parser.error("--round K needs K >= 0")
    path, out = args.results, args.outdir
    if not os.path.exists(path):
        sys.exit(f"{path}: no such file; run `phnn sweep` first")
    os.makedirs(out, exist_ok=True)
    runs, name, sweep = load(path, args.round)
    name = name or os.path.basename(path)
    written = []
    for make in (mse_boxplots,):
        written += make(runs, name, sweep, out)
    for make in (trajectories, size_trajectories, jacobian_traces, loss_curves, time_vs_error):
        written += make(runs, name, out)
    written += energies(runs, path, name, out)
    import plot_comparisons  # the P(improvement) matrices and the performance profiles
    written += plot_comparisons.profile_figures(sys.modules[__name__], runs, name, out)
    written += plot_comparisons.improvement_figures(sys.modules[__name__], path, name, out,
                                                    args.round)
    c = Counter(int(s) for s in runs["status"])
    print(f"{len(written)} figures written to {out}/ ({c[DONE]} done, {c[DIVERGED]} diverged, "
          f"{c[FAILED]} failed, {c[PENDING]} pending of {len(runs['status'])} runs)")
    for p in written:
        print("  " + os.path.basename(p))


if __name__ == "__main__":
    main()
