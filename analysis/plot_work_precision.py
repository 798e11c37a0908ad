#!/usr/bin/env python3
"""Integrator work-precision diagram from bench/work_precision's CSV.

    build/work_precision > wp.csv
    python3 analysis/plot_work_precision.py wp.csv OUTDIR

Writes OUTDIR/work_precision.png (one panel per system: RMS error against
wall time per trajectory, log-log, one line per method, diverged points
left out and counted in the legend) and prints a Markdown table of the
observed orders: the least-squares slope of log(error) against log(h) over
the finest pair of step sizes, log2(e(h) / e(h/2)) at h = 1/1600 s, with the
whole sequence of pairwise orders beside it (coarse to fine; errors below
1e-11, i.e. near round-off, left out) so the pre-asymptotic range of the
explicit methods on the stiff phases is visible.
"""
import argparse
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

METHODS = ["rk2", "dg", "rk4", "dg4"]
COLOURS = {"rk2": "#1f77b4", "dg": "#d62728", "rk4": "#2ca02c", "dg4": "#9467bd"}
LABELS = {"rk2": "RK2 (explicit midpoint)", "dg": "DG (Gonzalez)",
          "rk4": "RK4", "dg4": "DG4"}


def read(path):
    rows = defaultdict(list)
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            rows[(r["system"], r["method"])].append({
                "h": float(r["h"]), "error": float(r["rms_error"]),
                "seconds": float(r["seconds_per_trajectory"]),
                "balance": float(r["worst_balance_residual"]),
                "failures": int(r["newton_failures"]),
                "diverged": int(r["diverged_trajectories"])})
    return rows


def pairwise_orders(points):
    """log2(e(h) / e(h/2)) for successive h (finite errors above 1e-11)."""
    pts = sorted((p for p in points if p["diverged"] == 0 and p["error"] >= 1e-11),
                 key=lambda p: -p["h"])
    return [math.log(a["error"] / b["error"]) / math.log(a["h"] / b["h"])
            for a, b in zip(pts, pts[1:])]


def main():
    parser = argparse.ArgumentParser(
        description="Work-precision figure and observed orders from build/work_precision's CSV.")
    parser.add_argument("csv", help="output of build/work_precision")
    parser.add_argument("outdir", help="directory for the figure (created)")
    args = parser.parse_args()
    sys.argv[1:] = [args.csv, args.outdir]
    rows = read(sys.argv[1])
    systems = []
    for system, _ in rows:
        if system not in systems:
            systems.append(system)
    os.makedirs(sys.argv[2], exist_ok=True)
    fig, axes = plt.subplots(1, len(systems), figsize=(5 * len(systems), 4.2))
    print("| system | method | observed order | orders from h to h/2, coarse to fine | worst balance residual |"
          " Newton failures | diverged (of all h) |")
    print("|---|---|---|---|---|---|---|")
    for ax, system in zip(axes, systems):
        for method in METHODS:
            points = rows.get((system, method), [])
            if not points:
                continue
            orders = pairwise_orders(points)
            order = orders[-1] if orders else float("nan")
            ok = [p for p in points if p["diverged"] == 0]
            lost = len(points) - len(ok)
            label = f"{LABELS[method]} (order {order:.2f})"
            if lost:
                label += f", {lost} h diverged"
            ax.loglog([p["error"] for p in ok], [p["seconds"] for p in ok],
                      "o-", color=COLOURS[method], label=label, markersize=4)
            trend = " ".join(f"{o:.2f}" for o in orders)
            print(f"| {system} | {method} | {order:.2f} | {trend} | "
                  f"{max(p['balance'] for p in points):.1e} | "
                  f"{sum(p['failures'] for p in points)} | {lost} |")
        ax.set_title(system)
        ax.set_xlabel("RMS state error at t = k / 12.5 s")
        ax.set_ylabel("wall time per trajectory [s]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Integrator work-precision, true systems, 4 s trajectories, "
                 "h = 1/12.5 ... 1/3200 s")
    fig.tight_layout()
    out = os.path.join(sys.argv[2], "work_precision.png")
    fig.savefig(out, dpi=120)
    print(f"\nwrote {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
