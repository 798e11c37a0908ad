#!/usr/bin/env python3
"""Where an adaptive sweep spent its seeds, and what it cost against every cell at max_seeds.

    /usr/bin/python3 analysis/adaptive_cost.py results/paper-adaptive.h5 sweeps/paper-adaptive.toml
    /usr/bin/python3 analysis/adaptive_cost.py results/paper-adaptive.h5 OTHER.toml --rule

With --rule, OTHER's [adaptive] table is replayed on the file's runs (`phnn reduce --rule`): the
cost that rule would have had, from the wall times of the runs it asks for; runs it asks for that
the file lacks are counted and named as missing (their cost is unknown).

Seeds per cell come from `phnn reduce --per-run` (exactly the runs the rounds asked for), measured
core-seconds from the runs' `wall_time_s` (an item's wall time shared by its members; one thread
per rank, so core-seconds). The 40-seed (max_seeds) cost is not measured: per cell it is the
measured cost scaled by the cost model's ratio, cost(max_seeds) / cost(trained), with the model's
per-cell fixed and per-member seconds from `phnn sweep SWEEP --dry-run --cell-costs` and a fixed
part paid once per round the cell trained in (one work item per round). The same figures from the
cost model alone are printed beside it.
"""
import argparse
import math
import sys
from collections import Counter

from phnn_tool import run_csv

def cell_key(row, model_field):
    return (row["system"], row[model_field], row["size"], row["n_train"], row["regularizer"])


def summarize(run_rows, cost_rows, initial, batch, max_seeds):
    """Per-cell seeds and costs; returns a dict of totals (core-seconds) and the seed histogram."""
    seeds, measured = Counter(), Counter()
    for r in run_rows:
        k = cell_key(r, "model_label")
        seeds[k] += 1
        if r["wall_time_s"] not in ("", "nan"):
            measured[k] += float(r["wall_time_s"])
    model_trained = model_full = scaled_full = 0.0
    for c in cost_rows:
        k = cell_key(c, "model")
        fixed, member = float(c["fixed_s"]), float(c["member_s"])
        n = seeds.get(k, 0)
        rounds = 1 + math.ceil(max(0, n - initial) / batch) if n else 0
        trained = rounds * fixed + n * member
        full = fixed + max_seeds * member
        model_trained += trained
        model_full += full
        scaled_full += measured[k] * full / trained if trained > 0 else full
    return {"seeds": seeds, "runs": sum(seeds.values()), "cells": len(cost_rows),
            "measured": sum(measured.values()), "scaled_full": scaled_full,
            "model_trained": model_trained, "model_full": model_full}


def report(s, max_seeds):
    hist = Counter(s["seeds"].values())
    lines = ["- cells by seeds: " + ", ".join(f"{hist[k]} at {k}" for k in sorted(hist)),
             f"- runs trained: {s['runs']} of {s['cells'] * max_seeds} "
             f"({100 * s['runs'] / (s['cells'] * max_seeds):.0f} %)",
             f"- measured: {s['measured'] / 3600:.2f} core-hours; every cell at {max_seeds} seeds, "
             f"scaled by the cost model: {s['scaled_full'] / 3600:.2f} core-hours "
             f"({100 * s['measured'] / s['scaled_full']:.0f} %)",
             f"- cost model alone: {s['model_trained'] / 3600:.2f} against "
             f"{s['model_full'] / 3600:.2f} core-hours "
             f"({100 * s['model_trained'] / s['model_full']:.0f} %)"]
    return "\n".join(lines)


def summarize_sweep(results, sweep, rule=False):
    """(summarize() of RESULTS' runs with SWEEP's cost model, the runs asked for that RESULTS
    lacks, SWEEP's max_seeds); with rule, SWEEP's [adaptive] table replayed on RESULTS' runs
    (`phnn reduce --rule`)."""
    import tomllib
    with open(sweep, "rb") as f:
        adaptive = tomllib.load(f).get("adaptive")
    if not adaptive:
        raise ValueError(f"{sweep}: no [adaptive] table")
    replay = ("--rule", sweep) if rule else ()
    runs = run_csv("reduce", results, "--per-run", *replay)
    missing = [r for r in runs if r["status"] == "pending"]
    costs = run_csv("sweep", sweep, "--dry-run", "--cell-costs")
    # Round 0's seeds: the fewest any cell has (every cell trains them).
    seeds_by_cell = Counter(cell_key(r, "model_label") for r in runs)
    initial = min(seeds_by_cell.values()) if seeds_by_cell else 0
    max_seeds = adaptive["max_seeds"]
    return summarize(runs, costs, initial, adaptive["batch"], max_seeds), missing, max_seeds


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="results file of an adaptive sweep")
    parser.add_argument("sweep", help="its sweep file (for the cost model's per-cell seconds)")
    parser.add_argument("--rule", action="store_true",
                        help="replay SWEEP's [adaptive] table on the file's runs instead of the "
                        "file's own (same grid, another rule)")
    args = parser.parse_args(argv)
    try:
        s, missing, max_seeds = summarize_sweep(args.results, args.sweep, args.rule)
    except ValueError as e:
        parser.error(str(e))
    if missing:
        print(f"adaptive_cost.py: warning: {len(missing)} runs asked for are not finished in "
              f"{args.results}: they count as trained runs (and in the cost model's figures) but "
              f"their seconds are unknown, left out of 'measured', e.g. {missing[0]['run_id']}",
              file=sys.stderr)
    print(report(s, max_seeds))
    return 0


if __name__ == "__main__":
    sys.exit(main())
