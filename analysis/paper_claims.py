#!/usr/bin/env python3
"""The paper's §6 statements (and its conclusion's) checked on one results file of sweeps/paper.toml.

    /usr/bin/python3 analysis/paper_claims.py results/paper.h5 > claims.md

Every statement becomes a list of comparisons between two cells of the file, each with the
direction the paper claims.  A comparison of two medians is *resolved* when the reducer's
percentile-bootstrap 95 % intervals of the two medians do not overlap, a *tie* otherwise
(docs/DECISIONS.md).  Statements about dispersion compare IQRs, and the one about the Jacobian
compares per-run quantities at the last validation point: those have no interval here and are
counted by direction only (said in the row).  Verdicts:

  holds                   every comparison in the paper's direction and resolved
  same direction          every median in the paper's direction, not all resolved, none against
  partly                  some medians against the paper, none of those resolved
  not supported           no comparison resolved in the paper's direction (ties or against)
  contradicted / mixed    resolved against the paper (mixed: some resolved for it too)

A statement that something does *not* happen (e.g. "regularization does not improve the harmonic
oscillator") counts a resolved occurrence as against the paper and anything else as consistent,
by direction only: a tie cannot prove an absence, so such a statement is at best "same direction".

Medians, IQRs and intervals come from `phnn reduce --format csv` (the reducer's own statistics),
the per-run Jacobian quantities from `phnn reduce --format csv --per-run`.  The phnn binary: $PHNN,
else build/phnn.  A study or cell missing from the file is skipped and said so.

--reading four-way (default: overlap, the rules above): each comparison takes its reading from
`phnn reduce --comparisons` (analysis/four_way.py; paired by seed where the runs share weights,
batches and data): A better / B better / equivalent within x1.5 / undecided, turned into the
claim's terms -- for (the paper's direction), against, equivalent, undecided.  A statement that
something does not happen counts its occurrence (the claimed direction; for "about constant",
either direction) as against, and equivalent or the other direction as for.  Verdicts:

  supported                 every reading for the paper (and every by-direction one agrees)
  contradicted / mixed      some reading against the paper (mixed: some for it too)
  equivalent within x1.5    every reading equivalent
  partly                    some for, none against, the rest equivalent or undecided
  undecided                 none for or against, not all equivalent

Statements without readings (dispersion, per-run quantities) keep their by-direction verdict.
"""
import argparse
import math
import os
import statistics
import sys
from collections import namedtuple

import four_way
from phnn_tool import run_csv

# key: (system, model, n_train, size, regularizer), for the four-way reading's look-up
Cell = namedtuple("Cell", "median q25 q75 iqr lo hi done diverged expected key", defaults=(None,))
# ok: the paper's direction; reading (four-way only): for, against, equivalent, undecided
Comparison = namedtuple("Comparison", "label ok resolved reading", defaults=(None,))
FOUR_WAY = None  # a four_way.FourWay while the statements are read four-way
JOINT = False  # --resample joint (the report says how the seeds were resampled)

DEFAULTS = {"n_train": "25", "size": "small", "regularizer": "none"}  # the shared column
FAMILIES = {"PHNN-S": ("PHNN-S-DG", "PHNN-S-RK2"), "PHNN-JR": ("PHNN-JR-DG", "PHNN-JR-RK2")}
PHNN_MODELS = FAMILIES["PHNN-S"] + FAMILIES["PHNN-JR"]
SYSTEMS = ("harmonic", "duffing", "self-sustained")



def reduce_csv(path, *extra):
    return run_csv("reduce", path, "--format", "csv", *extra)


# ------------------------------------------------------------------ the file's cells
class Probe(namedtuple("Probe", Cell._fields + ("system", "models", "n_train", "size", "reg"))):
    """A cell without results (--write-comparisons): which cell(s) a comparison reads. `models`
    lists several when a statement takes the best of them."""

    @staticmethod
    def of(system, model, config):
        return Probe(1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0, 0, 0, None, system, (model,),
                     config["n_train"], config["size"], config["regularizer"])

    @staticmethod
    def merge(probes):
        models = tuple(m for p in probes for m in p.models)
        return probes[0]._replace(models=tuple(dict.fromkeys(models)))

    def selector(self):
        """The sweep file's cell selector: "system/models/n_train/size/regularizer"."""
        models = "+".join(m.lower() for m in self.models)
        return f"{self.system}/{models}/{self.n_train}/{self.size}/{self.reg}"


RECORDED = []  # (selector, selector) of every compare() on probes


class Results:
    """Cells by (study, system, model, column) and by configuration (shared columns once)."""

    def __init__(self, stat_rows, run_rows, probes=False):
        self.cells, self.by_config, self.runs = {}, {}, {}
        for r in stat_rows:
            f = lambda k: float(r[k]) if r[k] not in ("", "nan") else math.nan  # noqa: E731
            config = dict(DEFAULTS, **{r["axis"]: r["column"]})
            key = (r["system"], r["model"], config["n_train"], config["size"], config["regularizer"])
            cell = Cell(f("median"), f("q25"), f("q75"), f("iqr"), f("ci_low"), f("ci_high"),
                        int(r["done"]), int(r["diverged"]), int(r["expected"]), key)
            if probes:
                cell = Probe.of(r["system"], r["model"], config)
            self.cells[(r["study"], r["system"], r["model"], r["column"])] = cell
            self.by_config[key] = cell
        for r in run_rows:
            if r["status"] != "done":
                continue
            key = (r["system"], r["model_label"], r["n_train"], r["size"], r["regularizer"])
            self.runs.setdefault(key, []).append(r)

    def get(self, study, system, model, column):
        return self.cells.get((study, system, model, column))

    def columns(self, study):
        seen = []
        for (st, _, _, col) in self.cells:
            if st == study and col not in seen:
                seen.append(col)
        return seen

    def has(self, study):
        return any(k[0] == study for k in self.cells)


def fmt(cell):
    return f"{cell.median:.3g} ({cell.lo:.2g}, {cell.hi:.2g})"


def finite(cell):
    return cell is not None and not math.isnan(cell.median)


def compare(label, a, b, paper_says_lower=True):
    """a against b; the paper says a's median is below b's (or above, if not paper_says_lower)."""
    if isinstance(a, Probe):  # --write-comparisons: record the two cells, decide nothing
        RECORDED.append((a.selector(), b.selector()))
        return Comparison(label, True, False)
    if FOUR_WAY is not None:
        return compare_four_way(label, a, b, paper_says_lower)
    lower = a.median < b.median
    resolved = a.hi < b.lo if lower else a.lo > b.hi
    if a.median == b.median:
        resolved = False
    ok = lower if paper_says_lower else not lower
    sign = "<" if lower else ">="
    mark = "resolved" if resolved else "tie"
    return Comparison(f"{label}: {fmt(a)} {sign} {fmt(b)} [{mark}]", ok, resolved)


FOUR_WAY_MARKS = {"A better": "first better", "B better": "second better",
                  "undecided": "undecided"}


def compare_four_way(label, a, b, paper_says_lower):
    """compare() under --reading four-way: the reducer's reading of a against b."""
    raw = FOUR_WAY.reading(a.key, b.key)
    reading = four_way.claim_reading(raw, paper_says_lower)
    lower = a.median < b.median
    mark = FOUR_WAY_MARKS.get(raw, f"equivalent within x{FOUR_WAY.delta:g}")
    return Comparison(f"{label}: {fmt(a)} {'<' if lower else '>='} {fmt(b)} [{mark}]",
                      lower if paper_says_lower else not lower, reading in ("for", "against"),
                      reading)


def by_direction(label, ok):
    """A comparison without an interval (IQRs, per-run quantities)."""
    return Comparison(label, ok, None)


def absence(c, happens=None):
    """The paper says what comparison c shows does *not* happen (by default: c's direction,
    resolved). Only a resolved occurrence counts (against the paper); anything else is
    consistent with it, by direction only (a tie cannot prove an absence)."""
    if c.reading is not None:  # four-way: c.resolved = read either way
        occurs = c.reading == "for" if happens is None else happens
        kept = "undecided" if c.reading == "undecided" and not occurs else "for"
        return Comparison(c.label, not occurs, occurs, "against" if occurs else kept)
    occurs = (c.ok and c.resolved) if happens is None else happens
    return Comparison(c.label, not occurs, True if occurs else None)


def lowest(named_cells):
    """(model, cell) of the smallest median among (model, cell) pairs of finite cells; for probes
    (--write-comparisons) one probe that stands for all of them (the sweep picks at run time)."""
    named_cells = [(m, c) for m, c in named_cells if finite(c)]
    if not named_cells:
        return None, None
    if isinstance(named_cells[0][1], Probe):
        return named_cells[0][0], Probe.merge([c for _, c in named_cells])
    return min(named_cells, key=lambda mc: mc[1].median)


def best_of(results, study, system, models, column):
    return lowest([(m, results.get(study, system, m, column)) for m in models])


def verdict(comparisons):
    if FOUR_WAY is not None:
        return four_way.verdict(comparisons, FOUR_WAY.delta)
    n = len(comparisons)
    if n == 0:
        return "no data", ""
    ok = sum(c.ok for c in comparisons)
    intervals = [c for c in comparisons if c.resolved is not None]
    r_ok = sum(1 for c in intervals if c.ok and c.resolved)
    r_against = sum(1 for c in intervals if not c.ok and c.resolved)
    counts = f"{ok}/{n} in the paper's direction"
    if intervals:
        counts += f", {r_ok} resolved for it, {r_against} against"
    if len(intervals) < n:
        counts += f" ({n - len(intervals)} by direction only)"
    if r_against:
        return ("mixed" if r_ok else "contradicted"), counts
    if not intervals:
        return ("same direction" if ok == n else "partly" if ok else "not supported"), counts
    if ok == n:
        return ("holds" if r_ok == len(intervals) else "same direction"), counts
    return ("partly" if r_ok else "not supported"), counts


def decided(comparisons):
    """What the resolved comparisons alone decide, the directions of tied medians ignored (they
    flip from one draw of seeds to the next when two cells are truly alike):

      holds              every comparison with an interval resolved in the paper's direction
      for, in part       some resolved for it, none against
      undecided          none resolved (ties only)
      against / split    resolved against it (split: some resolved for it too)
      by direction only  no comparison has an interval (dispersion, Jacobian, absences seen
                         nowhere): seeds cannot decide it
    """
    intervals = [c for c in comparisons if c.resolved is not None]
    if not intervals:
        return "by direction only"
    r_for = sum(1 for c in intervals if c.ok and c.resolved)
    r_against = sum(1 for c in intervals if not c.ok and c.resolved)
    if r_against:
        return "split" if r_for else "against"
    if r_for == len(intervals):
        return "holds"
    return "for, in part" if r_for else "undecided"


def verdict_name(comparisons):
    return verdict(comparisons)[0]


JUDGES = {"verdict": verdict_name, "decided": decided}


# ------------------------------------------------------------------ the statements
def study_one(res):
    out = []
    if not res.has("I"):
        return out
    cols = res.columns("I")
    comps = []
    for system in SYSTEMS:
        for model in ("NODE-RK2",) + PHNN_MODELS:
            if system == "self-sustained" and model.startswith("PHNN-S-"):
                continue
            for lo_col, hi_col in zip(cols, cols[1:]):
                a, b = res.get("I", system, model, hi_col), res.get("I", system, model, lo_col)
                if finite(a) and finite(b):
                    comps.append(compare(f"{system} {model} N_train {hi_col} vs {lo_col}", a, b))
    out.append(("I.1", "More training points lower the error for every system and model",
                comps))
    comps = []
    for model in FAMILIES["PHNN-S"]:
        a, b = res.get("I", "self-sustained", model, cols[-1]), res.get("I", "self-sustained", model, cols[0])
        if finite(a) and finite(b):
            c = compare(f"self-sustained {model} N_train {cols[-1]} vs {cols[0]}", a, b)
            comps.append(absence(c, happens=c.resolved))
    out.append(("I.2", "... except PHNN-S on the self-sustained oscillator, about constant "
                "(counted: the end columns' intervals overlap)", comps))
    out.append(("I.3", "NODE is consistently outperformed by one of the PHNN models",
                node_outperformed(res, "I", cols)))
    comps = []
    for fam, (dg, rk2) in FAMILIES.items():
        a, b = res.get("I", "harmonic", dg, cols[0]), res.get("I", "harmonic", rk2, cols[0])
        if finite(a) and finite(b):
            comps.append(compare(f"harmonic {fam} N_train {cols[0]}: DG vs RK2", a, b))
    out.append(("I.4", "DG beats RK2 in the low-data regime on the harmonic oscillator", comps))
    comps = []
    for system in ("duffing", "self-sustained"):
        for fam, (dg, rk2) in FAMILIES.items():
            for col in cols:
                a, b = res.get("I", system, dg, col), res.get("I", system, rk2, col)
                if finite(a) and finite(b):
                    comps.append(compare(f"{system} {fam} N_train {col}: DG vs RK2", a, b))
    out.append(("I.5", "DG beats RK2 at every N_train on the nonlinear oscillators", comps))
    comps = []
    for model in ("NODE-RK2",) + PHNN_MODELS:
        d = res.get("I", "duffing", model, cols[0])
        for other, col in (("duffing", cols[-1]), ("harmonic", cols[0]), ("self-sustained", cols[0])):
            o = res.get("I", other, model, col)
            if finite(d) and finite(o):
                comps.append(by_direction(
                    f"{model} IQR/median: duffing {cols[0]} {rel_iqr(d):.3g} vs {other} {col} "
                    f"{rel_iqr(o):.3g}", rel_iqr(d) > rel_iqr(o)))
    out.append(("I.6", "Duffing shows a high dispersion (large IQR) in the low-data regime "
                "(relative IQR = IQR / median)", comps))
    out.append(("I.7", "PHNN-S has the lowest error on the harmonic and Duffing oscillators",
                family_best(res, "I", cols, ("harmonic", "duffing"), "PHNN-S")))
    comps = []
    for col in cols:
        _, s = best_of(res, "I", "self-sustained", FAMILIES["PHNN-S"], col)
        for label, models in (("PHNN-JR", FAMILIES["PHNN-JR"]), ("NODE", ("NODE-RK2",))):
            m, c = best_of(res, "I", "self-sustained", models, col)
            if s is not None and c is not None:
                comps.append(compare(f"self-sustained N_train {col}: {m} vs best PHNN-S", c, s))
    out.append(("I.8", "On the self-sustained oscillator PHNN-S is outperformed by PHNN-JR and NODE",
                comps))
    return out


def rel_iqr(cell):
    return cell.iqr / cell.median if cell.median > 0 else math.inf


def node_outperformed(res, study, cols):
    comps = []
    for system in SYSTEMS:
        for col in cols:
            m, best = best_of(res, study, system, PHNN_MODELS, col)
            node = res.get(study, system, "NODE-RK2", col)
            if best is not None and finite(node):
                comps.append(compare(f"{system} {col}: best PHNN ({m}) vs NODE", best, node))
    return comps


def family_best(res, study, cols, systems, family):
    other = [m for m in ("NODE-RK2",) + PHNN_MODELS if m not in FAMILIES[family]]
    comps = []
    for system in systems:
        for col in cols:
            m, a = best_of(res, study, system, FAMILIES[family], col)
            n, b = best_of(res, study, system, other, col)
            if a is not None and b is not None:
                comps.append(compare(f"{system} {col}: {m} vs the best other model ({n})", a, b))
    return comps


def study_two(res):
    if not res.has("II"):
        return []
    cols = res.columns("II")  # small, medium, large
    out, comps = [], []
    for system in SYSTEMS:
        for model in ("NODE-RK2",) + PHNN_MODELS:
            small = res.get("II", system, model, cols[0])
            for col in cols[1:]:
                c = res.get("II", system, model, col)
                if finite(small) and finite(c):
                    comps.append(compare(f"{system} {model} {col} vs {cols[0]}", c, small,
                                         paper_says_lower=False))
    out.append(("II.1", "More trainable parameters increase the error (N_train 25)", comps))
    out.append(("II.2", "NODE is again outperformed by one of the PHNN models",
                node_outperformed(res, "II", cols)))
    small_pairs, larger_pairs = [], []
    for system in SYSTEMS:
        for fam, (dg, rk2) in FAMILIES.items():
            for col in cols:
                a, b = res.get("II", system, dg, col), res.get("II", system, rk2, col)
                if not (finite(a) and finite(b)):
                    continue
                label = f"{system} {fam} {col}: DG vs RK2"
                if col == cols[0]:
                    small_pairs.append(compare(label, a, b))
                else:  # the paper: DG does not outperform RK2 here
                    larger_pairs.append(absence(compare(label, a, b)))
    out.append(("II.3", "DG outperforms RK2 only with small models: at small size", small_pairs))
    out.append(("II.4", "... and not at medium or large size (against = DG resolved better)",
                larger_pairs))
    comps = []
    for model in ("NODE-RK2",) + PHNN_MODELS:
        small = res.get("II", "duffing", model, cols[0])
        for col in cols[1:]:
            c = res.get("II", "duffing", model, col)
            if finite(small) and finite(c):
                comps.append(by_direction(f"duffing {model} IQR {col} {c.iqr:.3g} vs "
                                          f"{cols[0]} {small.iqr:.3g}", c.iqr < small.iqr))
    out.append(("II.5", "Larger models reduce the dispersion (IQR) on the Duffing oscillator", comps))
    return out


def study_three(res):
    if not res.has("III"):
        return []
    cols = res.columns("III")  # none, cn, sn, sr
    base, regs = cols[0], cols[1:]
    comps = []
    for system in ("harmonic", "self-sustained"):
        for model in ("NODE-RK2",) + PHNN_MODELS:
            b = res.get("III", system, model, base)
            for reg in regs:
                c = res.get("III", system, model, reg)
                if finite(b) and finite(c):
                    comps.append(absence(compare(f"{system} {model} {reg} vs {base}", c, b)))
    out = [("III.1", "Regularization does not improve the harmonic and self-sustained "
            "oscillators (against = a regularizer resolved better)", comps)]
    comps = []
    for model in ("NODE-RK2",) + PHNN_MODELS:
        b, c = res.get("III", "duffing", model, base), res.get("III", "duffing", model, "cn")
        if finite(b) and finite(c):
            comps.append(compare(f"duffing {model} cn vs {base}", c, b))
            comps.append(by_direction(f"duffing {model} IQR cn {c.iqr:.3g} vs {base} {b.iqr:.3g}",
                                      c.iqr < b.iqr))
    out.append(("III.2", "CN considerably improves the Duffing oscillator (error and IQR)", comps))
    comps = []
    for model in ("NODE-RK2",) + PHNN_MODELS:
        rho = {reg: run_median(res, ("duffing", model, "25", "small", reg), "final_rho")
               for reg in (base, "sr")}
        if all(v is not None for v in rho.values()):
            comps.append(by_direction(
                f"duffing {model} median |rho - 1| at the end: sr {abs(rho['sr'] - 1):.3g} vs "
                f"{base} {abs(rho[base] - 1):.3g}", abs(rho["sr"] - 1) < abs(rho[base] - 1)))
    out.append(("III.3", "SR brings the stiffness ratio closer to 1 (Duffing, end of training)",
                comps))
    comps = []
    for model in ("NODE-RK2",) + PHNN_MODELS:
        b, c = res.get("III", "duffing", model, base), res.get("III", "duffing", model, "sr")
        if finite(b) and finite(c):
            comps.append(absence(compare(f"duffing {model} sr vs {base}", c, b)))
    out.append(("III.4", "... but not always a lower error (counted: SR not resolved better)",
                comps))
    out.append(jacobian_ranking(res, base))
    return out


def run_values(res, key, field):
    """`field` of the finished runs of the cell `key` (empty and NaN values left out)."""
    return [float(r[field]) for r in res.runs.get(key, []) if r[field] not in ("", "nan")]


def run_median(res, key, field):
    values = run_values(res, key, field)
    return statistics.median(values) if values else None


def run_mean(res, key, field):
    values = run_values(res, key, field)
    return statistics.fmean(values) if values else None


def jacobian_ranking(res, base):
    """Duffing N_train 25 baseline: PHNN-S-RK2 and PHNN-S-DG have the highest mean kappa,
    sigma_max, rho and IQR, and rho > 1."""
    models = ("NODE-RK2",) + PHNN_MODELS
    comps = []
    for field in ("final_kappa", "final_sigma_max", "final_rho"):
        means = {m: run_mean(res, ("duffing", m, "25", "small", base), field) for m in models}
        means = {m: v for m, v in means.items() if v is not None}
        if len(means) < 3:
            continue
        top = sorted(means, key=means.get, reverse=True)[:2]
        listing = ", ".join(f"{m} {means[m]:.3g}" for m in sorted(means, key=means.get, reverse=True))
        comps.append(by_direction(f"mean {field[6:]} over seeds: {listing}",
                                  set(top) == set(FAMILIES["PHNN-S"])))
    iqrs = {m: res.by_config.get(("duffing", m, "25", "small", base)) for m in models}
    iqrs = {m: c.iqr for m, c in iqrs.items() if finite(c)}
    if len(iqrs) >= 3:
        top = sorted(iqrs, key=iqrs.get, reverse=True)[:2]
        listing = ", ".join(f"{m} {iqrs[m]:.3g}" for m in sorted(iqrs, key=iqrs.get, reverse=True))
        comps.append(by_direction(f"IQR of the MSE: {listing}", set(top) == set(FAMILIES["PHNN-S"])))
    for m in FAMILIES["PHNN-S"]:
        rho = run_mean(res, ("duffing", m, "25", "small", base), "final_rho")
        if rho is not None:
            comps.append(by_direction(f"{m} mean rho {rho:.3g} > 1", rho > 1))
    return ("III.5", "Duffing, N_train 25, no regularizer: PHNN-S-RK2 and PHNN-S-DG have the "
            "highest mean kappa, sigma_max and rho at the end of training and the highest IQR; "
            "their rho > 1", comps)


def across_studies(res):
    """§6.4 and the conclusion, over every distinct cell (a shared column counted once)."""
    configs = sorted({k[2:] for k in res.by_config})
    out, comps = [], []
    for system in SYSTEMS:
        want, other = ("PHNN-JR", "PHNN-S") if system == "self-sustained" else ("PHNN-S", "PHNN-JR")
        for n_train, size, reg in configs:
            cells = {m: res.by_config.get((system, m, n_train, size, reg)) for m in PHNN_MODELS}
            _, a = lowest([(m, c) for m, c in cells.items() if m in FAMILIES[want]])
            _, b = lowest([(m, c) for m, c in cells.items() if m in FAMILIES[other]])
            if a is not None and b is not None:
                comps.append(compare(f"{system} N_train {n_train} {size} {reg}: best {want} vs "
                                     f"best {other}", a, b))
    out.append(("§6.4", "In every study PHNN-S is the best architecture on the harmonic and Duffing "
                "oscillators, PHNN-JR on the self-sustained one", comps))
    by_group = {}
    for system in SYSTEMS:
        for n_train, size, reg in configs:
            for fam, (dg, rk2) in FAMILIES.items():
                a = res.by_config.get((system, dg, n_train, size, reg))
                b = res.by_config.get((system, rk2, n_train, size, reg))
                if finite(a) and finite(b):
                    group = ("linear" if system == "harmonic" else "nonlinear", size)
                    by_group.setdefault(group, []).append(
                        compare(f"{system} {fam} N_train {n_train} {size} {reg}: DG vs RK2", a, b))
    for (kind, size), comps in sorted(by_group.items()):
        out.append((f"C.1 {kind} {size}", "Conclusion: DG-based PHNNs outperform RK2-based ones, "
                    f"especially on nonlinear systems with small models ({kind} systems, {size})",
                    comps))
    for system in SYSTEMS:
        comps = []
        for model in ("NODE-RK2",) + PHNN_MODELS:
            b = res.by_config.get((system, model, "25", "small", "none"))
            for reg in ("cn", "sn", "sr"):
                c = res.by_config.get((system, model, "25", "small", reg))
                if finite(b) and finite(c):
                    comps.append(compare(f"{system} {model} {reg} vs none", c, b))
        benefits = system != "self-sustained"
        if not benefits:  # the paper: no benefit; against = a regularizer resolved better
            comps = [absence(c) for c in comps]
        out.append((f"C.2 {system}", "Conclusion: the harmonic and Duffing oscillators clearly "
                    "benefit from Jacobian regularization, the self-sustained one does not "
                    f"({system}: {'a regularizer lowers the error' if benefits else 'none helps'})",
                    comps))
    return out


PAPER_STEPS, PAPER_SEEDS = 50000, 10
STABLE = 0.9  # share of resamples with the same verdict below which a verdict is unstable


READING_WORDS = {"for": "for the paper", "against": "against the paper",
                 "equivalent": "equivalent", "undecided": "undecided"}


def detail_line(c):
    """One comparison as a Markdown bullet that does not nest ("- - x" would)."""
    if c.reading is not None:  # four-way: the reading, not the medians' direction
        return f"- {READING_WORDS[c.reading]}: {c.label}"
    return f"- {'for' if c.ok else 'against'} the paper: {c.label}"


def setting_problems(run_rows):
    """How the file's runs differ from the paper's training budget and seed count (empty: they
    do not): 50 000 Adam steps and 10 seeds per cell."""
    problems = []
    steps = sorted({int(r["steps"]) for r in run_rows if r.get("steps", "") != ""})
    if steps and steps != [PAPER_STEPS]:
        problems.append(f"{'/'.join(map(str, steps))} Adam steps per run (paper: {PAPER_STEPS})")
    seeds = {}
    for r in run_rows:
        if r["status"] not in ("done", "diverged"):
            continue  # the verdicts rest on finished runs only
        key = (r["system"], r["model_label"], r["n_train"], r["size"], r["regularizer"])
        seeds.setdefault(key, set()).add(r["seed"])
    fewest = min((len(v) for v in seeds.values()), default=PAPER_SEEDS)
    if fewest < PAPER_SEEDS:
        problems.append(f"as few as {fewest} finished seeds per cell (paper: {PAPER_SEEDS})")
    return problems


def all_claims(results):
    return study_one(results) + study_two(results) + study_three(results) + across_studies(results)


# ------------------------------------------------------------------ verdict stability
def quantile(sorted_values, q):
    """Linear-interpolation quantile along the last axis of sorted values, +inf exact (as the
    reducer: equal neighbours give their value, a positive weight on +inf gives +inf)."""
    import numpy as np
    n = sorted_values.shape[-1]
    pos = q * (n - 1)
    lo, frac = int(math.floor(pos)), pos - math.floor(pos)
    a = sorted_values[..., lo]
    b = sorted_values[..., min(lo + 1, n - 1)]
    with np.errstate(invalid="ignore"):
        return np.where((frac == 0) | (a == b), a, a + frac * (b - a))


def resampled_stat_row(row, values, rng, inner):
    """The reducer's statistics of one cell (a stat row) recomputed on `values`: median, q25, q75,
    IQR and a percentile-bootstrap 95 % interval of the median from `inner` resamples."""
    import numpy as np
    v = np.sort(values)
    median, q25, q75 = (float(quantile(v, q)) for q in (0.5, 0.25, 0.75))
    boot = np.sort(rng.choice(v, size=(inner, len(v)), replace=True), axis=1)
    medians = np.sort(quantile(boot, 0.5))
    lo = medians[int(math.floor(0.025 * (inner - 1)))]
    hi = medians[int(math.ceil(0.975 * (inner - 1)))]
    iqr = math.inf if math.isinf(q75) else q75 - q25
    out = dict(row)
    out.update(median=repr(median), q25=repr(q25), q75=repr(q75), iqr=repr(iqr),
               ci_low=repr(float(lo)), ci_high=repr(float(hi)),
               done=str(int(np.sum(np.isfinite(v)))), diverged=str(int(np.sum(~np.isfinite(v)))))
    return out


def run_value(r):
    """A finished run's MSE as the reducer counts it (NaN -> +inf)."""
    v = float(r["mse"]) if r["mse"] not in ("", "nan") else math.inf
    return math.inf if math.isnan(v) else v


def stability(stat_rows, run_rows, resamples, seed=0, inner=1000, judge=verdict_name,
              joint=False):
    """Per statement tag, the share of `resamples` bootstrap resamples of every cell's finished
    seeds (each cell resampled once per round, shared by every study that shows it) that give the
    verdict the file gives (judge: verdict_name, or decided for the resolved-only reading).
    With `joint`, one draw of the seeds serves every cell (four_way.draw_seed_lists, the
    four-way reading's resamples): runs of one seed stay together across cells.
    Per-run quantities (the Jacobian statement) use the same resample."""
    import numpy as np
    rng = np.random.default_rng(seed)
    base = {tag: judge(comps) for tag, _, comps in all_claims(Results(stat_rows, run_rows))}
    cells = {}
    for r in run_rows:
        if r["status"] in ("done", "diverged"):
            key = (r["system"], r["model_label"], r["n_train"], r["size"], r["regularizer"])
            cells.setdefault(key, []).append(r)
    lists = four_way.draw_seed_lists(run_rows, resamples, seed) if joint else None
    same = {tag: 0 for tag in base}
    for b in range(resamples):
        if joint:
            by_seed = {key: {int(r["seed"]): r for r in rows} for key, rows in cells.items()}
            drawn = {key: [rows[s] for s in lists[b] if s in rows] for key, rows in by_seed.items()}
        else:
            drawn = {key: [rows[i] for i in rng.integers(0, len(rows), len(rows))]
                     for key, rows in cells.items()}
        new_stats = []
        for row in stat_rows:
            config = dict(DEFAULTS, **{row["axis"]: row["column"]})
            key = (row["system"], row["model"], config["n_train"], config["size"],
                   config["regularizer"])
            if key in drawn:
                values = [run_value(r) for r in drawn[key]]
                new_stats.append(resampled_stat_row(row, values, rng, inner))
            else:
                new_stats.append(row)
        new_runs = [r for rows in drawn.values() for r in rows]
        for tag, _, comps in all_claims(Results(new_stats, new_runs)):
            if tag in same and judge(comps) == base[tag]:
                same[tag] += 1
    return {tag: same[tag] / resamples for tag in base}


def comparisons_toml(stat_rows):
    """Every comparison with an interval that the statements make, as the `comparisons` key of an
    [adaptive] table (rule = "comparisons"): each distinct pair of cell selectors once, in the
    order the statements first make it. Built from the file's cells alone (results not read)."""
    del RECORDED[:]
    all_claims(Results(stat_rows, [], probes=True))
    pairs = list(dict.fromkeys(tuple(sorted(p)) for p in RECORDED))
    lines = ["comparisons = ["]
    lines += [f'  ["{a}", "{b}"],' for a, b in pairs]
    return "\n".join(lines + ["]"])


def report(results, path, problems=(), stable=None):
    claims = all_claims(results)
    lines = [f"# The paper's statements checked on {os.path.basename(path)}", ""]
    if FOUR_WAY is not None:
        lines += [f"Reading: four-way (`phnn reduce --comparisons`, equivalence margin "
                  f"x{FOUR_WAY.delta:g}); verdicts supported / contradicted / mixed / equivalent "
                  "/ partly / undecided (analysis/paper_claims.py's docstring).", ""]
    if problems:
        lines += [f"**Not the paper's settings: {'; '.join(problems)}.** The verdicts below describe "
                  "this file only; they do not confirm or contradict the paper.", ""]
    if stable is None:
        lines += ["| # | the paper says | our evidence | verdict |", "|---|---|---|---|"]
    else:
        lines += ["| # | the paper says | our evidence | verdict | same verdict in resamples |",
                  "|---|---|---|---|---|"]
    details = ["", "## Details", ""]
    for tag, text, comps in claims:
        if not comps:
            continue
        v, counts = verdict(comps)
        if stable is None:
            lines.append(f"| {tag} | {text} | {counts} | {v} |")
        else:
            share = stable.get(tag, math.nan)
            mark = " **unstable**" if share < STABLE else ""
            lines.append(f"| {tag} | {text} | {counts} | {v} | {100 * share:.0f} %{mark} |")
        details.append(f"**{tag}** {text}: {v}")
        details.extend(detail_line(c) for c in comps)
        details.append("")
    if stable is not None and FOUR_WAY is not None:
        lines.append(f"\nLast column: the share of bootstrap resamples of the seeds (drawn "
                     "jointly: one draw of seeds for every cell, so paired runs stay paired; "
                     "each resample's readings from `phnn reduce --comparisons --seed-lists`) "
                     f"that give the same verdict; below {100 * STABLE:.0f} % the verdict is "
                     "marked unstable (it rests on seeds at the margin).")
    elif stable is not None:
        scheme = " (drawn jointly: one draw of seeds for every cell)" if JOINT else ""
        lines.append(f"\nLast column: the share of bootstrap resamples of every cell's finished "
                     f"seeds{scheme} that give the same verdict; below {100 * STABLE:.0f} % the "
                     "verdict is marked unstable (it rests on seeds at the margin).")
    missing = [s for s in ("I", "II", "III") if not results.has(s)]
    if missing:
        lines.append(f"\nNot in the file (statements skipped): Study {', '.join(missing)}.")
    return "\n".join(lines + details)


def four_way_verdicts(stat_rows, run_rows, readings):
    """{tag: four-way verdict} of every statement, the reducer's readings given."""
    global FOUR_WAY
    FOUR_WAY = readings
    return {tag: verdict_name(comps) for tag, _, comps in all_claims(Results(stat_rows, run_rows))}


def read_four_way(path, stat_rows, run_rows, resamples, extra=()):
    """Sets FOUR_WAY from `phnn reduce --comparisons`; with resamples > 0 returns the stability
    shares (four_way.stability: joint seed resamples, one reduce call for all of them)."""
    global FOUR_WAY
    comparison_rows = run_csv("reduce", path, "--comparisons", *extra)
    stable = None
    if resamples:
        stable = four_way.stability(
            stat_rows, run_rows, comparison_rows, four_way_verdicts,
            lambda lists: four_way.reduce_seed_lists(run_csv, path, lists, extra), resamples,
            run_value=run_value)
    FOUR_WAY = four_way.FourWay.of_rows(comparison_rows, stat_rows)
    return stable


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="The paper's statements (§6 and conclusion) checked on a results file of "
        "sweeps/paper.toml: comparisons with intervals and a verdict per statement, as Markdown.",
        epilog="Verdicts: holds, same direction, partly, not supported, contradicted / mixed; "
        "with --reading four-way supported, contradicted / mixed, equivalent within x1.5, "
        "partly, undecided (the module's docstring says when). A file trained with fewer "
        "steps or seeds than the paper's is flagged at the top; --strict refuses it.")
    parser.add_argument("results", help="results file written by `phnn sweep sweeps/paper.toml`")
    parser.add_argument("--stability", type=int, default=0, metavar="N",
                        help="recompute every verdict on N bootstrap resamples of each cell's "
                        "seeds and show the share that agrees (below 90 %%: unstable)")
    parser.add_argument("--reading", choices=("overlap", "four-way"), default="overlap",
                        help="overlap (default): a comparison is resolved when the two median "
                        "intervals do not overlap; four-way: each comparison's reading from "
                        "`phnn reduce --comparisons` (A better / B better / equivalent / "
                        "undecided) and the verdicts of the docstring")
    parser.add_argument("--resample", choices=("cell", "joint"), default=None,
                        help="--stability: resample each cell's seeds on its own (cell, the "
                        "overlap reading's default) or draw the seeds once for every cell "
                        "(joint, the four-way reading's only scheme: paired runs stay paired)")
    parser.add_argument("--strict", action="store_true",
                        help="exit 1 without verdicts if the steps or seeds differ from the paper's")
    parser.add_argument("--write-comparisons", action="store_true",
                        help="print the comparisons the statements make, as the `comparisons` "
                        "key of a sweep file's [adaptive] table (rule = \"comparisons\"); reads "
                        "only the file's cells (a file with every run pending will do)")
    parser.add_argument("--round", type=int, default=None, metavar="K",
                        help="adaptive sweeps: the verdicts as they stood after round K (0: "
                        "every cell at its first seeds, e.g. the 10-seed verdicts)")
    parser.add_argument("--rule", metavar="SWEEP",
                        help="adaptive sweeps: replay the [adaptive] table of sweep file SWEEP "
                        "on the file's runs (`phnn reduce --rule`): the verdicts that rule gives")
    args = parser.parse_args(argv)
    if not os.path.exists(args.results):
        parser.error(f"{args.results}: no such file")
    if args.write_comparisons:
        print(comparisons_toml(reduce_csv(args.results)))
        return 0
    if args.round is not None and args.round < 0:
        parser.error("--round K needs K >= 0")
    extra = ("--round", str(args.round)) if args.round is not None else ()
    extra += ("--rule", args.rule) if args.rule else ()
    run_rows = reduce_csv(args.results, "--per-run", *extra)
    problems = setting_problems(run_rows)
    for p in problems:
        print(f"paper_claims.py: warning: {args.results}: {p}", file=sys.stderr)
    if problems and args.strict:
        print("paper_claims.py: --strict: not the paper's settings; no verdicts", file=sys.stderr)
        return 1
    if args.stability < 0:
        parser.error("--stability N needs N >= 0")
    stat_rows = reduce_csv(args.results, *extra)
    if args.reading == "four-way" and args.resample == "cell":
        parser.error("--reading four-way resamples the seeds jointly (its comparisons pair runs "
                     "by seed); drop --resample cell")
    global JOINT
    JOINT = args.resample == "joint"
    if args.reading == "four-way":
        stable = read_four_way(args.results, stat_rows, run_rows, args.stability, extra)
    else:
        stable = (stability(stat_rows, run_rows, args.stability, joint=JOINT)
                  if args.stability else None)
    results = Results(stat_rows, run_rows)
    title = args.results + (f" replaying {args.rule}" if args.rule else "") + (
        f" after round {args.round}" if args.round is not None else "")
    print(report(results, title, problems, stable))
    return 0


if __name__ == "__main__":
    sys.exit(main())
