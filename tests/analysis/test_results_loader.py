#!/usr/bin/env python3
"""Tests of analysis/results.py on real results files written by $PHNN: one row per run (pending
ones too), one column per setting, exact numbers, a categorical status, the traces.

    PHNN=build/phnn /usr/bin/python3 tests/analysis/test_results_loader.py
"""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, ROOT)
from analysis.results import load, traces  # noqa: E402

import h5py  # noqa: E402
import numpy as np  # noqa: E402

PHNN = os.environ.get("PHNN", os.path.join(ROOT, "build", "phnn"))


class Loader(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        # Shard 0 of 2 of the tiny sweep: one cell trained, the other's 3 runs pending.
        cls.path = os.path.join(cls.dir.name, "tiny.h5")
        subprocess.run([PHNN, "sweep", os.path.join(ROOT, "sweeps", "tiny.toml"), "--shard", "0/2",
                        "--out", cls.path, "--quiet"], check=True, capture_output=True)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_one_row_per_run_with_its_settings(self):
        runs = load(self.path)
        with h5py.File(self.path, "r") as f:
            ids = [s.decode().rstrip("\0") for s in f["runs/id"][:]]
            mse = dict(zip(ids, f["runs/mse"][:]))
            seeds = dict(zip(ids, f["runs/seed"][:]))
        self.assertEqual(sorted(runs.run_id), sorted(ids))
        self.assertEqual(list(runs.status.cat.categories), ["pending", "done", "diverged", "failed"])
        self.assertEqual(sorted(runs.status.value_counts()[["done", "pending"]]), [3, 3])
        for key in ("system", "model", "integrator", "size", "n_train", "regularizer", "seed",
                    "steps", "learning_rate", "batch_size", "damping", "model_label", "mse"):
            self.assertIn(key, runs.columns)
        self.assertEqual(runs.n_train.dtype, np.int64)
        self.assertEqual(runs.seed.dtype, np.int64)
        self.assertEqual(runs.learning_rate.dtype, np.float64)
        self.assertEqual(set(runs.model_label), {"PHNN-JR-RK2", "NODE-RK2"})
        for row in runs.itertuples():
            self.assertEqual(row.seed, seeds[row.run_id])
            if row.status == "done":  # bitwise the stored double
                self.assertEqual(row.mse, mse[row.run_id])
            else:
                self.assertTrue(np.isnan(row.mse))
        # The file's own columns, one per setting (h5py alone): the loader's values, bitwise.
        with h5py.File(self.path, "r") as f:
            order = {rid: k for k, rid in enumerate(ids)}
            for key in ("learning_rate", "n_train", "seed", "damping"):
                stored = f["runs/config/" + key][:]
                for row in runs.itertuples():
                    self.assertEqual(stored[order[row.run_id]], getattr(row, key), key)
            self.assertEqual(f["runs/config/model"][0].decode().rstrip("\0") in ("phnn-jr", "node"),
                             True)
        medians = runs.groupby(["model", "n_train"]).mse.median()
        self.assertEqual(int(medians.notna().sum()), 1)  # the pending cell has no median

    def test_traces_are_every_validation_point(self):
        t = traces(self.path)
        with h5py.File(self.path, "r") as f:
            self.assertEqual(len(t), int(f["runs/trace_length"][:].sum()))
        self.assertEqual(list(t.columns), ["run_id", "step", "elapsed_s", "train_loss",
                                           "validation_loss", "kappa", "sigma_max", "rho"])
        self.assertEqual(sorted(set(t.step)), [0, 10, 20])

    def test_the_reducers_quantiles_are_the_stability_checks(self):
        # analysis/paper_claims.py --stability recomputes the reducer's median/IQR per resample:
        # on the original seeds it must give the reducer's numbers (printed to 7 digits).
        sys.path.insert(0, os.path.join(ROOT, "analysis"))
        import paper_claims as pc
        runs = load(self.path)
        stats = pc.reduce_csv(self.path)
        checked = 0
        for row in stats:
            if row["median"] in ("", "nan"):
                continue
            cell = runs[(runs.model_label == row["model"]) & runs.status.isin(["done", "diverged"])]
            values = np.sort(cell.mse.to_numpy(dtype=float))
            for q, key in ((0.5, "median"), (0.25, "q25"), (0.75, "q75")):
                self.assertAlmostEqual(float(pc.quantile(values, q)) / float(row[key]), 1.0, 6)
            checked += 1
        self.assertEqual(checked, 1)

    def test_weights_come_named_and_shaped(self):
        from analysis.results import weights
        runs = load(self.path)
        done = runs[runs.status == "done"]
        with h5py.File(self.path, "r") as f:
            ids = [s.decode().rstrip("\0") for s in f["runs/id"][:]]
            offsets, lengths = f["runs/weights_offset"][:], f["runs/weights_length"][:]
            flat = f["weights"][:]
        for row in done.itertuples():
            w = weights(self.path, row.run_id)
            k = ids.index(row.run_id)
            self.assertEqual(sum(a.size for a in w.values()), lengths[k])
            self.assertEqual(lengths[k], row.parameter_count)
            joined = np.concatenate([a.reshape(-1) for a in w.values()])
            self.assertTrue(np.array_equal(joined, flat[offsets[k]:offsets[k] + lengths[k]]))
            first = next(iter(w))
            self.assertEqual(first, "l_h.0.weight" if row.model == "phnn-jr" else "node.0.weight")
            self.assertEqual(w[first].shape[0], 2 if row.model == "phnn-jr" else 3)  # fan_in
        pending = runs[runs.status == "pending"].run_id.iloc[0]
        with self.assertRaisesRegex(KeyError, "no stored weights"):
            weights(self.path, pending)

    def test_status_is_an_enum_and_strings_are_utf8(self):
        with h5py.File(self.path, "r") as f:
            self.assertEqual(h5py.check_enum_dtype(f["runs/status"].dtype),
                             {"pending": 0, "done": 1, "diverged": 2, "failed": 3})
            self.assertEqual(f["runs/system"].id.get_type().get_cset(), h5py.h5t.CSET_UTF8)

    def test_a_file_of_the_earlier_format_loads(self):
        from analysis.results import weights
        old = os.path.join(ROOT, "tests", "fixtures", "results-2026-11-25.h5")
        runs = load(old)
        self.assertEqual(len(runs), 4)
        self.assertEqual(list(runs.status.unique()), ["done"])
        self.assertEqual(sorted(runs.model_label.unique()), ["NODE-RK2", "PHNN-JR-RK2"])
        with self.assertRaisesRegex(KeyError, "written before weight names"):
            weights(old, runs.run_id.iloc[0])

    def test_a_missing_file_is_named(self):
        with self.assertRaisesRegex(FileNotFoundError, "nowhere.h5"):
            load(os.path.join(self.dir.name, "nowhere.h5"))


if __name__ == "__main__":
    unittest.main()
