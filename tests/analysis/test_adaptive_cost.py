#!/usr/bin/env python3
"""Unit tests of analysis/adaptive_cost.py: seeds per cell, rounds paying the fixed part, and the
cost against every cell at max_seeds.

    /usr/bin/python3 tests/analysis/test_adaptive_cost.py
"""
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import adaptive_cost as ac  # noqa: E402


def run(model, seed, wall=1.0):
    return {"system": "duffing", "model_label": model, "size": "small", "n_train": "25",
            "regularizer": "none", "seed": str(seed), "wall_time_s": str(wall)}


def cost(model, fixed, member):
    return {"system": "duffing", "model": model, "size": "small", "n_train": "25",
            "regularizer": "none", "fixed_s": str(fixed), "member_s": str(member)}


class Summarize(unittest.TestCase):
    def test_seeds_rounds_and_ratios(self):
        # A stopped after round 0 (10 seeds), B had two more rounds of 10 (30 seeds).
        runs = [run("A", s) for s in range(10)] + [run("B", s) for s in range(30)]
        costs = [cost("A", 2.0, 1.0), cost("B", 2.0, 1.0)]
        s = ac.summarize(runs, costs, initial=10, batch=10, max_seeds=40)
        self.assertEqual(s["runs"], 40)
        self.assertEqual(dict(s["seeds"]), {("duffing", "A", "small", "25", "none"): 10,
                                            ("duffing", "B", "small", "25", "none"): 30})
        self.assertAlmostEqual(s["measured"], 40.0)
        # Model: A 1 round: 2 + 10; B 3 rounds: 3 x 2 + 30; full: 2 x (2 + 40).
        self.assertAlmostEqual(s["model_trained"], 48.0)
        self.assertAlmostEqual(s["model_full"], 84.0)
        # Measured, scaled per cell by full / trained: A 10 x 42/12, B 30 x 42/36.
        self.assertAlmostEqual(s["scaled_full"], 10 * 42 / 12 + 30 * 42 / 36)
        self.assertIn("1 at 10, 1 at 30", ac.report(s, 40))


if __name__ == "__main__":
    unittest.main()
