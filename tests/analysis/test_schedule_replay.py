#!/usr/bin/env python3
"""Unit tests of analysis/schedule_replay.py: measured cost ratios and the replayed schedule.

    /usr/bin/python3 tests/analysis/test_schedule_replay.py
"""
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import schedule_replay as sr  # noqa: E402


def cell(index, estimated, system="duffing", model="PHNN-S-DG", n_train="25"):
    return {"cell": str(index), "system": system, "model": model, "size": "small",
            "n_train": n_train, "regularizer": "none", "estimated_s": str(estimated)}


def item(cell_index, estimated):
    return {"cell": str(cell_index), "estimated_s": str(estimated)}


class CostRatios(unittest.TestCase):
    def test_ratio_of_the_sums_per_configuration(self):
        measured = [(cell(0, 10.0), 15.0), (cell(1, 30.0), 25.0),  # same configuration
                    (cell(2, 4.0, system="harmonic"), 2.0)]
        ratios = sr.cost_ratios(measured)
        self.assertAlmostEqual(ratios[("duffing", "PHNN-S-DG", "small", "25", "none")], 1.0)
        self.assertAlmostEqual(ratios[("harmonic", "PHNN-S-DG", "small", "25", "none")], 0.5)

    def test_unmeasured_configuration_is_named(self):
        ratios = {("duffing", "PHNN-S-DG", "small", "25", "none"): 2.0}
        self.assertEqual(sr.cell_ratios([cell(7, 1.0)], ratios), {7: 2.0})
        with self.assertRaisesRegex(KeyError, r"cell 3 \(duffing, PHNN-S-DG, small, 100, none\)"):
            sr.cell_ratios([cell(3, 1.0, n_train="100")], ratios)


class Replay(unittest.TestCase):
    def test_list_schedule_follows_the_given_order(self):
        # 2 ranks: 3 -> r0, 3 -> r1, 2 -> r0 (5), 2 -> r1 (5); in the other order 2, 2, 3, 3: 5, 5.
        self.assertEqual(sr.list_schedule_makespan([3, 3, 2, 2], 2), 5)
        # 4 first is not always best: 1, 1, 4 on 2 ranks gives 1 + 4 = 5 (4 first: 4).
        self.assertEqual(sr.list_schedule_makespan([1, 1, 4], 2), 5)
        self.assertEqual(sr.list_schedule_makespan([4, 1, 1], 2), 4)

    def test_a_cell_twice_as_expensive_as_estimated(self):
        # Cells 0 (8 s, split into two 4-s items) and 1 (4 s, whole) on 3 ranks: simulated
        # makespan 4, efficiency 12 / (3 x 4) = 1. Cell 1 measured at twice its estimate: the
        # replayed makespan is 8 (its item), efficiency (8 + 8) / (3 x 8); bound: the largest
        # item, 8 -> the same.
        cells = [cell(0, 8.0), cell(1, 4.0)]
        items = [item(0, 4.0), item(0, 4.0), item(1, 4.0)]
        simulated, replayed, bound = sr.replay(items, cells, {0: 1.0, 1: 2.0}, 3)
        self.assertAlmostEqual(simulated, 1.0)
        self.assertAlmostEqual(replayed, 16.0 / 24.0)
        self.assertAlmostEqual(bound, 16.0 / 24.0)

    def test_exact_costs_replay_the_simulation(self):
        cells = [cell(0, 9.0), cell(1, 5.0), cell(2, 3.0)]
        items = [item(0, 5.0), item(0, 5.0), item(1, 5.0), item(2, 3.0)]
        simulated, replayed, _ = sr.replay(items, cells, {0: 1.0, 1: 1.0, 2: 1.0}, 2)
        self.assertAlmostEqual(simulated, replayed)
        self.assertAlmostEqual(simulated, 17.0 / (2 * 10.0))  # 5 + 5 | 5 + 3 -> 10


if __name__ == "__main__":
    unittest.main()
