#!/usr/bin/env python3
"""A sweep's plan replayed with measured cell costs instead of the cost model's.

    /usr/bin/python3 analysis/schedule_replay.py sweeps/paper.toml 64,128 \\
        sweeps/cost-check.toml results/cost-check.h5

`phnn sweep --dry-run` simulates its schedule with the cost model's estimates; the efficiency it
prints is only as good as those estimates.  This script takes the plan the ranks would follow
(`phnn sweep SWEEP --dry-run --items --ranks N`: the work items, in the order the shared counter
hands them out) and replays it with each cell's cost scaled by measured / estimated of the same
configuration (system, model, size, n_train, regularizer) in a measured sweep
(analysis/cost_model_check.py's join of `--cell-costs` and `phnn reduce --per-run`): each item goes
to the rank that is free first, as the dynamic scheduler does.  Per rank count it prints the
simulated efficiency, the replayed one, and the bound of any schedule of the same items with the
measured costs (total / ranks, or the largest item).  Efficiency = (sum of the cells' unsplit
costs) / (ranks x makespan), as in `--dry-run`.  The measured sweep may be the same as SWEEP
(its own results) or a cheaper one with the same configurations (sweeps/cost-check.toml: the
paper grid at 2 seeds and 10 000 steps); the ratio then assumes the fixed and member parts of a
cell scale alike.  The phnn binary: $PHNN, else build/phnn.
"""
import argparse
import heapq
import sys

from cost_model_check import measured_cells
from phnn_tool import run_csv

CONFIGURATION = ("system", "model", "size", "n_train", "regularizer")


def configuration(cell):
    return tuple(cell[k] for k in CONFIGURATION)


def cost_ratios(measured):
    """{configuration: measured / estimated} over the measured cells; a configuration measured
    in several cells (e.g. other knobs) takes the ratio of the sums."""
    sums = {}
    for cell, seconds in measured:
        est, meas = sums.get(configuration(cell), (0.0, 0.0))
        sums[configuration(cell)] = (est + float(cell["estimated_s"]), meas + seconds)
    return {key: meas / est for key, (est, meas) in sums.items()}


def cell_ratios(cells, ratios):
    """The ratio of every cell of the replayed sweep, by index; raises naming the first cell
    whose configuration was not measured."""
    out = {}
    for cell in cells:
        key = configuration(cell)
        if key not in ratios:
            raise KeyError(f"cell {cell['cell']} ({', '.join(key)}) has no measured cell of the "
                           "same configuration: measure it (all its runs done) or replay a sweep "
                           "without it")
        out[int(cell["cell"])] = ratios[key]
    return out


def list_schedule_makespan(costs, ranks):
    """Each cost, in the given order, to the rank that is free first (the shared counter)."""
    loads = [0.0] * ranks
    for cost in costs:
        heapq.heappush(loads, heapq.heappop(loads) + cost)
    return max(loads)


def replay(items, cells, ratios, ranks):
    """(simulated efficiency, replayed efficiency, bound) of the plan `items` on `ranks`."""
    estimated = [float(i["estimated_s"]) for i in items]
    measured = [float(i["estimated_s"]) * ratios[int(i["cell"])] for i in items]
    unsplit_est = sum(float(c["estimated_s"]) for c in cells)
    unsplit_meas = sum(float(c["estimated_s"]) * ratios[int(c["cell"])] for c in cells)
    simulated = unsplit_est / (ranks * list_schedule_makespan(estimated, ranks))
    replayed = unsplit_meas / (ranks * list_schedule_makespan(measured, ranks))
    bound = unsplit_meas / (ranks * max(sum(measured) / ranks, max(measured)))
    return simulated, replayed, bound


def main(argv):
    parser = argparse.ArgumentParser(
        description="Replays a sweep's work plan with cell costs measured on another sweep.")
    parser.add_argument("sweep", help="the sweep file to plan")
    parser.add_argument("ranks", help="rank counts, e.g. 16,128")
    parser.add_argument("measured_sweep", help="a sweep file whose results give measured costs")
    parser.add_argument("measured_results", help="its results file")
    args = parser.parse_args(argv[1:])
    sweep, rank_list = args.sweep, args.ranks
    measured_sweep, measured_results = args.measured_sweep, args.measured_results
    measured_estimates = run_csv("sweep", measured_sweep, "--dry-run", "--cell-costs")
    runs = run_csv("reduce", measured_results, "--format", "csv", "--per-run")
    measured, incomplete = measured_cells(measured_estimates, runs)
    cells = run_csv("sweep", sweep, "--dry-run", "--cell-costs")
    try:
        ratios = cell_ratios(cells, cost_ratios(measured))
    except KeyError as e:
        print(f"schedule_replay.py: {e.args[0]}", file=sys.stderr)
        return 1
    print(f"measured / estimated from {measured_results}: {len(measured)} cells "
          f"({incomplete} left out: runs missing)")
    print("| ranks | items | simulated (cost model) | replayed (measured costs) | "
          "bound with measured costs |")
    print("|---|---|---|---|---|")
    for ranks in (int(r) for r in rank_list.split(",")):
        items = run_csv("sweep", sweep, "--dry-run", "--items", "--ranks", str(ranks))
        simulated, replayed, bound = replay(items, cells, ratios, ranks)
        print(f"| {ranks} | {len(items)} | {100 * simulated:.1f} % | {100 * replayed:.1f} % | "
              f"{100 * bound:.1f} % |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
