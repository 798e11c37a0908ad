#!/usr/bin/env python3
"""One ablation table: a baseline results file against variants that change one setting each.

    /usr/bin/python3 analysis/compare_ablation.py results/ablation-duffing-baseline.h5 \\
        "loss_norm = mse=results/ablation-duffing.h5" \\
        "dg_structure_point = start=results/ablation-duffing-dg-start.h5" \\
        "precision = float32=results/ablation-duffing-float32.h5" [--threshold 1.0]

For every (system, model, N_train) cell of the baseline, prints a Markdown row: the baseline's
median MSE with its bootstrap 95 % interval and the seeds above THRESHOLD (the Duffing oscillator's
bad mode: MSEs near 0.05 or near 10^2-10^3, so 1.0 separates them), then the same for each
variant that has the cell, marked "better" or "worse" when the two intervals do not overlap
("resolved"), "~" otherwise. Medians and intervals come from `phnn reduce --format csv` (the
reducer's own statistics: linear-interpolation quartiles, percentile bootstrap, fixed key); the
seed counts from `phnn reduce --format csv --per-run`. The phnn binary: $PHNN, else build/phnn.
"""
import sys

from phnn_tool import run_csv



def reduce_csv(path, *extra):
    return run_csv("reduce", path, "--format", "csv", *extra)


def cells(path, threshold):
    """{(system, model, n_train): (median, low, high, above, finished)}"""
    above, finished = {}, {}
    for r in reduce_csv(path, "--per-run"):
        if r["status"] not in ("done", "diverged"):
            continue
        key = (r["system"], r["model_label"], int(r["n_train"]))
        finished[key] = finished.get(key, 0) + 1
        above[key] = above.get(key, 0) + (float(r["mse"]) > threshold)
    out = {}
    for r in reduce_csv(path):
        if not r["median"]:
            continue
        if r["axis"] == "n_train":
            n_train = int(r["column"])
        else:  # a table with one column (no varied axis): the model's only N_train
            ns = {k[2] for k in finished if k[:2] == (r["system"], r["model"])}
            if r["axis"] or len(ns) != 1:
                continue
            n_train = ns.pop()
        key = (r["system"], r["model"], n_train)
        out[key] = (float(r["median"]), float(r["ci_low"]), float(r["ci_high"]),
                    above.get(key, 0), finished.get(key, 0))
    return out


def text(cell):
    median, low, high, above, n = cell
    return f"{median:.3g} ({low:.2g}, {high:.2g}) [{above}/{n}]"


def verdict(base, cell):
    if cell[2] < base[1]:
        return " better"
    if cell[1] > base[2]:
        return " worse"
    return " ~"


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    threshold = 1.0
    if "--threshold" in sys.argv:
        threshold = float(sys.argv[sys.argv.index("--threshold") + 1])
        args.remove(sys.argv[sys.argv.index("--threshold") + 1])
    if len(args) < 2:
        sys.exit(__doc__)
    base = cells(args[0], threshold)
    variants = [(a.rsplit("=", 1)[0], cells(a.rsplit("=", 1)[1], threshold)) for a in args[1:]]
    print("| system | model | N_train | baseline | " + " | ".join(n for n, _ in variants) + " |")
    print("|---" * (4 + len(variants)) + "|")
    for key in sorted(base):
        row = [key[0], key[1], str(key[2]), text(base[key])]
        for _, v in variants:
            row.append(text(v[key]) + verdict(base[key], v[key]) if key in v else "")
        print("| " + " | ".join(row) + " |")
    print(f"\nmedian (bootstrap 95 % interval) [seeds with MSE > {threshold:g} / finished]; "
          "better / worse: the intervals do not overlap; ~: they do.")


if __name__ == "__main__":
    main()
