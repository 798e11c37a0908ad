#!/usr/bin/env python3
"""analysis/work_plan.py — src/sweep/work_plan.cpp's plan_work() in Python: cells with runs to do,
split into work items (whole cells or contiguous member groups) for R ranks.

    from work_plan import PlanCell, plan_work
    items = plan_work([PlanCell(cell=0, fixed=4.35, member=29.8, runs=10), ...], ranks=128)
    # [(cell, runs), ...] largest estimated cost first: the order the ranks take them

The same policy as `phnn sweep` (docs/DECISIONS.md "Member groups"): the uniform cuts at every
target where a cell's group count changes, a descent on the group counts of each class of
equal-cost cells from the best cut and from the unsplit plan, then the cheapest plan (fewest
core-seconds) whose simulated makespan is within (1 + min_gain) of the shortest. Costs are the
cost model's, cost(k members) = fixed + k x member (Cell::cost_s), read from `phnn sweep SWEEP
--dry-run --cell-costs` (printed to 6 significant digits, so near-ties may order differently from
the binary's). analysis/rounds_replay.py plans each round of an adaptive sweep with it, as
`phnn sweep` does after every round; tests/analysis/test_rounds_replay.py compares it with
`phnn sweep --dry-run --items`.
"""
import heapq
from collections import namedtuple

# cell: index in the grid (cells largest first, as --cell-costs lists them); runs: how many of its
# runs are to do (> 0).
PlanCell = namedtuple("PlanCell", "cell fixed member runs")
# A plan's group count per cell (same order as the cells) and what its simulation gives.
Candidate = namedtuple("Candidate", "counts makespan cost")

RELATIVE = 1e-12  # work_plan.cpp's better(): round-off of sums of <= ~10^4 costs


def group_cost(cell, members):
    return cell.fixed + members * cell.member


def greedy_makespan(costs, ranks):
    """grid.cpp's greedy_makespan_s: largest first, each to the rank that is free first."""
    loads = [0.0] * ranks
    for cost in sorted(costs, reverse=True):
        heapq.heappush(loads, heapq.heappop(loads) + cost)
    return max(loads) if costs else 0.0


def largest_group(n, groups):
    return (n + groups - 1) // groups


def group_count(cell, target, cap):
    """Fewest near-equal groups of the cell's runs costing <= target, at most cap runs each."""
    n = cell.runs
    first = largest_group(n, cap) if cap > 0 else 1
    for g in range(first, n):
        if group_cost(cell, largest_group(n, g)) <= target:
            return g
    return max(1, n)


def items(cells, counts):
    """[(cell, runs, estimated cost)]: each cell in counts[i] near-equal groups, the larger first;
    all of them largest cost first, ties in cell order (a stable sort, as make_plan's)."""
    out = []
    for cell, count in zip(cells, counts):
        for g in range(count):
            size = cell.runs // count + (1 if g < cell.runs % count else 0)
            out.append((cell.cell, size, group_cost(cell, size)))
    return sorted(out, key=lambda item: -item[2])


def simulate(cells, counts, ranks):
    costs = [cost for _, _, cost in items(cells, counts)]
    return Candidate(tuple(counts), greedy_makespan(costs, ranks), sum(costs))


def better(a, b):
    """By simulated makespan, then by core-seconds."""
    if a.makespan < b.makespan * (1.0 - RELATIVE):
        return True
    if a.makespan > b.makespan * (1.0 + RELATIVE):
        return False
    return a.cost < b.cost * (1.0 - RELATIVE)


def best_of(candidates):
    best = candidates[0]
    for c in candidates[1:]:
        if better(c, best):
            best = c
    return best


def candidate_targets(cells, cap):
    """Every target at which the group counts change, largest first, down to the largest run."""
    floor = max(group_cost(c, 1) for c in cells)
    targets = set()
    for c in cells:
        for k in range(1, (min(c.runs, cap) if cap > 0 else c.runs) + 1):
            if group_cost(c, k) >= floor:
                targets.add(group_cost(c, k))
    return sorted(targets, reverse=True)


def equal_cost_classes(cells):
    """Positions of cells with equal (runs, fixed, member), classes in order of their first cell."""
    classes = {}
    for i, c in enumerate(cells):
        classes.setdefault((c.runs, c.fixed, c.member), []).append(i)
    return list(classes.values())


def refine(cells, classes, best, ranks, cap):
    """Moves each class's group count by -2..+3 while better(); each kept move improves."""
    improved = True
    while improved:
        improved = False
        for members in classes:
            n = cells[members[0]].runs
            fewest = largest_group(n, cap) if cap > 0 else 1
            for step in (-2, -1, 1, 2, 3):
                count = best.counts[members[0]] + step
                if count < fewest or count > n:
                    continue
                trial = list(best.counts)
                for i in members:
                    trial[i] = count
                candidate = simulate(cells, trial, ranks)
                if better(candidate, best):
                    best, improved = candidate, True
    return best


def plan_work(cells, ranks, split=True, cap=0, min_gain=0.01):
    """[(cell, runs)] of the plan, in the order the ranks take them; cells: PlanCell in grid order
    (those with runs to do). split=False: one item per cell (`--split off`)."""
    if not cells:
        return []
    unsplit = [group_count(c, 1e300, cap) for c in cells]
    if not split:
        return [(cell, runs) for cell, runs, _ in items(cells, unsplit)]
    candidates = [simulate(cells, [group_count(c, t, cap) for c in cells], ranks)
                  for t in candidate_targets(cells, cap)]
    classes = equal_cost_classes(cells)
    candidates.append(refine(cells, classes, best_of(candidates), ranks, cap))
    candidates.append(refine(cells, classes, simulate(cells, unsplit, ranks), ranks, cap))
    shortest = best_of(candidates).makespan
    chosen = None
    for c in candidates:
        if c.makespan <= shortest * (1.0 + min_gain) and (chosen is None or c.cost < chosen.cost):
            chosen = c
    return [(cell, runs) for cell, runs, _ in items(cells, chosen.counts)]
