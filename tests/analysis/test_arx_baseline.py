#!/usr/bin/env python3
"""Unit tests of analysis/arx_baseline.py: the least-squares fit recovers a linear system that
made the data, its simulation is exact there, and the error is Eq. 31 computed by hand on a
small case.

    /usr/bin/python3 tests/analysis/test_arx_baseline.py
"""
import os
import sys
import tempfile
import unittest

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import arx_baseline as arx  # noqa: E402

A = np.array([[0.99, 0.01], [-0.02, 0.98]])
B = np.array([[0.0], [0.01]])
C = np.array([0.001, -0.002])


def step(x, u):
    return A @ x + B @ u + C


class Arx(unittest.TestCase):
    def test_recovers_a_linear_system_and_simulates_it_exactly(self):
        rng = np.random.default_rng(3)
        x = rng.uniform(-1, 1, (200, 2))
        u = rng.uniform(-1, 1, (200, 1))
        x_next = np.array([step(a, b) for a, b in zip(x, u)])
        theta = arx.fit(x, u, x_next)
        np.testing.assert_allclose(theta[:2].T, A, atol=1e-12)
        np.testing.assert_allclose(theta[2:3].T, B, atol=1e-12)
        np.testing.assert_allclose(theta[3], C, atol=1e-12)
        inputs = rng.uniform(-1, 1, (3, 50, 1))
        states = np.empty((3, 50, 2))
        for i in range(3):
            states[i, 0] = rng.uniform(-1, 1, 2)
            for n in range(1, 50):
                states[i, n] = step(states[i, n - 1], inputs[i, n - 1])
        self.assertLess(arx.window_errors(theta, states, inputs).max(), 1e-24)

    def test_eq31_by_hand_on_a_file(self):
        # x_n+1 = x_n + u_n exactly (theta: identity, B = 1, c = 0); a window whose recorded
        # states are off by (0.1, 0) at n = 1 and (0, 0.2) at n = 2: e = (0.01 + 0.04) / 2.
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "d.h5")
            rng = np.random.default_rng(5)
            x, u = rng.uniform(-1, 1, (10, 2)), rng.uniform(-1, 1, (10, 2))
            with h5py.File(path, "w") as f:
                f["train/x"], f["train/x_next"], f["train/u"] = x, x + u, u
                f["inference/states"] = np.array([[[0.0, 0.0], [1.1, 1.0], [2.0, 2.2]]])
                f["inference/inputs"] = np.array([[[1.0, 1.0], [1.0, 1.0], [0.0, 0.0]]])
            errors = arx.main([path])
        self.assertAlmostEqual(float(errors[0]), (0.01 + 0.04) / 2, places=10)


if __name__ == "__main__":
    unittest.main()
