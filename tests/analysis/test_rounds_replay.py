#!/usr/bin/env python3
"""Unit tests of analysis/rounds_replay.py and analysis/work_plan.py: the schedule with and without
barriers between rounds, the port of plan_work(), the measured item costs; with a phnn binary
($PHNN, else build/phnn) the rounds rebuilt from a small adaptive sweep trained here (~3 s) and the
port's plans against `phnn sweep --dry-run --items`.

    PHNN=build/phnn /usr/bin/python3 tests/analysis/test_rounds_replay.py
"""
import contextlib
import io
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "analysis"))
import rounds_replay as rr  # noqa: E402
import work_plan as wp  # noqa: E402
from phnn_tool import phnn, run_csv  # noqa: E402


class Barriers(unittest.TestCase):
    def test_hand_computed_makespans(self):
        # 2 ranks, [[3, 3, 2], [1]]: round 0 3 | 3, then 2 on rank 0 -> 5; round 1: 1 -> 5 + 1.
        # Without the barrier the 1 goes to rank 1 (free at 3) -> 4: the makespan stays 5.
        self.assertEqual(rr.barrier_makespan([[3, 3, 2], [1]], 2), 6)
        self.assertEqual(rr.free_makespan([[3, 3, 2], [1]], 2), 5)
        # One item per round on 3 ranks: 3 x 4 with barriers; without, all three at once.
        r = rr.replay([[4], [4], [4]], 3)
        self.assertEqual((r["barrier"], r["free"], r["work"], r["items"]), (12, 4, 12, [1, 1, 1]))
        self.assertAlmostEqual(r["efficiency"], 12 / 36)
        self.assertAlmostEqual(r["free_efficiency"], 1.0)

    def test_plan_order_is_kept_within_a_round(self):
        # 1, 1, 4 on 2 ranks: 1 | 1, then 4 -> 5 (the plan's order, as the shared counter).
        self.assertEqual(rr.barrier_makespan([[1, 1, 4], [2]], 2), 7)

    def test_efficiency_at_most_one_and_free_at_most_barrier(self):
        rng = random.Random(7)
        for _ in range(300):
            rounds = [sorted((rng.uniform(0.1, 10) for _ in range(rng.randint(1, 12))),
                             reverse=True) for _ in range(rng.randint(1, 6))]
            ranks = rng.randint(1, 9)
            r = rr.replay(rounds, ranks)
            self.assertLessEqual(r["efficiency"], 1 + 1e-12)
            self.assertLessEqual(r["free_efficiency"], 1 + 1e-12)
            self.assertLessEqual(r["free"], r["barrier"] * (1 + 1e-12))
            self.assertGreaterEqual(r["free"], r["work"] / ranks * (1 - 1e-12))


class Speculation(unittest.TestCase):
    COSTS = [{"cell": "0", "fixed_s": "0", "member_s": "1"},
             {"cell": "1", "fixed_s": "0", "member_s": "1"}]

    def test_ahead_items_fill_the_drain_and_stop_at_its_end(self):
        # 3 | 1 on 2 ranks: the round ends at 3; rank 1 trains a 2 s ahead item from 1 to 3
        # (finished), then nothing: the next one would start at the end.
        ahead = [{"left": 2.0}, {"left": 5.0}]
        self.assertEqual(rr.ahead_schedule([3.0, 1.0], ahead, 2), (3.0, 2.0))
        self.assertEqual([a["left"] for a in ahead], [0.0, 5.0])

    def test_hand_computed_rounds(self):
        # Round 0: cell 0 (2 runs, 2 s) | cell 1 (1 run, 1 s): ends at 2. Rank 1 then trains
        # cell 0's next 2 seeds (2 s, asked for by round 1) from 1 to 2: 1 s done, 1 s left.
        # Round 1 asks for them: the resumed item's 1 s on rank 0 -> ends at 1; meanwhile rank 1
        # trains cell 0's next seeds, which no round asks for: 1 s lost. Makespan 2 + 1 = 3
        # against 2 + 2 with barriers alone.
        rounds = [{0: (2, 1.0), 1: (1, 1.0)}, {0: (2, 1.0)}]
        self.assertEqual(rr.speculative_replay(rounds, self.COSTS, 2, 2, 10, split=False),
                         (3.0, 2.0, 1.0, 5.0))
        self.assertEqual(rr.barrier_makespan(rr.round_item_costs(rounds, self.COSTS, 2, False), 2),
                         4.0)
        # One rank never idles: the makespan is the work, nothing is trained ahead.
        self.assertEqual(rr.speculative_replay(rounds, self.COSTS, 1, 2, 10, split=False),
                         (5.0, 0.0, 0.0, 5.0))
        # Critical path: round 0's costliest run 1 s, round 1's 1 s.
        self.assertEqual(rr.critical_path(rounds, self.COSTS), 2.0)
        # max_seeds 2: cell 0 is at the cap after round 0, so only cell 1's second seed (1 s,
        # never asked for) is trained ahead.
        self.assertEqual(rr.speculative_replay(rounds, self.COSTS, 2, 2, 2, split=False)[1:],
                         (1.0, 1.0, 5.0))

    def test_cells_known_early_by_hand(self):
        # The comparisons rule: round 0 on 2 ranks is cell 2 (3 s) | cell 0 (1 s), cell 1 (1 s):
        # cells 0, 1, 2 finish at 1, 2, 3. Comparison 0 covers cells 0 and 1, comparison 1
        # cells 1 and 2. Comparison 0 names cell 0 (2 more seeds): known at 2, when cell 1 is
        # done; rank 1 trains it from 2 to the round's end at 3 (1 s of 2). Round 1 resumes it:
        # 1 s. Makespan 3 + 1 against 3 + 2 with barriers; the work asked for is 7 s, all of it
        # trained once; nothing is lost.
        costs = self.COSTS + [{"cell": "2", "fixed_s": "0", "member_s": "1"}]
        rounds = [{0: (1, 1.0), 1: (1, 1.0), 2: (3, 1.0)}, {0: (2, 1.0)}]
        covered = [{0, 1}, {1, 2}]
        self.assertEqual(rr.early_replay(rounds, costs, 2, 2, 10, covered, [{0: [0]}],
                                         split=False), (4.0, 1.0, 0.0, 7.0))
        # Named by comparison 1 instead, cell 0 is known only when cell 2 is done, at the
        # round's end: nothing ahead, 3 + 2.
        self.assertEqual(rr.early_replay(rounds, costs, 2, 2, 10, covered, [{0: [1]}],
                                         split=False), (5.0, 0.0, 0.0, 7.0))
        # Either comparison: the earlier one counts.
        self.assertEqual(rr.early_replay(rounds, costs, 2, 2, 10, covered, [{0: [1, 0]}],
                                         split=False)[0], 4.0)
        # The longest chain: comparison 0's round 0 (its costliest single run, 1 s) and the run
        # of cell 0 it named (1 s); comparison 1 named nothing: 1 s.
        self.assertEqual(rr.comparison_chain(rounds, costs, covered, [{0: [0]}]), 2.0)
        self.assertEqual(rr.comparison_chain(rounds, costs, covered, [{}]), 1.0)


class WorkPlanPort(unittest.TestCase):
    def test_split_by_hand(self):
        # 4 runs, fixed 1 s, member 1 s, 4 ranks: whole 5 s; 2 groups of 2: 3 s each (6 s of
        # work); 4 single runs: 2 s each (8 s). Shortest makespan 2: four items.
        cell = [wp.PlanCell(cell=0, fixed=1.0, member=1.0, runs=4)]
        self.assertEqual(wp.plan_work(cell, 4), [(0, 1)] * 4)
        self.assertEqual(wp.plan_work(cell, 4, split=False), [(0, 4)])
        # Within 100 % of the shortest (4 s) the cheapest is 2 groups (6 s of work, makespan 3).
        self.assertEqual(wp.plan_work(cell, 4, min_gain=1.0), [(0, 2), (0, 2)])
        # One rank: splitting only costs.
        self.assertEqual(wp.plan_work(cell, 1), [(0, 4)])

    def test_items_largest_first_ties_in_cell_order(self):
        cells = [wp.PlanCell(3, 1.0, 1.0, 2), wp.PlanCell(5, 2.0, 1.0, 3),
                 wp.PlanCell(8, 1.0, 1.0, 2)]
        self.assertEqual(wp.plan_work(cells, 1, split=False), [(5, 3), (3, 2), (8, 2)])


def row(run_id, wall):
    return {"run_id": run_id, "wall_time_s": str(wall), "status": "done"}


class ItemCosts(unittest.TestCase):
    COSTS = [{"cell": "0", "fixed_s": "2", "member_s": "1", "run_ids": "a b c d"},
             {"cell": "1", "fixed_s": "2", "member_s": "1", "run_ids": "e f g h"}]

    def test_stacks_scale_the_cost_model(self):
        # Round 0: cell 0's a, b in one stack of 6 s (3 s each stored): model 2 + 2 = 4 -> scale
        # 1.5; cell 1's e, f (one stack, 2 s each) and g (alone, 3 s): 7 s against model 4 + 3.
        # Round 1: cell 0's c alone, 4.5 s: model 3 -> scale 1.5.
        times = {"a": ("t0", "t1"), "b": ("t0", "t1"), "e": ("t0", "t2"), "f": ("t0", "t2"),
                 "g": ("t2", "t3"), "c": ("t4", "t5")}
        rounds = [[row("a", 3), row("b", 3), row("e", 2), row("f", 2), row("g", 3)],
                  [row("c", 4.5)]]
        cells = rr.round_cells(rounds, self.COSTS, times)
        self.assertEqual(cells, [{0: (2, 1.5), 1: (3, 1.0)}, {0: (1, 1.5)}])
        # Whole cells on 1 rank: cell 0 as trained (6 s), cell 1 as one stack: 2 + 3 = 5 s; in
        # plan order, the cost model's largest first (cell 1: 5 s estimated, cell 0: 4 s).
        costs = rr.round_item_costs(cells, self.COSTS, 1, split=False)
        self.assertEqual(costs, [[5.0, 6.0], [4.5]])
        # Without run times every cell and round is one stack: cell 1 then 7 / 5.
        self.assertAlmostEqual(rr.round_cells(rounds, self.COSTS, {})[0][1][1], 7 / 5)

    def test_failed_run_costs_nothing_and_foreign_run_is_named(self):
        cells = rr.round_cells([[row("a", 3), row("b", "nan")]], self.COSTS, {})
        self.assertEqual(cells, [{0: (2, 3 / 4)}])
        with self.assertRaisesRegex(ValueError, "run z is not in the sweep file's grid"):
            rr.round_cells([[row("z", 1)]], self.COSTS, {})


TINY_ADAPTIVE = """
name = "tiny-adaptive"
output = "tiny-adaptive.h5"
[data]
num_validation = 50
num_inference = 5
[training]
steps = 20
eval_every = 10
[grid]
systems = ["harmonic"]
models = ["node-rk2", "phnn-jr-rk2"]
sizes = ["small"]
n_train = [25, 26]
regularizers = ["none"]
seeds = "0-4"
[adaptive]
max_seeds = 15
batch = 5
rule = "comparisons"
comparisons = [
  ["harmonic/node-rk2/25/small/none", "harmonic/node-rk2/26/small/none"],
  ["harmonic/phnn-jr-rk2/25/small/none", "harmonic/node-rk2/25/small/none"],
]
"""


@unittest.skipUnless(os.access(phnn(), os.X_OK), f"no phnn binary at {phnn()}")
class WithBinary(unittest.TestCase):
    def test_port_plans_the_binary_s_items(self):
        for sweep, ranks in (("paper.toml", 128), ("paper.toml", 1024),
                             ("paper-adaptive.toml", 128), ("paper-adaptive.toml", 1024)):
            path = os.path.join(ROOT, "sweeps", sweep)
            cells = [wp.PlanCell(int(c["cell"]), float(c["fixed_s"]), float(c["member_s"]),
                                 int(c["members"]))
                     for c in run_csv("sweep", path, "--dry-run", "--cell-costs")]
            items = run_csv("sweep", path, "--dry-run", "--items", "--ranks", str(ranks))
            self.assertEqual(wp.plan_work(cells, ranks),
                             [(int(i["cell"]), int(i["runs"])) for i in items], (sweep, ranks))

    def test_rounds_of_a_small_adaptive_sweep(self):
        tmp = tempfile.mkdtemp(prefix="rounds-replay-")
        try:
            self.check_rounds(tmp)
        finally:
            shutil.rmtree(tmp)

    def check_rounds(self, tmp):
        sweep, results = os.path.join(tmp, "s.toml"), os.path.join(tmp, "s.h5")
        with open(sweep, "w") as f:
            f.write(TINY_ADAPTIVE)
        subprocess.run([phnn(), "sweep", sweep, "--out", results, "--quiet"], check=True,
                       capture_output=True)
        rounds = rr.runs_by_round(results)
        every = run_csv("reduce", results, "--per-run")
        self.assertEqual(sorted(r["run_id"] for rs in rounds for r in rs),
                         sorted(r["run_id"] for r in every if r["status"] != "pending"))
        self.assertGreaterEqual(len(rounds), 2)
        # Round 0: every cell's seeds 0-4; then 5 more per named cell, above its largest seed.
        top = {}
        for k, rows in enumerate(rounds):
            by_cell = {}
            for r in rows:
                by_cell.setdefault((r["model_label"], r["n_train"]), []).append(int(r["seed"]))
            for cell, seeds in by_cell.items():
                first = top.get(cell, -1) + 1
                self.assertEqual(sorted(seeds), list(range(first, first + 5)), (k, cell))
                top[cell] = first + 4
            if k == 0:
                self.assertEqual(len(by_cell), 4)
        # The cells of rounds 1, 2, ... are those the reducer says grew after rounds 0, 1, ...
        tables = subprocess.run([phnn(), "reduce", results], check=True, capture_output=True,
                                text=True).stdout
        grown = re.search(r"complete after round (\d+);.*after round 0, 1, \.\.\.: ([\d, ]+)\.",
                          tables)
        self.assertEqual(int(grown.group(1)), len(rounds) - 1)
        self.assertEqual([int(n) for n in grown.group(2).split(", ")],
                         [len({(r["model_label"], r["n_train"]) for r in rows})
                          for rows in rounds[1:]])
        # On 1 rank the replay plans the items the sweep trained: their costs are its wall times.
        costs = run_csv("sweep", sweep, "--dry-run", "--cell-costs")
        cells = rr.round_cells(rounds, costs, rr.item_times(results))
        r = rr.replay(rr.round_item_costs(cells, costs, 1), 1)
        measured = sum(float(x["wall_time_s"]) for rows in rounds for x in rows)
        self.assertAlmostEqual(r["work"], measured, delta=1e-9 * measured)
        self.assertEqual(r["items"], [len(c) for c in cells])
        self.assertAlmostEqual(r["efficiency"], 1.0)
        # The script's table: one row per rank count; 1 rank is busy all the time.
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            self.assertEqual(rr.main([results, sweep, "1,64"]), 0)
        text = out.getvalue()
        self.assertRegex(text, rf"\| 1 \| {len(rounds)} \| {sum(r['items'])} \| [^|]+ \| [^|]+ \| "
                               r"100\.0 % \| [^|]+ \| 100\.0 % \|")
        self.assertRegex(text, r"\| 64 \| .* %")
        self.assertIn("items per round on 1 rank: " + ", ".join(str(len(c)) for c in cells), text)


if __name__ == "__main__":
    unittest.main()
