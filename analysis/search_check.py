#!/usr/bin/env python3
"""Checks a [search] sweep against its full grid (the same sweep with eta = 1, whose runs are a
superset of the search's, with the same ids): which configuration each picks at the last rung, by
the search's criterion (median best validation loss over seeds) and by the inference MSE, where the
search's pick ranks in the full grid, whether its MSE median lies in the 95 % bootstrap interval of
the full grid's best, and the training core-seconds of each (per configuration and seed, the
wall time of the last rung it reached: a rung that goes on from the one before counts the time
before it too).

    /usr/bin/python3 analysis/search_check.py results/search-pendulum.h5 results/search-pendulum-full.h5

Prints Markdown. A configuration is every setting column that varies across the full grid's runs,
other than the seed and the step budget.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from analysis.results import load  # noqa: E402

NOT_SETTINGS = {"run_id", "studies", "seed", "steps", "inference"}


def configuration_columns(runs):
    """The setting columns (before `status`) that vary, the model label first."""
    settings = list(runs.columns[: list(runs.columns).index("status")])
    # A column set for some models only (the DG Newton settings) varies by
    # NaN alone: not a setting of its own.
    varying = [c for c in settings if c not in NOT_SETTINGS and runs[c].nunique() > 1]
    return ["model_label"] + [c for c in varying if c not in ("model_label", "model", "integrator")]


def label(key, columns):
    return " ".join([str(key[0])] + [f"{c}={v:g}" if isinstance(v, float) else f"{c}={v}"
                                     for c, v in zip(columns[1:], key[1:])])


def median_interval(values, rng, draws=10000):
    values = np.asarray(values, dtype=float)
    medians = np.median(rng.choice(values, size=(draws, len(values))), axis=1)
    return np.quantile(medians, 0.025), np.quantile(medians, 0.975)


def last_rung(runs, columns):
    """Per configuration at the largest budget: criterion and MSE medians, the MSE values."""
    top = runs[(runs.status.isin(["done", "diverged"])) & (runs.steps == runs.steps.max())]
    out = []
    for key, g in top.groupby(columns, sort=False, dropna=False):
        crit = np.where(g.status == "diverged", np.inf, g.best_validation_loss)
        mse = np.where(g.status == "diverged", np.inf, g.mse)
        out.append((label(key, columns), float(np.median(crit)), float(np.median(mse)), mse))
    return sorted(out, key=lambda e: e[1])


def core_seconds(runs, columns):
    finished = runs[runs.status.isin(["done", "diverged", "failed"])]
    last = finished.sort_values("steps").groupby(columns + ["seed"], sort=False, dropna=False).tail(1)
    return float(last.wall_time_s.sum())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("search")
    ap.add_argument("full")
    args = ap.parse_args()
    search, full = load(args.search), load(args.full)
    columns = configuration_columns(full)
    s_rung, f_rung = last_rung(search, columns), last_rung(full, columns)
    pick = s_rung[0]
    by_crit = [e[0] for e in f_rung]
    by_mse = [e[0] for e in sorted(f_rung, key=lambda e: e[2])]
    best_mse = sorted(f_rung, key=lambda e: e[2])[0]
    low, high = median_interval(best_mse[3], np.random.default_rng(0))
    s_cost, f_cost = core_seconds(search, columns), core_seconds(full, columns)
    print("| | search | full grid |\n|---|---|---|")
    print(f"| configurations at the last rung | {len(s_rung)} | {len(f_rung)} |")
    print(f"| best by median best validation loss | {pick[0]} | {f_rung[0][0]} |")
    print(f"| best by median inference MSE | | {best_mse[0]} ({best_mse[2]:.3e}, "
          f"95 % interval {low:.3e}–{high:.3e}) |")
    print(f"| the search's pick in the full grid | rank {by_crit.index(pick[0]) + 1} of {len(f_rung)} "
          f"by validation, {by_mse.index(pick[0]) + 1} by MSE; MSE {pick[2]:.3e}, "
          f"{'inside' if low <= pick[2] <= high else 'outside'} the best's interval | |")
    print(f"| training core-seconds (sum over configurations and seeds) | {s_cost:.0f} | "
          f"{f_cost:.0f} ({100 * s_cost / f_cost:.0f} % for the search) |")


if __name__ == "__main__":
    main()
