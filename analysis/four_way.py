#!/usr/bin/env python3
"""The four-way reading of analysis/paper_claims.py (--reading four-way): every comparison a
statement makes takes its reading from `phnn reduce --comparisons` (A better / B better /
equivalent within x delta / undecided; docs/METHOD.md "Comparisons"), never recomputed here.

    readings = FourWay.of_rows(run_csv("reduce", path, "--comparisons"), stat_rows)
    readings.reading(a_key, b_key)       # "A better" ... for the cells a, b in that order

A cell is known by its configuration key (system, model, n_train, size, regularizer); the reducer
names it "study/system/model/column" in every study table that shows it.  A comparison of two
keys is looked up in a table holding both (the same column, or the same row), in either order
(B better read backwards is A better).  The reducer exports every pair of rows of a column and
every pair of columns of a row, so every comparison of the statements is there.

Stability (--stability N): N bootstrap resamples of the seeds, drawn here (numpy, fixed seed)
jointly for every cell: slot j of a resample holds seed s_j in every cell, so runs paired by seed
stay paired.  The reducer reads every resample in one call (`--seed-lists`); the medians that
pick "the best of a family" are recomputed here on the same slots.
"""
import math
import os
import tempfile
from collections import defaultdict

FLIP = {"A better": "B better", "B better": "A better", "equivalent": "equivalent",
        "undecided": "undecided"}
READINGS = tuple(FLIP)


def config_key(row):
    """(system, model, n_train, size, regularizer) of a `phnn reduce --format csv` row."""
    config = {"n_train": "25", "size": "small", "regularizer": "none", row["axis"]: row["column"]}
    return (row["system"], row["model"], config["n_train"], config["size"], config["regularizer"])


class FourWay:
    """The reducer's readings by pair of cell names, and each cell's names by configuration."""

    def __init__(self, readings, names, delta):
        self.readings, self.names, self.delta = readings, names, delta

    @staticmethod
    def of_rows(comparison_rows, stat_rows):
        readings, delta = {}, 1.5  # reduce's default, for a file without comparisons
        for r in comparison_rows:
            if r["reading"] not in READINGS:
                raise ValueError(f"phnn reduce --comparisons: unknown reading {r['reading']!r} "
                                 f"for {r['a']} vs {r['b']}; expected one of {READINGS}")
            readings[(r["a"], r["b"])] = r["reading"]
            delta = float(r["delta"])
        names = defaultdict(list)
        for row in stat_rows:
            names[config_key(row)].append(
                f"{row['study']}/{row['system']}/{row['model']}/{row['column']}")
        return FourWay(readings, dict(names), delta)

    def reading(self, a_key, b_key):
        """The reducer's reading of cell a against cell b (in this order)."""
        for na in self.names.get(a_key, ()):
            for nb in self.names.get(b_key, ()):
                if (na, nb) in self.readings:
                    return self.readings[(na, nb)]
                if (nb, na) in self.readings:
                    return FLIP[self.readings[(nb, na)]]
        raise KeyError(f"no `phnn reduce --comparisons` row compares {a_key} with {b_key}: the "
                       "two cells share no study table (a statement compares cells no table "
                       "shows side by side)")


def claim_reading(raw, paper_says_lower):
    """A reading of (a, b) in the claim's terms: for / against / equivalent / undecided."""
    if raw == "A better":
        return "for" if paper_says_lower else "against"
    if raw == "B better":
        return "against" if paper_says_lower else "for"
    return raw


def verdict(comparisons, delta=1.5):
    """(verdict, evidence) of a statement from its comparisons' readings (c.reading: for,
    against, equivalent, undecided; None = by direction only, c.ok):

      supported                 every reading for the paper (and every by-direction one agrees)
      contradicted              some reading against the paper, none for it
      mixed                     readings against and for
      equivalent within xD      every reading equivalent (D = the reducer's delta)
      partly                    some for, none against, the rest equivalent or undecided
      undecided                 none for or against, not all equivalent
    A statement without readings (dispersion, per-run quantities) keeps the by-direction verdict:
    same direction / partly / not supported."""
    n = len(comparisons)
    if n == 0:
        return "no data", ""
    read = [c for c in comparisons if c.reading is not None]
    direction = [c for c in comparisons if c.reading is None]
    count = {k: sum(1 for c in read if c.reading == k)
             for k in ("for", "against", "equivalent", "undecided")}
    equivalent = f"equivalent within x{delta:g}"
    evidence = (f"{count['for']} for, {count['against']} against, {count['equivalent']} "
                f"{equivalent}, {count['undecided']} undecided")
    ok = sum(c.ok for c in direction)
    if not read:
        verdict_name = "same direction" if ok == n else "partly" if ok else "not supported"
        return verdict_name, f"{ok}/{n} in the paper's direction ({n} by direction only)"
    if direction:
        evidence += f" ({len(direction)} by direction only, {ok} in the paper's direction)"
    if count["against"]:
        return ("mixed" if count["for"] else "contradicted"), evidence
    if count["for"] == len(read) and ok == len(direction):
        return "supported", evidence
    if count["equivalent"] == len(read) and not direction:
        return equivalent, evidence
    return ("partly" if count["for"] else "undecided"), evidence


# ------------------------------------------------------------------ stability
def quantile(sorted_values, q):
    """numpy's linear quantile of sorted values, +inf exact (the reducer's rule)."""
    n = len(sorted_values)
    pos = q * (n - 1)
    lo = int(math.floor(pos))
    a, b = sorted_values[lo], sorted_values[min(lo + 1, n - 1)]
    frac = pos - lo
    if frac == 0 or a == b:
        return a
    if math.isinf(b):
        return b
    return a + frac * (b - a)


def slot_stat_row(row, values):
    """A stat row's median, quartiles and counts on a resample's values (no interval: the
    four-way reading takes none from the tables)."""
    out = dict(row)
    if not values:
        out.update(median="", q25="", q75="", iqr="", ci_low="", ci_high="", done="0",
                   diverged="0")
        return out
    v = sorted(values)
    median, q25, q75 = (quantile(v, q) for q in (0.5, 0.25, 0.75))
    out.update(median=repr(median), q25=repr(q25), q75=repr(q75),
               iqr=repr(math.inf if math.isinf(q75) else q75 - q25), ci_low="", ci_high="",
               done=str(sum(1 for x in v if math.isfinite(x))),
               diverged=str(sum(1 for x in v if not math.isfinite(x))))
    return out


def draw_seed_lists(run_rows, resamples, seed=0):
    """`resamples` bootstrap resamples of the finished runs' seeds (each as long as the set)."""
    import numpy as np
    rng = np.random.default_rng(seed)
    seeds = sorted({int(r["seed"]) for r in run_rows if r["status"] in ("done", "diverged")})
    return [[seeds[i] for i in rng.integers(0, len(seeds), len(seeds))] for _ in range(resamples)]


def reduce_seed_lists(run_csv, path, lists, extra=()):
    """`phnn reduce PATH --comparisons --seed-lists` on `lists`: the rows of each list, in order."""
    with tempfile.NamedTemporaryFile("w", suffix=".lists", delete=False) as f:
        f.write("# bootstrap resamples of the seeds (analysis/four_way.py)\n")
        f.writelines(",".join(map(str, lst)) + "\n" for lst in lists)
    try:
        rows = run_csv("reduce", path, "--comparisons", "--seed-lists", f.name, *extra)
    finally:
        os.unlink(f.name)
    by_list = [[] for _ in lists]
    for r in rows:
        by_list[int(r.pop("list")) - 1].append(r)
    return by_list


def resampled_inputs(stat_rows, run_rows, seeds, run_value):
    """The stat rows and run rows of one resample: slot j takes every cell's run of seeds[j]."""
    by_cell = defaultdict(dict)
    for r in run_rows:
        if r["status"] in ("done", "diverged"):
            key = (r["system"], r["model_label"], r["n_train"], r["size"], r["regularizer"])
            by_cell[key][int(r["seed"])] = r
    new_runs = [cell[s] for cell in by_cell.values() for s in seeds if s in cell]
    new_stats = []
    for row in stat_rows:
        cell = by_cell.get(config_key(row), {})
        new_stats.append(slot_stat_row(row, [run_value(cell[s]) for s in seeds if s in cell]))
    return new_stats, new_runs


def stability(stat_rows, run_rows, comparison_rows, judge_all, fetch_lists, resamples, seed=0,
              run_value=None):
    """Per statement tag, the share of `resamples` seed resamples whose four-way verdict equals
    the file's.  judge_all(stat_rows, run_rows, four_way) -> {tag: verdict};
    fetch_lists(lists) -> the reducer's comparison rows per list."""
    base = judge_all(stat_rows, run_rows, FourWay.of_rows(comparison_rows, stat_rows))
    lists = draw_seed_lists(run_rows, resamples, seed)
    same = {tag: 0 for tag in base}
    for seeds, rows in zip(lists, fetch_lists(lists)):
        new_stats, new_runs = resampled_inputs(stat_rows, run_rows, seeds, run_value)
        verdicts = judge_all(new_stats, new_runs, FourWay.of_rows(rows, new_stats))
        for tag, v in verdicts.items():
            if tag in same and v == base[tag]:
                same[tag] += 1
    return {tag: same[tag] / resamples for tag in base}
