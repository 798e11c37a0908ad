#!/usr/bin/env python3
"""One ablation table: a baseline results file against variants that change one setting each.

    /usr/bin/python3 analysis/compare_ablation.py results/ablation-duffing-baseline.h5 \\
        "loss_norm = mse=results/ablation-duffing.h5" \\
        "dg_structure_point = start=results/ablation-duffing-dg-start.h5" \\
        "precision = float32=results/ablation-duffing-float32.h5" [--threshold 1.0]

For every cell of the baseline that a variant has, prints a Markdown row: the baseline's median
MSE with its bootstrap 95 % interval and the seeds above THRESHOLD (the Duffing oscillator's bad
mode: MSEs near 0.05 or near 10^2-10^3, so 1.0 separates them), then the same for each variant
that has the cell, marked "better" or "worse" when the two intervals do not overlap ("resolved"),
"~" otherwise. A cell is (system, model, the column of its table): N_train when the tables vary
it (the third column then shows the number), else the varied axis, e.g. "size=large", so a
variant of the paper's Study II compares with results/paper.h5's Study II table. Medians and
intervals come from `phnn reduce --format csv` (the reducer's own statistics: linear-interpolation
quartiles, percentile bootstrap, fixed key); the seed counts from `phnn reduce --format csv
--per-run`, over the runs of the row's study. The phnn binary: $PHNN, else build/phnn.
"""
import argparse
import math
import sys

from phnn_tool import run_csv



def reduce_csv(path, *extra):
    return run_csv("reduce", path, "--format", "csv", *extra)


AXES = ("n_train", "size", "regularizer")


def cells(path, threshold):
    """{(system, model, axis, column): (median, low, high, above, finished)}"""
    above, finished = {}, {}
    for r in reduce_csv(path, "--per-run"):
        if r["status"] not in ("done", "diverged"):
            continue
        for study in r["studies"].split(","):
            for axis in AXES:
                key = (study, r["system"], r["model_label"], axis, r[axis])
                finished[key] = finished.get(key, 0) + 1
                above[key] = above.get(key, 0) + (float(r["mse"]) > threshold)
    out = {}
    for r in reduce_csv(path):
        if not r["median"]:
            continue
        axis, column = r["axis"], r["column"]
        if not axis:  # a table with one column (no varied axis): the model's only N_train
            ns = {k[4] for k in finished
                  if k[:3] == (r["study"], r["system"], r["model"]) and k[3] == "n_train"}
            if len(ns) != 1:
                continue
            axis, column = "n_train", ns.pop()
        if axis not in AXES:
            continue
        counted = (r["study"], r["system"], r["model"], axis, column)
        out[(r["system"], r["model"], axis, column)] = (
            float(r["median"]), number(r["ci_low"]), number(r["ci_high"]),
            above.get(counted, 0), finished.get(counted, 0))
    return out


def number(text):
    """A reducer CSV number; an empty field (no interval: fewer than 5 finished seeds) is NaN."""
    return float(text) if text not in ("", "nan") else math.nan


def column_text(axis, column):
    return column if axis == "n_train" else f"{axis}={column}"


def sort_key(key):
    system, model, axis, column = key
    return (system, model, AXES.index(axis), int(column) if axis == "n_train" else column)


def text(cell):
    median, low, high, above, n = cell
    interval = f"({low:.2g}, {high:.2g})" if not math.isnan(low) else "(no interval)"
    return f"{median:.3g} {interval} [{above}/{n}]"


def verdict(base, cell):
    """better / worse when the intervals do not overlap; ~ otherwise or without intervals."""
    if cell[2] < base[1]:
        return " better"
    if cell[1] > base[2]:
        return " worse"
    return " ~"


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="Each cell of ablation results files against a baseline file: median "
        "(bootstrap interval) [seeds above the threshold / finished] and better/worse/~.")
    parser.add_argument("baseline", help="results file of the baseline")
    parser.add_argument("variants", nargs="+", metavar="NAME=RESULTS",
                        help="a variant's column name and results file")
    parser.add_argument("--threshold", type=float, default=1.0,
                        help="count the seeds whose MSE is above this (default 1)")
    args = parser.parse_args(argv)
    for v in args.variants:
        if "=" not in v:
            parser.error(f"{v}: give a variant as NAME=RESULTS")
    threshold = args.threshold
    base = cells(args.baseline, threshold)
    variants = [(a.rsplit("=", 1)[0], cells(a.rsplit("=", 1)[1], threshold)) for a in args.variants]
    keys = sorted((k for k in base if any(k in v for _, v in variants)), key=sort_key)
    only_n_train = all(k[2] == "n_train" for k in keys)
    print(f"| system | model | {'N_train' if only_n_train else 'column'} | baseline | "
          + " | ".join(n for n, _ in variants) + " |")
    print("|---" * (4 + len(variants)) + "|")
    for key in keys:
        row = [key[0], key[1], column_text(key[2], key[3]), text(base[key])]
        for _, v in variants:
            row.append(text(v[key]) + verdict(base[key], v[key]) if key in v else "")
        print("| " + " | ".join(row) + " |")
    print(f"\nmedian (bootstrap 95 % interval) [seeds with MSE > {threshold:g} / finished]; "
          "better / worse: the intervals do not overlap; ~: they do.")


if __name__ == "__main__":
    main()
