#!/usr/bin/env python3
"""Unit tests of analysis/plot_eval_errors.py: the summary against numpy on a synthetic CSV of
`phnn eval --errors`, the figure files, and a CSV of another kind refused.

    /usr/bin/python3 tests/analysis/test_plot_eval_errors.py
"""
import os
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import plot_eval_errors as pe  # noqa: E402


def write_csv(path, runs):
    """runs: {(run_id, model, integrator, seed): [errors]}; mse = their mean (Eq. 31)."""
    with open(path, "w") as f:
        f.write(",".join(pe.COLUMNS) + "\n")
        for (run_id, model, integrator, seed), errors in runs.items():
            for k, e in enumerate(errors):
                f.write(f"{run_id},pendulum,{model},{integrator},small,25,none,{seed},{2900 + k},0,"
                        f"{e!r},{np.mean(errors)!r}\n")


class Summary(unittest.TestCase):
    def test_medians_and_iqr_match_numpy(self):
        rng = np.random.default_rng(1)
        runs = {(f"r{s}", "phnn-s", "dg", s): list(rng.lognormal(-6, 1, 7)) for s in range(5)}
        runs.update({(f"n{s}", "node", "rk2", s): list(rng.lognormal(-4, 1, 7)) for s in range(4)})
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "chirp.csv")
            write_csv(path, runs)
            table = pe.summary(pe.load([path])).set_index("model")
            pe.plot(pe.load([path]), os.path.join(tmp, "fig", "chirp"), "t")
            for ext in ("pdf", "png"):
                self.assertGreater(os.path.getsize(os.path.join(tmp, "fig", f"chirp.{ext}")), 1000)
        s_errors = np.concatenate([v for k, v in runs.items() if k[1] == "phnn-s"])
        s_mse = [np.mean(v) for k, v in runs.items() if k[1] == "phnn-s"]
        row = table.loc["PHNN-S-DG"]
        self.assertEqual(row.seeds, 5)
        self.assertEqual(row.trajectories, 7)
        self.assertAlmostEqual(row.median_error, float(np.median(s_errors)), delta=1e-15)
        self.assertAlmostEqual(row.median_mse, float(np.median(s_mse)), delta=1e-15)
        q25, q75 = np.percentile(s_mse, [25, 75])
        self.assertAlmostEqual(row.iqr_mse, q75 - q25, delta=1e-15)
        self.assertEqual(table.loc["NODE-RK2"].seeds, 4)

    def test_another_csv_is_refused_naming_the_file(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "other.csv")
            with open(path, "w") as f:
                f.write("a,b\n1,2\n")
            with self.assertRaises(SystemExit) as stop:
                pe.load([path])
            self.assertIn("other.csv: not a `phnn eval --errors` CSV", str(stop.exception))


if __name__ == "__main__":
    unittest.main()
