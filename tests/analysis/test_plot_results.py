#!/usr/bin/env python3
"""Unit tests of analysis/plot_results.py's choices: column order, median seed, status counts.

    /usr/bin/python3 tests/analysis/test_plot_results.py
"""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import plot_results as pr  # noqa: E402


def runs_of(**columns):
    n = len(next(iter(columns.values())))
    runs = {"rows": np.arange(n), "studies": ["I"] * n}
    runs.update({k: (np.array(v) if k in ("n_train", "seed", "status", "mse") else list(v))
                 for k, v in columns.items()})
    return runs


class ColumnOrder(unittest.TestCase):
    def test_numeric_not_string_length(self):
        runs = runs_of(n_train=[400, 25, 100, 25])
        self.assertEqual(pr.column_order(runs, "n_train", runs["rows"], {}, "I"), [25, 100, 400])

    def test_known_orders(self):
        runs = runs_of(size=["large", "small", "medium"], regularizer=["sr", "none", "cn"])
        self.assertEqual(pr.column_order(runs, "size", runs["rows"], {}, "II"),
                         ["small", "medium", "large"])
        self.assertEqual(pr.column_order(runs, "regularizer", runs["rows"], {}, "III"),
                         ["none", "cn", "sr"])

    def test_sweep_file_order_wins(self):
        runs = runs_of(regularizer=["none", "cn", "sn"])
        sweep = {"study": {"III": {"regularizers": ["sn", "none", "cn"]}}}
        self.assertEqual(pr.column_order(runs, "regularizer", runs["rows"], sweep, "III"),
                         ["sn", "none", "cn"])


class MedianSeed(unittest.TestCase):
    def test_lower_median_and_inf_last(self):
        runs = runs_of(seed=[0, 1, 2, 3], status=[1, 1, 2, 1], mse=[3.0, 1.0, np.inf, 2.0])
        self.assertEqual(pr.median_seed_row(runs, [0, 1, 2, 3]), 3)  # sorted 1, 2, 3, inf

    def test_pending_skipped(self):
        runs = runs_of(seed=[0, 1, 2], status=[0, 1, 1], mse=[np.nan, 5.0, 4.0])
        self.assertEqual(pr.median_seed_row(runs, [0, 1, 2]), 2)


class Labels(unittest.TestCase):
    def test_model_labels_and_fixed_colours(self):
        self.assertEqual(pr.model_label("phnn-jr", "dg4"), "PHNN-JR-DG4")
        self.assertEqual(pr.model_label("node", "rk4"), "NODE-RK4")
        self.assertEqual(len(set(pr.MODEL_COLOURS.values())), len(pr.MODEL_COLOURS))

    def test_status_note_counts_everything(self):
        runs = runs_of(status=[1, 1, 2, 3, 0, 0], mse=[1.0, np.inf, np.inf, np.nan, np.nan, np.nan])
        self.assertEqual(pr.status_note(runs, range(6)),
                         "3 of 6 runs drawn, 1 diverged in training, 1 with a diverged rollout "
                         "(MSE = +inf), 1 failed (not drawn), 2 pending (not drawn)")


class SizeTrajectories(unittest.TestCase):
    def test_the_papers_model_at_each_size_nearest_n_train_25(self):
        runs = runs_of(system=["duffing"] * 6 + ["self-sustained"] * 2,
                       model=["PHNN-S-DG"] * 5 + ["PHNN-S-RK2"] + ["PHNN-JR-DG"] * 2,
                       regularizer=["none"] * 4 + ["cn", "none", "none", "none"],
                       size=["large", "small", "small", "medium", "medium", "medium",
                             "small", "small"],
                       n_train=[100, 100, 400, 100, 100, 100, 25, 25])
        groups, n_train = pr.size_trajectory_rows(runs, "duffing")
        self.assertEqual(n_train, 100)  # the only N_train with more than one size
        self.assertEqual(groups, {"small": [1], "medium": [3], "large": [0]})  # cn, RK2 left out
        self.assertEqual(pr.size_trajectory_rows(runs, "self-sustained"), ({}, None))


class RecordedData(unittest.TestCase):
    """system_states reads whether a data set is recorded and its figure inputs; the legend
    gathers the recording, the rollouts and the inputs."""

    def data_file(self, split, with_h, inputs):
        import h5py
        f = h5py.File("recorded.h5", "w", driver="core", backing_store=False)
        g = f.create_group("data/pend")
        g.attrs["state_names"], g.attrs["state_units"], g.attrs["input_names"] = "q,p", "rad,x", "u"
        g.attrs["system_file"] = 'states = ["q", "p"]\n' + ('H = "p^2/2"\n' if with_h else "")
        if split:
            g.attrs["split"] = "blocks: ..."
        if inputs:
            g.create_dataset("inference/inputs", data=np.arange(3 * 5).reshape(3, 5, 1) * 1.0)
        return f

    def test_recorded_and_inputs(self):
        with self.data_file(split=True, with_h=True, inputs=True) as f:
            states = pr.system_states(f, "pend")
            self.assertTrue(states["recorded"])
            self.assertEqual(states["inputs"]["names"], ["u"])
            self.assertEqual(states["inputs"]["values"].shape, (2, 5, 1))  # figures: trajectories 0, 1
        with self.data_file(split=False, with_h=False, inputs=False) as f:
            states = pr.system_states(f, "pend")
            self.assertTrue(states["recorded"])  # structure only: a recording
            self.assertIsNone(states["inputs"])
        with self.data_file(split=False, with_h=True, inputs=False) as f:
            self.assertFalse(pr.system_states(f, "pend")["recorded"])

    def test_legend_gathers_the_lines_of_the_first_and_the_input_axes(self):
        fig, axes = pr.plt.subplots(2, 3, squeeze=False)
        axes[0, 0].plot([0, 1], [0, 1], label="recording")
        axes[0, 0].plot([0, 1], [1, 0], label="PHNN-S-DG")
        axes[0, 2].plot([0, 1], [0, 0], label="input u")
        pr.figure_legend(axes)
        texts = [t.get_text() for t in axes[0, -1].get_legend().get_texts()]
        self.assertEqual(texts, ["recording", "PHNN-S-DG", "input u"])
        pr.plt.close(fig)


if __name__ == "__main__":
    unittest.main()
