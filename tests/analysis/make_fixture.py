#!/usr/bin/env python3
"""Write a small synthetic phnn-results file (format_version 1) for the plotting smoke test.

    /usr/bin/python3 tests/analysis/make_fixture.py OUT.h5

Two systems, models node-rk2, phnn-s-dg, phnn-jr-rk4, phnn-s-dg4, three seeds, Study I (n_train
25, 100, 400), Study II (small, medium) and Study III (none, cn), with every status: done, done with MSE = +inf (a diverged
rollout), diverged (training), failed and pending.  Numbers are random, not physics.
"""
import sys

import h5py
import numpy as np

SYSTEMS = ["harmonic", "duffing"]
MODELS = [("node", "rk2"), ("phnn-s", "dg"), ("phnn-jr", "rk4"), ("phnn-s", "dg4")]
SWEEP = """name = "fixture"
[grid]
systems = ["harmonic", "duffing"]
sizes = ["small"]
n_train = [25]
regularizers = ["none"]
seeds = [0, 1, 2]
[study.I]
title = "Impact of the number of training points"
n_train = [25, 100, 400]
[study.II]
title = "Impact of the model size"
sizes = ["small", "medium"]
[study.III]
title = "Impact of the Jacobian regularization"
regularizers = ["none", "cn"]
"""


def run_list():
    runs = []
    for system in SYSTEMS:
        for model, integrator in MODELS:
            for n_train, reg, studies, size in ((25, "none", "I,II,III", "small"),
                                                (100, "none", "I", "small"),
                                                (400, "none", "I", "small"),
                                                (25, "cn", "III", "small"),
                                                (25, "none", "II", "medium")):
                for seed in range(3):
                    runs.append((system, model, integrator, n_train, reg, studies, seed, size))
    return runs


def main(path):
    rng = np.random.default_rng(1)
    runs = run_list()
    R, T, F = len(runs), 12, 101
    status = np.ones(R, dtype=np.int64)
    mse = 10.0 ** rng.uniform(-4, 1, R)
    status[[3, 40]] = 2          # diverged in training
    mse[[3, 40]] = np.nan
    mse[[7, 8]] = np.inf         # done, but a rollout diverged
    status[[11, 60]] = 3         # failed
    mse[[11, 60]] = np.nan
    status[-6:] = 0              # pending
    mse[-6:] = np.nan
    trace = np.full((R, T, 7), np.nan)
    steps = np.arange(T) * 100.0
    for i in range(R):
        decay = np.exp(-steps / rng.uniform(200, 600))
        trace[i, :, 0] = steps
        trace[i, :, 1] = steps * 0.01
        trace[i, :, 2] = 2 * decay + 1e-3
        trace[i, :, 3] = 2.2 * decay + 2e-3
        trace[i, :, 4] = 1 + 5 * decay * rng.uniform(0.5, 2)
        trace[i, :, 5] = 6 - 5 * decay
        trace[i, :, 6] = 1 + decay
    trace_length = np.where(status == 0, 0, T)
    trace_length[3] = 5          # diverged after 5 points
    t = np.arange(F) / 100.0
    fig = {}
    for key, e in (("05", 0.5), ("075", 0.75)):
        q0 = np.sqrt(e) * 0.3
        fig["reference_" + key] = np.stack([q0 * np.cos(6 * t) * np.exp(-0.3 * t),
                                            -q0 * np.sin(6 * t) * np.exp(-0.3 * t)], -1)
    with h5py.File(path, "w") as f:
        f.attrs.update({"format": b"phnn-results", "format_version": 1, "sweep_name": b"fixture",
                        "sweep_text": SWEEP.encode()})
        g = f.create_group("runs")
        for k, col in (("system", 0), ("model", 1), ("integrator", 2), ("regularizer", 4),
                       ("studies", 5)):
            g[k] = np.array([r[col].encode() for r in runs], dtype="S32")
        g["size"] = np.array([r[7].encode() for r in runs], dtype="S32")
        g["canonical"] = np.array([f"system={r[0]};size={r[7]};sample_rate=100;seed={r[6]}".encode()
                                   for r in runs], dtype="S1024")
        g["n_train"] = np.array([r[3] for r in runs], dtype=np.int64)
        g["seed"] = np.array([r[6] for r in runs], dtype=np.int64)
        g["status"], g["mse"], g["trace"], g["trace_length"] = status, mse, trace, trace_length
        g["wall_time_s"] = rng.uniform(1, 10, R)
        length = np.where(status[:, None] == 0, 0, F) * np.ones((1, 4), dtype=np.int64)
        for key in ("05", "075"):
            ref = np.broadcast_to(fig["reference_" + key], (R, F, 2))
            g["figure/reference_" + key] = ref
            g["figure/prediction_" + key] = ref * rng.uniform(0.8, 1.2, (R, 1, 2))
        g["figure/prediction_05"][7, 50:, :] = np.nan   # a rollout that blew up at t = 0.5 s
        g["figure/length"] = length


if __name__ == "__main__":
    main(sys.argv[1])
