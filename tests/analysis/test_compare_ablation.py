#!/usr/bin/env python3
"""Unit tests of analysis/compare_ablation.py: which cells are compared, and the seed counts.

    /usr/bin/python3 tests/analysis/test_compare_ablation.py
"""
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import compare_ablation as ca  # noqa: E402


def run(studies, size, n_train, mse, status="done"):
    return {"studies": studies, "system": "duffing", "model_label": "PHNN-S-DG", "size": size,
            "n_train": str(n_train), "regularizer": "none", "mse": str(mse), "status": status}


def row(study, axis, column, median):
    return {"study": study, "system": "duffing", "model": "PHNN-S-DG", "axis": axis,
            "column": column, "median": str(median), "ci_low": str(median / 2),
            "ci_high": str(median * 2)}


class Cells(unittest.TestCase):
    def setUp(self):
        self.saved = ca.reduce_csv

    def tearDown(self):
        ca.reduce_csv = self.saved

    def fake(self, runs, rows):
        ca.reduce_csv = lambda path, *extra: runs if extra == ("--per-run",) else rows

    def test_a_paper_like_file_counts_the_seeds_of_each_study(self):
        # Study I varies N_train (small), Study II the size (N_train 25); the small / 25 runs are
        # in both. Study I's N_train 25 column counts only its small runs, not the large ones.
        runs = [run("I,II", "small", 25, 3.0), run("I,II", "small", 25, 0.1),
                run("II", "large", 25, 5.0), run("II", "large", 25, 7.0, "diverged"),
                run("II", "large", 25, 9.0, "failed"), run("I", "small", 100, 0.01)]
        rows = [row("I", "n_train", "25", 1.0), row("I", "n_train", "100", 0.01),
                row("II", "size", "small", 1.0), row("II", "size", "large", 6.0)]
        self.fake(runs, rows)
        out = ca.cells("paper.h5", threshold=1.0)
        self.assertEqual(out[("duffing", "PHNN-S-DG", "n_train", "25")], (1.0, 0.5, 2.0, 1, 2))
        self.assertEqual(out[("duffing", "PHNN-S-DG", "size", "large")], (6.0, 3.0, 12.0, 2, 2))
        self.assertEqual(len(out), 4)

    def test_a_one_column_table_takes_its_only_n_train(self):
        self.fake([run("grid", "small", 25, 2.0)], [row("grid", "", "MSE", 2.0)])
        self.assertEqual(ca.cells("a.h5", threshold=1.0),
                         {("duffing", "PHNN-S-DG", "n_train", "25"): (2.0, 1.0, 4.0, 1, 1)})

    def test_rows_sort_by_axis_then_number(self):
        keys = [("d", "M", "size", "large"), ("d", "M", "n_train", "100"),
                ("d", "M", "n_train", "25")]
        self.assertEqual([k[3] for k in sorted(keys, key=ca.sort_key)], ["25", "100", "large"])
        self.assertEqual(ca.column_text("size", "large"), "size=large")
        self.assertEqual(ca.column_text("n_train", "25"), "25")


if __name__ == "__main__":
    unittest.main()
