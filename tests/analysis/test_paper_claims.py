#!/usr/bin/env python3
"""Unit tests of analysis/paper_claims.py: comparisons, verdicts, absence statements, and the
Study I statements on a synthetic reducer output (no phnn binary needed).

    /usr/bin/python3 tests/analysis/test_paper_claims.py
"""
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import paper_claims as pc  # noqa: E402


def cell(median, lo, hi, iqr=1.0):
    return pc.Cell(median, median - iqr / 2, median + iqr / 2, iqr, lo, hi, 10, 0, 10)


def stat_row(study, system, model, axis, column, median, lo, hi, iqr=1.0):
    return {"study": study, "system": system, "model": model, "axis": axis, "column": column,
            "median": str(median), "q25": "0", "q75": "0", "iqr": str(iqr),
            "ci_low": str(lo), "ci_high": str(hi), "done": "10", "diverged": "0",
            "expected": "10"}


class Compare(unittest.TestCase):
    def test_resolved_only_without_overlap(self):
        a, b = cell(1.0, 0.5, 1.5), cell(3.0, 2.0, 4.0)
        self.assertEqual(pc.compare("x", a, b)[1:3], (True, True))
        touching = cell(3.0, 1.5, 4.0)  # a.hi == b.lo: overlap, a tie
        self.assertEqual(pc.compare("x", a, touching)[1:3], (True, False))
        self.assertEqual(pc.compare("x", b, a)[1:3], (False, True))
        self.assertEqual(pc.compare("x", b, a, paper_says_lower=False)[1:3], (True, True))

    def test_absence_counts_only_a_resolved_occurrence(self):
        a, b = cell(1.0, 0.5, 1.5), cell(3.0, 2.0, 4.0)
        occurs = pc.absence(pc.compare("x", a, b))         # a resolved lower: happens
        self.assertEqual(occurs[1:3], (False, True))
        tie = pc.absence(pc.compare("x", a, cell(1.2, 0.4, 2.0)))
        self.assertEqual(tie[1:3], (True, None))
        reverse = pc.absence(pc.compare("x", b, a))        # resolved, but the other way
        self.assertEqual(reverse[1:3], (True, None))


class Verdict(unittest.TestCase):
    def c(self, ok, resolved):
        return pc.Comparison("x", ok, resolved)

    def test_each_verdict(self):
        self.assertEqual(pc.verdict([self.c(True, True)] * 3)[0], "holds")
        self.assertEqual(pc.verdict([self.c(True, True), self.c(True, False)])[0], "same direction")
        self.assertEqual(pc.verdict([self.c(True, True), self.c(False, False)])[0], "partly")
        self.assertEqual(pc.verdict([self.c(True, False), self.c(False, False)])[0], "not supported")
        self.assertEqual(pc.verdict([self.c(False, True), self.c(True, False)])[0], "contradicted")
        self.assertEqual(pc.verdict([self.c(False, True), self.c(True, True)])[0], "mixed")

    def test_direction_only(self):
        self.assertEqual(pc.verdict([self.c(True, None)] * 2)[0], "same direction")
        self.assertEqual(pc.verdict([self.c(True, None), self.c(False, None)])[0], "partly")
        self.assertIn("2 by direction only", pc.verdict([self.c(True, None)] * 2)[1])


class StudyOne(unittest.TestCase):
    def results(self, dg_harmonic_25):
        rows = []
        for system in pc.SYSTEMS:
            for model in ("NODE-RK2",) + pc.PHNN_MODELS:
                for i, col in enumerate(("25", "100", "400")):
                    m = 10.0 ** (-i)  # every cell drops by 10x per column, resolved
                    if model == "NODE-RK2":
                        m *= 5
                    rows.append(stat_row("I", system, model, "n_train", col, m, 0.8 * m, 1.2 * m))
        for r in rows:  # harmonic DG models at 25
            if r["system"] == "harmonic" and r["model"].endswith("-DG") and r["column"] == "25":
                r.update(median=str(dg_harmonic_25[0]), ci_low=str(dg_harmonic_25[1]),
                         ci_high=str(dg_harmonic_25[2]))
        return pc.Results(rows, [])

    def claim(self, res, tag):
        return next(c for c in pc.study_one(res) if c[0] == tag)

    def test_dg_vs_rk2_on_the_harmonic_oscillator(self):
        better = self.results((0.5, 0.45, 0.55))  # resolved below RK2's 1.0 (0.8, 1.2)
        self.assertEqual(pc.verdict(self.claim(better, "I.4")[2])[0], "holds")
        tie = self.results((0.9, 0.7, 1.1))
        self.assertEqual(pc.verdict(self.claim(tie, "I.4")[2])[0], "same direction")
        worse = self.results((2.0, 1.8, 2.2))
        self.assertEqual(pc.verdict(self.claim(worse, "I.4")[2])[0], "contradicted")

    def test_more_points_and_node(self):
        res = self.results((1.0, 0.8, 1.2))
        self.assertEqual(pc.verdict(self.claim(res, "I.1")[2])[0], "holds")
        self.assertEqual(pc.verdict(self.claim(res, "I.3")[2])[0], "holds")
        # PHNN-S on the self-sustained oscillator drops resolved here: against "about constant".
        self.assertEqual(pc.verdict(self.claim(res, "I.2")[2])[0], "contradicted")

    def test_shared_cells_are_counted_once_across_studies(self):
        rows = [stat_row(st, "duffing", m, axis, col, 1.0, 0.9, 1.1)
                for st, axis, col in (("I", "n_train", "25"), ("II", "size", "small"))
                for m in pc.PHNN_MODELS]
        res = pc.Results(rows, [])
        self.assertEqual(len(res.by_config), len(pc.PHNN_MODELS))


class Settings(unittest.TestCase):
    @staticmethod
    def run_row(seed, steps="50000", status="done", model="NODE-RK2"):
        return {"system": "duffing", "model_label": model, "n_train": "25", "size": "small",
                "regularizer": "none", "seed": str(seed), "steps": steps, "status": status}

    def test_the_papers_settings_pass(self):
        rows = [self.run_row(s) for s in range(10)] + [self.run_row(s, model="PHNN-S-DG")
                                                        for s in range(12)]
        self.assertEqual(pc.setting_problems(rows), [])

    def test_fewer_steps_or_finished_seeds_are_named(self):
        rows = [self.run_row(s, steps="600") for s in range(2)]
        problems = pc.setting_problems(rows)
        self.assertEqual(len(problems), 2)
        self.assertIn("600 Adam steps per run (paper: 50000)", problems[0])
        self.assertIn("as few as 2 finished seeds per cell", problems[1])
        pending = [self.run_row(s, status="pending" if s > 3 else "done") for s in range(10)]
        self.assertEqual(pc.setting_problems(pending),
                         ["as few as 4 finished seeds per cell (paper: 10)"])

    def test_the_report_flags_them_and_bullets_do_not_nest(self):
        a, b = cell(1.0, 0.5, 1.5), cell(3.0, 2.0, 4.0)
        res = pc.Results([], [])
        text = pc.report(res, "x.h5", ["600 Adam steps per run (paper: 50000)"])
        self.assertIn("**Not the paper's settings: 600 Adam steps", text)
        self.assertEqual(pc.detail_line(pc.compare("x", b, a)),
                         "- against the paper: x: 3 (2, 4) >= 1 (0.5, 1.5) [resolved]")
        self.assertTrue(pc.detail_line(pc.compare("x", a, b)).startswith("- for the paper: x: "))


class Stability(unittest.TestCase):
    @staticmethod
    def cell_rows(column, values):
        """Per-run rows of harmonic NODE-RK2 at N_train `column`, and its stat row (the stats
        as the reducer would give them, from resampled_stat_row on the values themselves)."""
        import numpy as np
        runs = [{"system": "harmonic", "model_label": "NODE-RK2", "n_train": column,
                 "size": "small", "regularizer": "none", "seed": str(k), "steps": "50000",
                 "status": "done", "mse": repr(v)} for k, v in enumerate(values)]
        base = {"study": "I", "system": "harmonic", "model": "NODE-RK2", "axis": "n_train",
                "column": column, "expected": str(len(values))}
        return runs, pc.resampled_stat_row(base, values, np.random.default_rng(1), 2000)

    def test_decided_reads_resolved_comparisons_only(self):
        def c(ok, resolved):
            return pc.Comparison("x", ok, resolved)
        self.assertEqual(pc.decided([c(True, True)] * 2), "holds")
        self.assertEqual(pc.decided([c(True, True), c(False, False)]), "for, in part")
        # The verdicts "same direction", "partly" and "not supported" of ties alone differ by the
        # directions of the tied medians; decided() gives all three the same answer.
        for ties in ([c(True, False)] * 2, [c(True, False), c(False, False)], [c(False, False)]):
            self.assertEqual(pc.decided(ties), "undecided")
        self.assertEqual(pc.decided([c(False, True), c(True, False)]), "against")
        self.assertEqual(pc.decided([c(False, True), c(True, True)]), "split")
        self.assertEqual(pc.decided([c(True, None), c(False, None)]), "by direction only")
        self.assertEqual(pc.decided([c(True, None), c(True, True)]), "holds")  # intervals only

    def stability_of(self, low_n, high_n):
        r25, s25 = self.cell_rows("25", low_n)
        r100, s100 = self.cell_rows("100", high_n)
        return pc.stability([s25, s100], r25 + r100, resamples=60, inner=300)["I.1"]

    def test_quantiles_follow_the_reducer_with_infinity(self):
        import numpy as np
        v = np.array([1.0, 2.0, math.inf, math.inf])
        self.assertEqual(float(pc.quantile(v, 0.5)), math.inf)   # between 2 and +inf
        self.assertEqual(float(pc.quantile(v, 0.25)), 1.75)
        self.assertEqual(float(pc.quantile(v, 0.75)), math.inf)   # equal neighbours
        self.assertEqual(float(pc.quantile(np.arange(1.0, 6.0), 0.5)), 3.0)

    def test_a_clear_comparison_is_stable_a_marginal_one_is_not(self):
        clear = self.stability_of([10.0 + k for k in range(10)], [1.0 + k * 0.1 for k in range(10)])
        self.assertEqual(clear, 1.0)
        # N_train 100 a hair below 25 on most seeds: the direction flips in some resamples.
        marginal = self.stability_of([1.0 + k for k in range(10)], [0.9 + k for k in range(10)])
        self.assertLess(marginal, 0.9)

    def test_joint_resamples_keep_a_paired_direction(self):
        # N_train 100 a hair below 25 on every seed: resampled per cell the medians' order flips;
        # drawn jointly (one draw of seeds for both cells) it never does (order statistics keep
        # the seed-wise order), so the verdict "same direction" holds in every resample.
        r25, s25 = self.cell_rows("25", [1.0 + k for k in range(10)])
        r100, s100 = self.cell_rows("100", [0.9 + k for k in range(10)])
        joint = pc.stability([s25, s100], r25 + r100, resamples=60, inner=300, joint=True)
        self.assertEqual(joint["I.1"], 1.0)
        cell = pc.stability([s25, s100], r25 + r100, resamples=60, inner=300)
        self.assertLess(cell["I.1"], 0.9)

    def test_a_tie_whose_direction_flips_is_stably_undecided(self):
        # Two alike cells: the medians' order flips between resamples, so the verdict ("same
        # direction" / "not supported") is unstable, but "undecided" holds in every resample.
        r25, s25 = self.cell_rows("25", [1.0 + k for k in range(10)])
        r100, s100 = self.cell_rows("100", [1.0 + k + 0.01 * (-1) ** k for k in range(10)])
        judged = pc.stability([s25, s100], r25 + r100, resamples=60, inner=300, judge=pc.decided)
        self.assertEqual(judged["I.1"], 1.0)
        plain = pc.stability([s25, s100], r25 + r100, resamples=60, inner=300)
        self.assertLess(plain["I.1"], 0.9)

    def test_the_report_shows_the_share_and_marks_unstable_ones(self):
        r25, s25 = self.cell_rows("25", [1.0 + k for k in range(10)])
        r100, s100 = self.cell_rows("100", [0.9 + k for k in range(10)])
        res = pc.Results([s25, s100], r25 + r100)
        text = pc.report(res, "x.h5", (), {"I.1": 0.5})
        self.assertIn("| same verdict in resamples |", text)
        self.assertIn("| 50 % **unstable** |", text)


class WriteComparisons(unittest.TestCase):
    """--write-comparisons: the cells every interval comparison reads, as sweep-file selectors."""

    def rows(self):
        rows = []
        for system in pc.SYSTEMS:
            for model in ("NODE-RK2",) + pc.PHNN_MODELS:
                for col in ("25", "100", "400"):  # no results: the cells alone
                    rows.append(stat_row("I", system, model, "n_train", col, "", "", ""))
        return rows

    def test_pairs_name_cells_and_families_once(self):
        text = pc.comparisons_toml(self.rows())
        lines = text.splitlines()
        self.assertEqual((lines[0], lines[-1]), ("comparisons = [", "]"))
        pairs = lines[1:-1]
        self.assertEqual(len(pairs), len(set(pairs)))  # each pair once
        # I.4: harmonic PHNN-S DG vs RK2 at N_train 25, one model per side.
        self.assertIn('  ["harmonic/phnn-s-dg/25/small/none", "harmonic/phnn-s-rk2/25/small/none"],',
                      pairs)
        # I.1: the same model at two N_train.
        self.assertIn('  ["duffing/node-rk2/100/small/none", "duffing/node-rk2/25/small/none"],',
                      pairs)
        # I.8: the best of a family against a single model: one '+'-joined side.
        self.assertTrue(any('"self-sustained/phnn-s-dg+phnn-s-rk2/400/small/none"' in p
                            and '"self-sustained/node-rk2/400/small/none"' in p for p in pairs))
        for p in pairs:
            for selector in p.strip(" [],").split('", "'):
                fields = selector.strip('"').split("/")
                self.assertEqual(len(fields), 5, selector)
                self.assertIn(fields[0], pc.SYSTEMS)
        self.assertGreaterEqual(len(pc.RECORDED), len(pairs))  # duplicates merged


class VerdictTable(unittest.TestCase):
    def test_rows_marked_where_columns_differ(self):
        import verdict_table as vt
        a = {"I.1": ("holds", None), "I.4": ("same direction", 0.95)}
        b = {"I.1": ("holds", None), "I.4": ("partly", 0.5)}
        lines = vt.table([a, b], ["x.h5@0", "x.h5"]).splitlines()
        self.assertEqual(lines[0], "| # | x.h5@0 | x.h5 | differ |")
        self.assertEqual(lines[2], "| I.1 | holds | holds |  |")
        self.assertEqual(lines[3], "| I.4 | same direction (95 %) | partly (50 %!) | **yes** |")


if __name__ == "__main__":
    unittest.main()
