#!/usr/bin/env python3
"""A linear ARX baseline for a data set of recordings (`phnn import`): x_n+1 = A x_n + B u_n + c
fitted by least squares on the training pairs, then simulated on each inference window from its
recorded first state under its recorded inputs; the error is the paper's Eq. 31, as `phnn`
computes it for the models (mean over windows of (1/N) sum_n=1..N |x_n - x_hat_n|^2).

    /usr/bin/python3 analysis/arx_baseline.py results/pendulum-long.h5 [--n-train 1000]

Prints one Markdown row: the fit's pairs, the MSE and the median error per window.
"""
import argparse

import h5py
import numpy as np


def fit(x, u, x_next):
    """Theta [n_x + n_u + 1, n_x] minimizing |[x u 1] Theta - x_next|^2 (numpy lstsq)."""
    design = np.hstack([x, u, np.ones((len(x), 1))])
    theta, *_ = np.linalg.lstsq(design, x_next, rcond=None)
    return theta


def simulate(theta, x0, inputs):
    """States x_0..x_N from x0 under inputs u_0..u_N-1 (held per step)."""
    out = np.empty((len(inputs), len(x0)))
    out[0] = x0
    for n in range(1, len(inputs)):
        out[n] = np.concatenate([out[n - 1], inputs[n - 1], [1.0]]) @ theta
    return out


def window_errors(theta, states, inputs):
    """Eq. 31's per-trajectory errors e_i = (1/N) sum_n=1..N |x_n - x_hat_n|^2."""
    errors = []
    for x, u in zip(states, inputs):
        sim = simulate(theta, x[0], u)
        errors.append(float(np.mean(np.sum((x[1:] - sim[1:]) ** 2, axis=1))))
    return np.array(errors)


def load(path, n_train):
    with h5py.File(path, "r") as f:
        x, x_next = f["train/x"][:], f["train/x_next"][:]
        u = f["train/u"][:] if "train/u" in f else np.zeros((len(x), 0))
        states = f["inference/states"][:]
        if "inference/inputs" in f:
            inputs = f["inference/inputs"][:]
        elif "inference/u" in f:
            inputs = np.repeat(f["inference/u"][:][:, None, :], states.shape[1], axis=1)
        else:
            inputs = np.zeros(states.shape[:2] + (0,))
    n = len(x) if n_train is None else n_train
    return x[:n], u.reshape(len(u), -1)[:n], x_next[:n], states, inputs


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset", help="data-set file (phnn import / phnn data)")
    ap.add_argument("--n-train", type=int, default=None,
                    help="fit on the first N training pairs (the models' n_train); default all")
    args = ap.parse_args(argv)
    x, u, x_next, states, inputs = load(args.dataset, args.n_train)
    theta = fit(x, u, x_next)
    errors = window_errors(theta, states, inputs)
    print(f"| linear ARX (least squares, {len(x)} pairs) | {errors.mean():.3e} | "
          f"{np.median(errors):.3e} | {len(errors)} windows |")
    return errors


if __name__ == "__main__":
    main()
