#!/usr/bin/env python3
"""analysis/rounds_replay.py — a finished adaptive sweep's rounds replayed on R ranks with the
measured costs, a barrier after each round as `phnn sweep` has, and without.

    /usr/bin/python3 analysis/rounds_replay.py results/paper-adaptive.h5 \\
        sweeps/paper-adaptive.toml 2,16,128,1024

`phnn sweep --dry-run` simulates an adaptive sweep's round 0 and its worst case only. This script
rebuilds the rounds the file's sweep ran and replays them:

- A run's round: the first K for which `phnn reduce RESULTS --per-run --round K` lists it (the
  runs rounds 0..K asked for), K = 0, 1, ... until a round adds none. Round 0 is every cell's first
  seeds; round k the cells named after round k-1 with their added seeds.
- Items: per rank count and round, analysis/work_plan.py's port of plan_work() on the round's
  cells, as `phnn sweep` plans after every round (the same items as the binary's, tested against
  `--dry-run --items`): whole cells or contiguous member groups, largest first.
- Costs: the trainer stores in each run wall_time_s = the stack's wall time / its members, so the
  runs of an item sum to the item's wall time. The stacks the sweep trained are its runs with equal
  (cell, started_utc, finished_utc) (`/runs/*_utc` of the file, read with h5py; without them one
  stack per cell and round). Per cell and round, scale = (measured seconds) / (cost model of the
  stacks trained), fixed_s + members x member_s each (`phnn sweep SWEEP --dry-run --cell-costs`);
  a replayed item of k runs costs scale x (fixed_s + k x member_s). Where the replay forms the
  items the sweep trained, the item costs are the measured wall times exactly; elsewhere the cell's
  fixed and per-member parts are assumed to scale alike. Runs without a wall time (failed before
  training) cost nothing.
- Schedule: every item in plan order to the rank free first (schedule_replay.py's
  list_schedule_makespan); with barriers each round starts when the last rank finished the round
  before; without, each rank goes on with the next round's items at once (not possible in a real
  sweep, whose rule reads the round's results: the bound if no rank idled between rounds).
- With speculation (speculative_replay, as `phnn sweep` without --no-speculation): barriers,
  and while a round drains the idle ranks train the next seeds of the cells the round grows; what
  the next round asks for of that goes on from where it stopped, the rest is lost work.

Per rank count: rounds, items, core-hours (the sum of the item costs), makespan and efficiency =
core-hours / (ranks x makespan) with barriers, with speculation (the same core-hours: the work
asked for; the work spent ahead and the part of it no round asked for beside it) and without
barriers, and the items per round. The output
depends on the file alone (deterministic). The phnn binary: $PHNN, else build/phnn. On the paper
grid's adaptive file (2 230 runs, 12 rounds, 345 MB) it takes ~9 min of one core, nearly all in the
`phnn reduce --round K` calls (each replays the rounds up to K).
"""
import argparse
import heapq
import math
import sys
import tomllib
from collections import Counter

from phnn_tool import run_csv
from schedule_replay import list_schedule_makespan
from work_plan import PlanCell, plan_work


def runs_by_round(results):
    """[[per-run row of each run round k added]] for k = 0, 1, ... (last: the sweep's last)."""
    rounds, seen = [], set()
    while True:
        rows = run_csv("reduce", results, "--per-run", "--round", str(len(rounds)))
        added = [r for r in rows if r["run_id"] not in seen]
        if not added:
            return rounds
        pending = [r["run_id"] for r in added if r["status"] == "pending"]
        if pending:
            raise ValueError(f"{results}: round {len(rounds)} has {len(pending)} pending runs "
                             f"(e.g. {pending[0]}): replay a finished sweep")
        seen.update(r["run_id"] for r in added)
        rounds.append(added)


def item_times(results):
    """{run_id: (started_utc, finished_utc)} of the file's runs that have them; {} without h5py."""
    try:
        import h5py
    except ImportError:
        return {}
    with h5py.File(results, "r") as f:
        runs = f["runs"]
        if "started_utc" not in runs:
            return {}
        ids, started, finished = (runs[k][()] for k in ("id", "started_utc", "finished_utc"))
    return {i.decode(): (s.decode(), e.decode()) for i, s, e in zip(ids, started, finished)
            if s and e}


def round_cells(rounds, cost_rows, times):
    """Per round {cell: (runs, scale)}: the runs it trained of the cell, and measured seconds /
    the cost model's seconds of the stacks they were trained in."""
    cell_of = {i: int(c["cell"]) for c in cost_rows for i in c["run_ids"].split()}
    model = {int(c["cell"]): (float(c["fixed_s"]), float(c["member_s"])) for c in cost_rows}
    out = []
    for rows in rounds:
        runs, seconds, stacks = Counter(), Counter(), Counter()
        for r in rows:
            if r["run_id"] not in cell_of:
                raise ValueError(f"run {r['run_id']} is not in the sweep file's grid: give the "
                                 "sweep file of the results file")
            cell = cell_of[r["run_id"]]
            runs[cell] += 1
            wall = float(r["wall_time_s"]) if r["wall_time_s"] else math.nan
            seconds[cell] += wall if math.isfinite(wall) else 0.0
            stacks[(cell, times.get(r["run_id"], ""))] += 1
        modelled = Counter()
        for (cell, _), members in stacks.items():
            modelled[cell] += model[cell][0] + members * model[cell][1]
        out.append({c: (runs[c], seconds[c] / modelled[c]) for c in sorted(runs)})
    return out


def round_item_costs(cells_of_rounds, cost_rows, ranks, split=True):
    """Per round, the measured cost of each item of `ranks`' plan, in plan order."""
    model = {int(c["cell"]): (float(c["fixed_s"]), float(c["member_s"])) for c in cost_rows}
    out = []
    for cells in cells_of_rounds:
        plan = plan_work([PlanCell(c, *model[c], n) for c, (n, _) in cells.items()], ranks, split)
        out.append([cells[c][1] * (model[c][0] + k * model[c][1]) for c, k in plan])
    return out


def unsplit_work(cells_of_rounds, cost_rows):
    """The runs asked for as one stack per cell and round (fixed + runs x member, at the round's
    measured scale) [s]: the least work any schedule spends on them."""
    model = {int(c["cell"]): (float(c["fixed_s"]), float(c["member_s"])) for c in cost_rows}
    return sum(scale * (model[c][0] + n * model[c][1])
               for cells in cells_of_rounds for c, (n, scale) in cells.items())


def critical_path(cells_of_rounds, cost_rows):
    """Sum over rounds of the round's costliest single run (fixed + one member, at its measured
    scale) [s]: no schedule that waits for each round's decision is shorter, at any rank count
    and however finely cells are split."""
    model = {int(c["cell"]): (float(c["fixed_s"]), float(c["member_s"])) for c in cost_rows}
    return sum(max(scale * (model[c][0] + model[c][1]) for c, (_, scale) in cells.items())
               for cells in cells_of_rounds if cells)


def barrier_makespan(rounds, ranks):
    """Each round on its own (every rank free at its start), one after the other."""
    return sum(list_schedule_makespan(costs, ranks) for costs in rounds)


def free_makespan(rounds, ranks):
    """The rounds' items as one list: no rank waits for the others between rounds."""
    return list_schedule_makespan([c for costs in rounds for c in costs], ranks)


def ahead_schedule(costs, ahead, ranks):
    """One round with ranks left idle training ahead: `costs` (the round's items, plan order) each
    to the rank free first; the round ends when its last item does (T). Then, in order, each
    ahead item ({"left": cost left, ...}) to the rank free first while that is before T: it
    finishes (left 0) or stops at T with its progress kept. Returns (T, work spent ahead)."""
    loads = [0.0] * ranks
    for cost in costs:
        heapq.heappush(loads, heapq.heappop(loads) + cost)
    end, spent = max(loads), 0.0
    for item in ahead:
        free = heapq.heappop(loads)
        if free >= end:
            break
        done = min(item["left"], end - free)
        item["left"] -= done
        spent += done
        heapq.heappush(loads, free + done)
    return end, spent


def take_ahead(cells, seeds, started, model):
    """Round start: the items of the round's cells ({cell: (runs, scale)}) trained ahead before
    (`started`, {cell: {first seed: item}}) are taken, and `seeds` advanced. Returns
    ([(cell, cost left)] of the resumed ones, [PlanCell] of the runs still to plan)."""
    resumed, to_plan = [], []
    for c, (n, _) in cells.items():
        first = seeds.get(c, 0)
        for start in [s0 for s0 in started.get(c, {}) if s0 < first + n]:
            item = started[c].pop(start)
            n -= item["runs"]
            if item["left"] > 0:
                resumed.append((c, item["left"]))
        if n > 0:
            to_plan.append(PlanCell(c, *model[c], n))
        seeds[c] = first + cells[c][0]
    return resumed, to_plan


# As `phnn sweep` plans the items idle ranks may train ahead under the comparisons rule
# (sweep_items.cpp, kAheadSplit): for this many times the ranks, so that they fit the end of a
# round.
AHEAD_SPLIT = 8


def speculative_replay(cells_of_rounds, cost_rows, ranks, batch, max_seeds, split=True,
                       depth=1, window=1):
    """The rounds with speculation as `phnn sweep` does it for the column-best rule (docs/METHOD.md
    "Speculation"): while round k drains, idle ranks train the next `depth` batches of `batch`
    seeds (fewer at max_seeds) of each cell round k grows, nearer batches first, largest items
    first within one; an ahead item stops at the round's end. A round that asks for an ahead item's runs takes them as they are (finished, or a resumed item first in the plan, what is left of its
    cost); a cell that stops growing loses the work ahead of it. An ahead item costs what it
    costs in the round that asks for it (that round's scale), else in this one. window > 1: the
    cells grown in any of the last `window` rounds (`phnn sweep`: 1).
    Returns (makespan, work spent ahead, of it never asked for, work spent on the runs asked
    for)."""
    model = {int(c["cell"]): (float(c["fixed_s"]), float(c["member_s"])) for c in cost_rows}
    seeds = {}    # cell -> seeds asked so far
    grown = {}    # cell -> the last round that gave it seeds
    started = {}  # cell -> {first seed: ahead item} trained ahead, not yet asked for
    makespan = spent = lost = trained = 0.0

    def scale_of(c, k):  # of the first later round that asks for cell c, else its last round's
        for later in cells_of_rounds[k + 1:]:
            if c in later:
                return later[c][1]
        return cells_of_rounds[grown[c]][c][1]

    for k, cells in enumerate(cells_of_rounds):
        resumed, to_plan = take_ahead(cells, seeds, started, model)
        resumed = [left for _, left in resumed]
        for c in cells:
            grown[c] = k
        growing = [c for c in sorted(grown) if k - grown[c] < window]
        for c in [c for c in started if c not in growing]:  # stopped growing
            lost += sum(i["cost"] - i["left"] for i in started.pop(c).values())
        costs = resumed + [cells[c][1] * (model[c][0] + m * model[c][1])
                           for c, m in plan_work(to_plan, ranks, split)]
        ahead = []
        for j in range(depth):
            candidates, firsts = [], {}
            for c in growing:
                first = seeds[c] + j * batch
                if first < max_seeds and first not in started.get(c, {}):
                    candidates.append(PlanCell(c, *model[c], min(batch, max_seeds - first)))
                    firsts[c] = first
            for c, m in plan_work(candidates, ranks, split):
                cost = scale_of(c, k) * (model[c][0] + m * model[c][1])
                ahead.append({"cell": c, "first": firsts[c], "runs": m, "cost": cost, "left": cost})
                firsts[c] += m
        makespan += ahead_schedule(costs, ahead, ranks)[0]
        trained += sum(costs)
        for item in ahead:
            spent += item["cost"] - item["left"]
            if item["left"] < item["cost"]:
                started.setdefault(item["cell"], {})[item["first"]] = item
    lost += sum(i["cost"] - i["left"] for items in started.values() for i in items.values())
    return makespan, spent, lost, trained + spent - lost


def comparison_cells(comparisons, cost_rows):
    """Per comparison of an [adaptive] table, the set of cells its two selectors cover."""
    cell_of = {"/".join((c["system"], c["model"].lower(), c["n_train"], c["size"],
                         c["regularizer"])): int(c["cell"]) for c in cost_rows}
    out = []
    for pair in comparisons:
        cells = set()
        for side in pair:
            system, models, rest = side.split("/", 2)
            cells.update(cell_of[f"{system}/{m}/{rest}"] for m in models.split("+")
                         if f"{system}/{m}/{rest}" in cell_of)
        out.append(cells)
    return out


def named_by_round(results, rounds, cost_rows):
    """Per round k but the last, {cell: [comparison index, ...]}: the comparisons that named the
    cell after round k (`phnn reduce --round k --named`)."""
    cell_of = {"/".join((c["system"], c["model"].lower(), c["n_train"], c["size"],
                         c["regularizer"])): int(c["cell"]) for c in cost_rows}
    out = []
    for k in range(len(rounds) - 1):
        named = {}
        for row in run_csv("reduce", results, "--round", str(k), "--named"):
            named.setdefault(cell_of[row["cell"]], []).append(int(row["comparison"]) - 1)
        out.append(named)
    return out


def comparison_chain(cells_of_rounds, cost_rows, cells_of_comparison, named):
    """The longest chain of one comparison's decisions [s]: the costliest single run of its cells
    in round 0, plus for each round after which it named cells the costliest single run of those
    (at the next round's measured scale). A comparison decides again only once the runs it named
    have finished, and they cannot start before it named them: a schedule that trains only runs
    a decision has asked for is never shorter, however many ranks and however finely split."""
    model = {int(c["cell"]): (float(c["fixed_s"]), float(c["member_s"])) for c in cost_rows}

    def single(c, k):
        return cells_of_rounds[k][c][1] * (model[c][0] + model[c][1])

    longest = 0.0
    for j, cells in enumerate(cells_of_comparison):
        chain = max((single(c, 0) for c in cells if c in cells_of_rounds[0]), default=0.0)
        for k, known in enumerate(named):
            mine = [c for c, by in known.items() if j in by and c in cells_of_rounds[k + 1]]
            chain += max((single(c, k + 1) for c in mine), default=0.0)
        longest = max(longest, chain)
    return longest


def early_replay(cells_of_rounds, cost_rows, ranks, batch, max_seeds, cells_of_comparison,
                 named, split=True):
    """The rounds as `phnn sweep` runs a comparisons rule (docs/METHOD.md "Speculation"): a
    comparison names its cells for the next round as soon as every cell it covers has finished
    the round's items, and ranks left idle train those cells' next seeds (items of the plan of
    every comparison cell's next batch), the first ready one in plan order; an item stops at the
    round's end and goes on from where it stopped when the next round asks for it (always: only
    named cells are trained; the plan is made for AHEAD_SPLIT times the ranks, as the sweep's).
    Returns (makespan, work spent ahead, of it never asked for, work spent
    on the runs asked for)."""
    model = {int(c["cell"]): (float(c["fixed_s"]), float(c["member_s"])) for c in cost_rows}
    candidates = sorted(set().union(*cells_of_comparison)) if cells_of_comparison else []
    seeds, started = {}, {}
    makespan = spent = lost = trained = 0.0
    for k, cells in enumerate(cells_of_rounds):
        items, to_plan = take_ahead(cells, seeds, started, model)
        for c in [c for c in started if c not in cells]:  # never asked for
            lost += sum(i["cost"] - i["left"] for i in started.pop(c).values())
        items += [(c, cells[c][1] * (model[c][0] + m * model[c][1]))
                  for c, m in plan_work(to_plan, ranks, split)]
        loads, finish = [0.0] * ranks, {}
        trained += sum(cost for _, cost in items)
        for c, cost in items:
            t = heapq.heappop(loads) + cost
            finish[c] = max(finish.get(c, 0.0), t)
            heapq.heappush(loads, t)
        end = max(loads)
        makespan += end
        if k + 1 >= len(cells_of_rounds):
            break
        nxt, known = cells_of_rounds[k + 1], named[k]
        ahead, firsts = [], {}
        plan = [PlanCell(c, *model[c], min(batch, max_seeds - seeds.get(c, 0))) for c in candidates
                if seeds.get(c, 0) < max_seeds and seeds.get(c, 0) not in started.get(c, {})]
        for c, m in plan_work(plan, ranks * AHEAD_SPLIT, split):
            if c not in known:
                continue
            ready = min(max(finish.get(d, 0.0) for d in cells_of_comparison[j]) for j in known[c])
            scale = nxt[c][1] if c in nxt else 1.0
            cost = scale * (model[c][0] + m * model[c][1])
            first = firsts.get(c, seeds.get(c, 0))
            ahead.append({"cell": c, "first": first, "runs": m, "cost": cost, "left": cost,
                          "ready": ready})
            firsts[c] = first + m
        while ahead:
            free = heapq.heappop(loads)
            if free >= end:
                break
            ready = [i for i in ahead if i["ready"] <= free]
            if not ready:
                heapq.heappush(loads, min(i["ready"] for i in ahead))
                continue
            item = ready[0]
            ahead.remove(item)
            done = min(item["left"], end - free)
            item["left"] -= done
            spent += done
            heapq.heappush(loads, free + done)
            started.setdefault(item["cell"], {})[item["first"]] = item
    lost += sum(i["cost"] - i["left"] for items in started.values() for i in items.values())
    return makespan, spent, lost, trained + spent - lost


def replay(rounds, ranks):
    """{ranks, items, work, barrier, free, efficiency, free_efficiency} of per-round item costs."""
    work = sum(sum(costs) for costs in rounds)
    barrier, free = barrier_makespan(rounds, ranks), free_makespan(rounds, ranks)
    return {"ranks": ranks, "items": [len(costs) for costs in rounds], "work": work,
            "barrier": barrier, "free": free,
            "efficiency": work / (ranks * barrier) if barrier > 0 else 1.0,
            "free_efficiency": work / (ranks * free) if free > 0 else 1.0}


def duration(seconds):
    """As `phnn sweep --dry-run` prints it (work_plan.cpp's format_duration)."""
    if seconds < 10:
        return f"{seconds:.1f} s"
    if seconds < 120:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.1f} min" if seconds < 7200 else f"{seconds / 3600:.1f} h"


def table(rows):
    lines = ["| ranks | rounds | items | core-hours | makespan with barriers | efficiency | "
             "with speculation | efficiency | core-hours ahead (never asked for) | "
             "without barriers | efficiency |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        spec, ahead, lost, _ = r["speculative"]
        lines.append(f"| {r['ranks']} | {len(r['items'])} | {sum(r['items'])} | "
                     f"{r['work'] / 3600:.3g} | {duration(r['barrier'])} | "
                     f"{100 * r['efficiency']:.1f} % | {duration(spec)} | "
                     f"{100 * r['work'] / (r['ranks'] * spec):.1f} % | "
                     f"{ahead / 3600:.2f} ({lost / 3600:.2f}) | {duration(r['free'])} | "
                     f"{100 * r['free_efficiency']:.1f} % |")
    lines.append("")
    for r in rows:
        lines.append(f"items per round on {r['ranks']} rank{'' if r['ranks'] == 1 else 's'}: "
                     + ", ".join(str(n) for n in r["items"]))
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0].split(" — ")[1])
    parser.add_argument("results", help="results file of a finished adaptive sweep")
    parser.add_argument("sweep", help="its sweep file (cells and the cost model's seconds)")
    parser.add_argument("ranks", help="rank counts, e.g. 2,16,128,1024")
    parser.add_argument("--split", choices=("auto", "off"), default="auto",
                        help="as phnn sweep's --split: off = one item per cell and round")
    args = parser.parse_args(argv)
    cost_rows = run_csv("sweep", args.sweep, "--dry-run", "--cell-costs")
    try:
        rounds = runs_by_round(args.results)
        cells = round_cells(rounds, cost_rows, item_times(args.results))
    except ValueError as e:
        print(f"rounds_replay.py: {e}", file=sys.stderr)
        return 1
    measured = sum(float(r["wall_time_s"]) for rows in rounds for r in rows
                   if r["wall_time_s"] and math.isfinite(float(r["wall_time_s"])))
    print(f"{args.results}: {len(rounds)} rounds, {sum(len(r) for r in rounds)} runs "
          f"({measured / 3600:.2f} core-hours measured); runs per round: "
          + ", ".join(str(len(r)) for r in rounds) + "; cells per round: "
          + ", ".join(str(len(c)) for c in cells))
    with open(args.sweep, "rb") as f:
        adaptive = tomllib.load(f)["adaptive"]
    early = adaptive.get("rule") == "comparisons"
    if early:
        named = named_by_round(args.results, rounds, cost_rows)
        covered = comparison_cells(adaptive["comparisons"], cost_rows)
    rows = []
    for n in (int(r) for r in args.ranks.split(",")):
        row = replay(round_item_costs(cells, cost_rows, n, args.split == "auto"), n)
        row["speculative"] = (
            early_replay(cells, cost_rows, n, adaptive["batch"], adaptive["max_seeds"], covered,
                         named, args.split == "auto") if early else
            speculative_replay(cells, cost_rows, n, adaptive["batch"], adaptive["max_seeds"],
                               args.split == "auto"))
        rows.append(row)
    print(table(rows))
    print(f"the runs asked for as one stack per cell and round: "
          f"{unsplit_work(cells, cost_rows) / 3600:.2f} core-hours")
    print(f"critical path of the rounds (each round's costliest single run, summed): "
          f"{duration(critical_path(cells, cost_rows))}")
    if early:
        print(f"longest chain of one comparison's decisions (its named cells' costliest single "
              f"run per round, summed): {duration(comparison_chain(cells, cost_rows, covered, named))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
