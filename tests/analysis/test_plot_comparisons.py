#!/usr/bin/env python3
"""analysis/plot_comparisons.py (through analysis/plot_results.py): the P(improvement) matrices
and the performance profiles.  Unit tests on made-up values; with a phnn binary, a 60-run sweep
trained here, plotted, its figures checked to exist (PNG and PDF) and the profile values at a few
tau checked against the shares counted here from /runs with h5py.

    /usr/bin/python3 tests/analysis/test_plot_comparisons.py [PHNN]
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

try:
    import h5py
    import numpy as np
except ImportError:
    print("h5py/numpy missing: skipped")
    sys.exit(77)

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "analysis"))
import plot_comparisons as pcmp  # noqa: E402

PHNN = os.path.abspath(sys.argv.pop(1)) if len(sys.argv) > 1 else None

SWEEP = """name = "profiles"
[data]
num_validation = 20
num_inference = 3
[training]
steps = 20
eval_every = 10
[grid]
systems = ["harmonic", "duffing"]
models = ["node-rk2", "phnn-s-dg", "phnn-jr-rk2"]
sizes = ["small"]
regularizers = ["none"]
seeds = "0-4"
[study.I]
n_train = [25, 100]
"""


class Matrices(unittest.TestCase):
    def test_pairs_of_models_in_a_column_both_ways_columns_of_a_row_left_out(self):
        rows = [{"a": "I/duffing/NODE-RK2/25", "b": "I/duffing/PHNN-S-DG/25", "p_a_less": "0.2"},
                {"a": "I/duffing/NODE-RK2/100", "b": "I/duffing/NODE-RK2/25", "p_a_less": "0.9"}]
        m = pcmp.improvement_matrices(rows)
        self.assertEqual(list(m), [("I", "duffing", "25")])
        self.assertEqual(m[("I", "duffing", "25")][("NODE-RK2", "PHNN-S-DG")], 0.2)
        self.assertAlmostEqual(m[("I", "duffing", "25")][("PHNN-S-DG", "NODE-RK2")], 0.8)


class Profiles(unittest.TestCase):
    def test_shares_and_diverged_runs(self):
        taus = np.array([0.5, 1.0, 2.5, 10.0])
        share, low, high = pcmp.profile([1.0, 2.0, 3.0, np.inf], [0, 1, 2, 3], taus)
        np.testing.assert_array_equal(share, [0.0, 0.25, 0.5, 0.75])  # inf never <= tau
        self.assertTrue(np.all(low <= high))

    def test_one_value_per_seed_gives_no_band(self):
        share, low, high = pcmp.profile([1.0, 1.0, 4.0, 4.0], [0, 0, 0, 0], np.array([2.0]))
        self.assertEqual((share[0], low[0], high[0]), (0.5, 0.5, 0.5))  # one seed: no spread

    def test_taus_span_the_finite_positive_values(self):
        taus = pcmp.profile_taus(np.array([np.inf, 1e-3, 10.0, np.nan, 0.0]))
        self.assertEqual(taus.size, pcmp.PROFILE_POINTS)
        self.assertAlmostEqual(taus[0], 1e-3)
        self.assertAlmostEqual(taus[-1], 10.0)


@unittest.skipIf(PHNN is None, "needs the phnn binary")
class OnTrainedFile(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="phnn_profiles_")
        sweep = os.path.join(cls.dir, "profiles.toml")
        with open(sweep, "w") as f:
            f.write(SWEEP)
        cls.path = os.path.join(cls.dir, "profiles.h5")
        subprocess.run([PHNN, "sweep", sweep, "--out", cls.path], check=True,
                       stdout=subprocess.DEVNULL)
        cls.out = os.path.join(cls.dir, "figs")
        subprocess.run([sys.executable, os.path.join(ROOT, "analysis", "plot_results.py"),
                        cls.path, cls.out], check=True, stdout=subprocess.DEVNULL,
                       env=dict(os.environ, PHNN=PHNN))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_the_figures_exist_as_png_and_pdf(self):
        for stem in ("profile_harmonic", "profile_duffing", "pimprove_I_harmonic",
                     "pimprove_I_duffing"):
            for ext in (".png", ".pdf"):
                self.assertGreater(os.path.getsize(os.path.join(self.out, stem + ext)), 1000, stem)

    def test_profile_values_are_the_shares_of_runs_below_tau(self):
        with h5py.File(self.path, "r") as f:
            r = f["runs"]
            system = [v.decode() for v in r["system"][()]]
            model = [f"{m.decode()}|{i.decode()}" for m, i in zip(r["model"][()],
                                                                   r["integrator"][()])]
            status, mse = r["status"][()], r["mse"][()]
        mse = np.where(status == 2, np.inf, mse)
        names = {"node|rk2": "NODE-RK2", "phnn-s|dg": "PHNN-S-DG", "phnn-jr|rk2": "PHNN-JR-RK2"}
        checked = 0
        for sys_name in ("harmonic", "duffing"):
            rows = np.genfromtxt(os.path.join(self.out, f"profile_{sys_name}.csv"), delimiter=",",
                                 names=True, dtype=None, encoding=None)
            for k in (3, 47, 60, 93, len(rows) - 1):  # all three models
                label, tau, share = rows["model"][k], rows["tau"][k], rows["share"][k]
                mine = [mse[i] for i in range(len(mse)) if system[i] == sys_name
                        and names[model[i]] == label and status[i] in (1, 2)
                        and not np.isnan(mse[i])]
                self.assertEqual(len(mine), 10)  # 2 columns x 5 seeds
                self.assertEqual(share, sum(v <= tau for v in mine) / len(mine), (label, tau))
                self.assertLessEqual(rows["low"][k], rows["high"][k])
                checked += 1
        self.assertEqual(checked, 10)


if __name__ == "__main__":
    unittest.main()
