#!/usr/bin/env python3
"""Two figures of analysis/plot_results.py that read comparisons and seeds rather than cells:

  pimprove_<st>_<sys>.png     one panel per column of study <st>: the matrix P(row model < column
                              model) of the inference MSE, from `phnn reduce --comparisons`
                              (p_a_less: paired by seed where the runs share weights, batches and
                              data, the share of seeds with A < B, a tie counting 1/2; otherwise
                              the Mann-Whitney probability), annotated, diverging colormap centred
                              at 1/2 (blue: the row model has the smaller error).  P(B < A) = 1 -
                              P(A < B).  Needs the phnn binary ($PHNN, else build/phnn); without
                              it, or for a file it cannot read, the figure is skipped and said so.
  profile_<sys>.png           performance profiles: per model, the share of its finished runs on
                              the system (every configuration of the file, each run once; a
                              diverged run, MSE +inf, is never <= tau) with MSE <= tau over a log
                              grid of tau, and a 95 % bootstrap band over seeds (B = 1000
                              resamples of the file's seeds, one draw for every run, numpy seed
                              0).  The values are written next to it as profile_<sys>.csv
                              (model, tau, share, low, high).

Both as PNG (300 dpi), PDF and caption (plot_results.save).  The functions take plot_results as
`pr` (its save, suptitle, colours and orders), so either module can be the script.
"""
import csv
import subprocess

import numpy as np

PROFILE_POINTS = 40       # taus per profile, log-spaced
PROFILE_RESAMPLES = 1000  # bootstrap resamples of the seeds for the band


# ------------------------------------------------------------------------- P(improvement)
def improvement_matrices(comparison_rows):
    """{(study, system, column): {(row model, column model): P(row < column)}} from the reducer's
    comparisons of two models in one column (both orders)."""
    out = {}
    for r in comparison_rows:
        sa, sys_a, ma, ca = r["a"].split("/")
        sb, sys_b, mb, cb = r["b"].split("/")
        if (sa, sys_a, ca) != (sb, sys_b, cb) or r["p_a_less"] == "":
            continue  # a comparison of two columns of a row
        p = float(r["p_a_less"])
        cell = out.setdefault((sa, sys_a, ca), {})
        cell[(ma, mb)], cell[(mb, ma)] = p, 1.0 - p
    return out


def improvement_figures(pr, path, name, out, round_k=None):
    """pimprove_<st>_<sys>.png per (study, system) with a panel per column; of an adaptive sweep
    the runs of rounds 0..round_k when given (reduce --round), as the other figures."""
    import matplotlib.pyplot as plt
    from phnn_tool import run_csv
    extra = ("--round", str(round_k)) if round_k is not None else ()
    try:
        rows = run_csv("reduce", path, "--comparisons", *extra)
    except (OSError, subprocess.CalledProcessError) as e:
        print(f"  P(improvement) matrices skipped: phnn reduce --comparisons failed ({e})")
        return []
    matrices = improvement_matrices(rows)
    tables = {}
    for (study, system, column) in matrices:
        tables.setdefault((study, system), []).append(column)
    written = []
    for (study, system), columns in tables.items():
        fig, axes = plt.subplots(1, len(columns), figsize=(4.2 * len(columns), 4.0),
                                 squeeze=False)
        for ax, column in zip(axes[0], columns):
            image = draw_matrix(pr, ax, matrices[(study, system, column)])
            ax.set_title(f"column {column}", fontsize=9)
        fig.colorbar(image, ax=axes[0][-1], shrink=0.8, label="P(row model < column model)")
        pr.suptitle(fig, f"{name}: {system}, study {study}: P(row model has the smaller "
                    "inference MSE than the column model), per column",
                    "From `phnn reduce --comparisons` (p_a_less): paired by seed where the runs "
                    "share weights, batches and data (share of seeds, a tie counting 1/2), else "
                    "the Mann-Whitney probability; P(B < A) = 1 - P(A < B); blue = the row model "
                    "does better.")
        written.append(pr.save(fig, out, f"pimprove_{study}_{system}.png"))
    return written


def draw_matrix(pr, ax, probabilities):
    models = pr.ordered_models({m for pair in probabilities for m in pair})
    grid = np.full((len(models), len(models)), np.nan)
    for (a, b), p in probabilities.items():
        grid[models.index(a), models.index(b)] = p
    image = ax.imshow(grid, cmap="RdBu", vmin=0.0, vmax=1.0)  # blue: the row model does better
    for i in range(len(models)):
        for j in range(len(models)):
            if not np.isnan(grid[i, j]):
                ax.text(j, i, f"{grid[i, j]:.2f}", ha="center", va="center", fontsize=7,
                        color="white" if abs(grid[i, j] - 0.5) > 0.3 else "black")
    ax.set_xticks(range(len(models)), models, rotation=45, ha="right", fontsize=7)
    ax.set_yticks(range(len(models)), models, fontsize=7)
    return image


# ------------------------------------------------------------------------ performance profiles
def profile_taus(values):
    """PROFILE_POINTS log-spaced taus over the finite positive MSEs (empty if there are none)."""
    finite = values[np.isfinite(values) & (values > 0)]
    if finite.size == 0:
        return np.array([])
    lo, hi = finite.min(), finite.max()
    if lo == hi:
        lo, hi = lo / 2, hi * 2
    return np.geomspace(lo, hi, PROFILE_POINTS)


def profile(mse, seeds, taus, resamples=PROFILE_RESAMPLES, rng_seed=0):
    """(share, low, high) per tau: share = #{runs with MSE <= tau} / #runs; the band = 2.5 % and
    97.5 % points over `resamples` draws of the seed set with replacement (one draw for every run:
    a run enters as often as its seed was drawn)."""
    mse, seeds = np.asarray(mse, dtype=float), np.asarray(seeds)
    below = mse[None, :] <= taus[:, None]                      # [tau, run]
    share = below.mean(axis=1)
    pool = np.unique(seeds)
    rng = np.random.default_rng(rng_seed)
    index = {s: k for k, s in enumerate(pool)}
    column = np.array([index[s] for s in seeds])
    draws = np.empty((resamples, taus.size))
    for b in range(resamples):
        counts = np.bincount(rng.integers(0, pool.size, pool.size), minlength=pool.size)
        weight = counts[column].astype(float)
        draws[b] = below @ weight / weight.sum() if weight.sum() > 0 else np.nan
    low, high = np.nanpercentile(draws, [2.5, 97.5], axis=0)
    return share, low, high


def profile_figures(pr, runs, name, out):
    """profile_<sys>.png and profile_<sys>.csv per system."""
    import matplotlib.pyplot as plt
    written = []
    for system in pr.ordered_systems(runs, runs["rows"]):
        sel = pr.drawable(runs, [i for i in runs["rows"] if runs["system"][i] == system])
        sel = [i for i in sel if not np.isnan(runs["mse"][i])]
        taus = profile_taus(np.array([runs["mse"][i] for i in sel]))
        if taus.size == 0:
            continue
        fig, ax = plt.subplots(figsize=(7.5, 4.6))
        lines = []
        for m in pr.ordered_models(runs["model"][i] for i in sel):
            mine = [i for i in sel if runs["model"][i] == m]
            share, low, high = profile([runs["mse"][i] for i in mine],
                                       [int(runs["seed"][i]) for i in mine], taus)
            ax.plot(taus, share, color=pr.colour(m), label=f"{m} ({len(mine)} runs)")
            ax.fill_between(taus, low, high, color=pr.colour(m), alpha=0.2, lw=0)
            lines += [(m, t, s, lo, hi) for t, s, lo, hi in zip(taus, share, low, high)]
        ax.set_xscale("log")
        ax.set_ylim(-0.02, 1.02)
        ax.set_xlabel(r"$\tau$ (inference MSE)")
        ax.set_ylabel(r"share of runs with MSE $\leq \tau$")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
        pr.suptitle(fig, f"{name}: {system}: performance profiles (share of a model's runs with "
                    r"inference MSE <= tau)",
                    "Every finished run of the model on the system (all configurations, each run "
                    "once; diverged runs count, never below tau); band: 95 % bootstrap over the "
                    f"seeds ({PROFILE_RESAMPLES} resamples of the seed set, one draw for every "
                    "run).")
        written.append(pr.save(fig, out, f"profile_{system}.png"))
        with open(f"{out}/profile_{system}.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(("model", "tau", "share", "low", "high"))
            w.writerows((m, repr(float(t)), repr(float(s)), repr(float(lo)), repr(float(hi)))
                        for m, t, s, lo, hi in lines)
    return written
