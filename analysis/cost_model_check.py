#!/usr/bin/env python3
"""The cost model against a measured sweep: estimated and measured seconds per cell.

    /usr/bin/python3 analysis/cost_model_check.py sweeps/paper.toml results/paper.h5

The estimates come from `phnn sweep SWEEP --dry-run --cell-costs` (include/phnn/sweep/grid.h's
CostModel), the measurements from `phnn reduce RESULTS --format csv --per-run`: a cell's measured
cost is the sum of its runs' wall_time_s (the trainer stores the stack's wall time divided by its
members), over the runs with status done or diverged; cells with runs missing are left out and
counted.  Prints a Markdown table of measured / estimated per model label, size and regularizer
(the median and range of the per-cell ratios, and the ratio of the sums), then the totals.  The
phnn binary: $PHNN, else build/phnn.
"""
import argparse
import statistics
import sys

from phnn_tool import run_csv




def measured_cells(estimates, runs):
    """[(estimate row, measured seconds)] for the cells whose runs all finished; and the
    number of cells left out."""
    wall = {r["run_id"]: float(r["wall_time_s"]) for r in runs
            if r["status"] in ("done", "diverged")}
    out, incomplete = [], 0
    for cell in estimates:
        ids = cell["run_ids"].split()
        if all(i in wall for i in ids):
            out.append((cell, sum(wall[i] for i in ids)))
        else:
            incomplete += 1
    return out, incomplete


def grouped(cells):
    groups = {}
    for cell, seconds in cells:
        key = (cell["model"], cell["size"], cell["regularizer"])
        groups.setdefault(key, []).append((float(cell["estimated_s"]), seconds))
    return groups


def table(cells, incomplete):
    lines = ["| model | size | regularizer | cells | estimated [s] | measured [s] | "
             "measured / estimated: median (range) | of the sums |", "|---|---|---|---|---|---|---|---|"]
    for (model, size, reg), pairs in sorted(grouped(cells).items()):
        est = sum(e for e, _ in pairs)
        meas = sum(m for _, m in pairs)
        ratios = [m / e for e, m in pairs]
        lines.append(f"| {model} | {size} | {reg} | {len(pairs)} | {est:.0f} | {meas:.0f} | "
                     f"{statistics.median(ratios):.2f} ({min(ratios):.2f}–{max(ratios):.2f}) | "
                     f"{meas / est:.2f} |")
    est = sum(float(c["estimated_s"]) for c, _ in cells)
    meas = sum(m for _, m in cells)
    lines.append("")
    lines.append(f"{len(cells)} cells measured ({incomplete} left out: runs missing): "
                 f"estimated {est / 3600:.2f} core-hours, measured {meas / 3600:.2f} core-hours, "
                 f"measured / estimated {meas / est:.2f}.")
    return "\n".join(lines)


def main(argv):
    parser = argparse.ArgumentParser(
        description="The cost model's estimate of each cell against its measured time.")
    parser.add_argument("sweep", help="sweep file")
    parser.add_argument("results", help="its results file")
    args = parser.parse_args(argv[1:])
    argv = [argv[0], args.sweep, args.results]
    estimates = run_csv("sweep", argv[1], "--dry-run", "--cell-costs")
    runs = run_csv("reduce", argv[2], "--format", "csv", "--per-run")
    cells, incomplete = measured_cells(estimates, runs)
    if not cells:
        print(f"cost_model_check.py: no cell of {argv[1]} has all its runs in {argv[2]}",
              file=sys.stderr)
        return 1
    print(table(cells, incomplete))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
