#!/usr/bin/env python3
"""Writes a large trajectory CSV for `phnn import` memory measurements (docs/BENCHMARKS.md).

    bench/make_import_csv.py OUT.csv [--trajectories 5000] [--samples 1000] [--digits 12]

Columns trajectory,t,q,p,u (sweeps/systems/pendulum.toml's names), t = k/100, smooth q and p
written with 12 significant digits (--digits), u constant per trajectory: ~200 MB with the
defaults; --trajectories 100000 --samples 40 --digits 17 writes 288 MB of many short ones.
Deterministic (no random numbers), so two runs write the same bytes.
"""
import argparse
import math


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--trajectories", type=int, default=5000)
    parser.add_argument("--samples", type=int, default=1000)
    parser.add_argument("--digits", type=int, default=12)
    args = parser.parse_args()
    row = "%%d,%%.12g,%%.%dg,%%.%dg,%%.%dg\n" % (args.digits, args.digits, args.digits)
    with open(args.out, "w") as out:
        out.write("trajectory,t,q,p,u\n")
        for i in range(args.trajectories):
            a, w, u = 0.1 + (i % 97) / 100.0, 1.0 + (i % 13) / 10.0, ((i % 7) - 3) / 10.0
            rows = []
            for k in range(args.samples):
                t = k / 100.0
                rows.append(row % (i, t, a * math.cos(w * t), -a * w * math.sin(w * t), u))
            out.write("".join(rows))


if __name__ == "__main__":
    main()
