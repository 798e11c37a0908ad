#!/usr/bin/env python3
"""Unit tests of analysis/cost_model_check.py: joining estimated cells with measured runs.

    /usr/bin/python3 tests/analysis/test_cost_model_check.py
"""
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import cost_model_check as cmc  # noqa: E402


def cell(model, estimated, ids, reg="none"):
    return {"model": model, "size": "small", "regularizer": reg, "estimated_s": str(estimated),
            "run_ids": " ".join(ids)}


def run(run_id, wall, status="done"):
    return {"run_id": run_id, "wall_time_s": str(wall), "status": status}


class MeasuredCells(unittest.TestCase):
    def test_sums_the_runs_of_complete_cells_only(self):
        estimates = [cell("A", 10.0, ["a", "b"]), cell("B", 4.0, ["c", "d"])]
        runs = [run("a", 3.0), run("b", 2.5, "diverged"), run("c", 1.0), run("d", 9.0, "failed")]
        cells, incomplete = cmc.measured_cells(estimates, runs)
        self.assertEqual(incomplete, 1)  # d failed: its cell is left out
        self.assertEqual([(c["model"], m) for c, m in cells], [("A", 5.5)])

    def test_table_ratios(self):
        cells = [(cell("A", 10.0, ["a"]), 5.0), (cell("A", 10.0, ["b"]), 15.0),
                 (cell("B", 2.0, ["c"]), 2.0)]
        text = cmc.table(cells, 0)
        self.assertIn("| A | small | none | 2 | 20 | 20 | 1.00 (0.50–1.50) | 1.00 |", text)
        self.assertIn("| B | small | none | 1 | 2 | 2 | 1.00 (1.00–1.00) | 1.00 |", text)
        self.assertIn("measured / estimated 1.00.", text)


if __name__ == "__main__":
    unittest.main()
