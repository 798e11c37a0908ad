#!/usr/bin/env python3
"""compare_runs.py A.csv B.csv — the runs of two `phnn reduce --per-run --format
csv` tables agree: the same run ids, and for each, the same status and the same
result columns, bitwise (wall times and clock columns excepted). Exit 1 with
the first differences otherwise."""
import csv
import sys

CLOCKS = ("seconds", "utc", "wall", "train_s")


def rows(path):
    with open(path, newline="") as f:
        return {r["run_id"] if "run_id" in r else r["id"]: r for r in csv.DictReader(f)}


def main():
    a, b = rows(sys.argv[1]), rows(sys.argv[2])
    problems = []
    if set(a) != set(b):
        problems.append(f"run ids differ: {len(set(a) ^ set(b))} in one file only")
    for rid in sorted(set(a) & set(b)):
        for key, value in a[rid].items():
            if any(c in key for c in CLOCKS):
                continue
            if b[rid].get(key) != value:
                problems.append(f"run {rid}: {key} = {value!r} vs {b[rid].get(key)!r}")
    for p in problems[:10]:
        print(p)
    print(f"{len(a)} runs compared, {len(problems)} differences")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
