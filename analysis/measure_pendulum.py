#!/usr/bin/env python3
"""A "measurement" of the damped pendulum of sweeps/systems/pendulum.toml that no
discrete gradient made: classical RK4 at a step 100 times finer than the data's,
sub-sampled to 100 Hz, with Gaussian noise on the states, written as the CSV that
`phnn import` reads (docs/DATASET_FORMAT.md, "Trajectory files").

    /usr/bin/python3 analysis/measure_pendulum.py --long 2 --rms 0.2 --out results/pendulum-measured.csv
    build/phnn import results/pendulum-measured.csv --system sweeps/systems/pendulum.toml \\
        --window 10 --out results/pendulum-measured.h5
    mpirun -np 2 build/phnn sweep sweeps/examples/pendulum-measured.toml

The pendulum (parameters as in the system file): q' = p / (m l^2),
p' = -m g l sin q - c q' - u. With --long R (the worked example): R recordings of
--duration s under a multisine torque held per sample (long_recordings). Without
it (the earlier example, imported with --split trajectories --num-validation 500
--num-inference 50 --pair-window 0.31): a constant torque u per trajectory. Initial
states: q0 ~ U(-1, 1) rad, p0 ~ U(-0.25, 0.25) kg m^2/s (energies up to ~0.9 J,
below the separatrix 1.96 J); u ~ U(-0.3, 0.3) N m. Training and validation
recordings last 1 s (pairs are drawn in their first 0.31 s by --pair-window),
inference recordings 5 s. Noise: `--noise` times each state's standard deviation
over the recordings (default 1e-3), on every sample, inference included (a
measurement is noisy everywhere).
"""
import argparse
import sys

import numpy as np

M, L, G, C = 0.2, 0.5, 9.81, 0.02   # sweeps/systems/pendulum.toml [parameters]


def field(x, u):
    q, p = x[:, 0], x[:, 1]
    qdot = p / (M * L * L)
    return np.stack([qdot, -M * G * L * np.sin(q) - C * qdot - u], axis=1)


def rk4_sample(x, u, h, substeps):
    """x [K, 2] after `substeps` classical RK4 steps of h under u [K] (one sample)."""
    for _ in range(substeps):
        k1 = field(x, u)
        k2 = field(x + 0.5 * h * k1, u)
        k3 = field(x + 0.5 * h * k2, u)
        k4 = field(x + h * k3, u)
        x = x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


def rk4(x0, u, duration, rate, substeps):
    """States at `rate` Hz over `duration` s, integrated with `substeps` RK4
    steps per sample; x0 [K, 2], u [K]."""
    h = 1.0 / (rate * substeps)
    samples = int(round(duration * rate)) + 1
    out = np.empty((samples, len(x0), 2))
    x = x0.copy()
    out[0] = x
    for n in range(1, samples):
        x = rk4_sample(x, u, h, substeps)
        out[n] = x
    return out  # [samples, K, 2]


def multisine(rng, duration, rate, components=8, band=(0.1, 2.0), rms=0.1):
    """A torque of `components` sines at frequencies spread over `band` [Hz] (log-spaced,
    jittered), random phases, scaled to `rms` [N m]: one value per sample, held over it."""
    t = np.arange(int(round(duration * rate)) + 1) / rate
    freqs = np.geomspace(*band, components) * rng.uniform(0.9, 1.1, components)
    phases = rng.uniform(0, 2 * np.pi, components)
    u = np.sin(2 * np.pi * freqs[None, :] * t[:, None] + phases[None, :]).sum(axis=1)
    return u * rms / np.sqrt(np.mean(u * u))


def rk4_held(x0, u, rate, substeps):
    """One trajectory under the input u[n] held over [t_n, t_n+1): states at every sample."""
    h = 1.0 / (rate * substeps)
    out = np.empty((len(u), 2))
    x = np.asarray(x0, dtype=float)[None, :]
    out[0] = x[0]
    for n in range(1, len(u)):
        x = rk4_sample(x, np.array([u[n - 1]]), h, substeps)
        out[n] = x[0]
    return out


def long_recordings(args):
    """`--long R`: R recordings of `--duration` s at 100 Hz under a multisine torque, with sensor
    noise (`--noise` of each state's spread) and a slow drift of the angle sensor
    (`--drift` rad, a sine of period 600 s): a measurement as system identification takes it."""
    rng = np.random.default_rng(args.seed)
    rate, substeps = 100, 100
    with open(args.out, "w") as f:
        f.write("# measure_pendulum.py --long: RK4 at 10 kHz under a multisine torque (8 sines, "
                "0.1-2 Hz, rms %g N m, held per sample), sampled at 100 Hz; noise %g of the "
                "spread, angle drift %g rad\n" % (args.rms, args.noise, args.drift))
        f.write("trajectory,t,q,p,u\n")
        for r in range(args.long):
            u = multisine(rng, args.duration, rate, rms=args.rms)
            x = rk4_held([rng.uniform(-0.5, 0.5), 0.0], u, rate, substeps)
            t = np.arange(len(u)) / rate
            noisy = x + args.noise * x.std(axis=0) * rng.standard_normal(x.shape)
            noisy[:, 0] += args.drift * np.sin(2 * np.pi * t / 600.0)
            for n in range(len(u)):
                f.write("%d,%.17g,%.17g,%.17g,%.17g\n" % (r, t[n], noisy[n, 0], noisy[n, 1], u[n]))
    print("measure_pendulum.py: %d recordings of %g s -> %s" % (args.long, args.duration, args.out),
          file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="CSV to write")
    ap.add_argument("--train", type=int, default=400, help="1 s training recordings")
    ap.add_argument("--validation", type=int, default=500, help="1 s validation recordings")
    ap.add_argument("--inference", type=int, default=50, help="5 s inference recordings")
    ap.add_argument("--noise", type=float, default=1e-3, help="relative noise level")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--long", type=int, default=0, metavar="R",
                    help="instead: R long recordings under a multisine torque (see long_recordings)")
    ap.add_argument("--duration", type=float, default=180.0, help="--long: seconds per recording")
    ap.add_argument("--drift", type=float, default=2e-3, help="--long: angle-sensor drift [rad]")
    ap.add_argument("--rms", type=float, default=0.1, help="--long: the torque's rms [N m]")
    args = ap.parse_args()
    if args.long:
        return long_recordings(args)
    rng = np.random.default_rng(args.seed)
    rate, substeps = 100, 100
    groups = [(args.train + args.validation, 1.0), (args.inference, 5.0)]
    recordings = []
    for count, duration in groups:
        x0 = np.stack([rng.uniform(-1, 1, count), rng.uniform(-0.25, 0.25, count)], axis=1)
        u = rng.uniform(-0.3, 0.3, count)
        recordings.append((rk4(x0, u, duration, rate, substeps), u))
    spread = np.concatenate([r.reshape(-1, 2) for r, _ in recordings]).std(axis=0)
    ident = 0
    with open(args.out, "w") as f:
        f.write("# measure_pendulum.py: RK4 at 10 kHz, sampled at 100 Hz, noise %g of the "
                "spread (%.4g, %.4g)\n" % (args.noise, spread[0], spread[1]))
        f.write("trajectory,t,q,p,u\n")
        for states, u in recordings:
            noisy = states + args.noise * spread * rng.standard_normal(states.shape)
            for k in range(states.shape[1]):
                for n in range(states.shape[0]):
                    f.write("%d,%.17g,%.17g,%.17g,%.17g\n"
                            % (ident, n / rate, noisy[n, k, 0], noisy[n, k, 1], u[k]))
                ident += 1
    print("measure_pendulum.py: %d trajectories -> %s" % (ident, args.out), file=sys.stderr)


if __name__ == "__main__":
    main()
