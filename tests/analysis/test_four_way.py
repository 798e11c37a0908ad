#!/usr/bin/env python3
"""analysis/paper_claims.py --reading four-way (analysis/four_way.py): the verdict rule on made-up
readings, and on a results file trained here (tests/fixtures/claims-2026-11-28.toml, 360 runs of
20 steps, about a minute) that `phnn reduce --comparisons`, the adaptive rule's four-way reading
(`[adaptive] reading = "four-way"`, replayed by `phnn reduce --rule`) and paper_claims.py read
every comparison of the statements alike.

    /usr/bin/python3 tests/analysis/test_four_way.py [PHNN]   (without PHNN: the unit tests only)
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "analysis"))
import four_way  # noqa: E402
import paper_claims as pc  # noqa: E402
from phnn_tool import run_csv  # noqa: E402

# The binary, from argv (popped before unittest reads argv).
PHNN = os.path.abspath(sys.argv.pop(1)) if len(sys.argv) > 1 else None
if PHNN:
    os.environ["PHNN"] = PHNN


def c(reading, ok=True):
    return pc.Comparison("x", ok, None, reading)


class Verdict(unittest.TestCase):
    def test_each_verdict(self):
        v = lambda *readings: four_way.verdict([c(r) for r in readings])[0]  # noqa: E731
        self.assertEqual(v("for", "for"), "supported")
        self.assertEqual(v("against", "undecided"), "contradicted")
        self.assertEqual(v("against", "for"), "mixed")
        self.assertEqual(v("equivalent", "equivalent"), "equivalent within x1.5")
        self.assertEqual(v("for", "equivalent"), "partly")
        self.assertEqual(v("for", "undecided"), "partly")
        self.assertEqual(v("equivalent", "undecided"), "undecided")
        self.assertEqual(four_way.verdict([])[0], "no data")

    def test_direction_only_comparisons(self):
        self.assertEqual(four_way.verdict([c(None), c(None, ok=False)])[0], "partly")
        self.assertEqual(four_way.verdict([c("for"), c(None, ok=False)])[0], "partly")
        self.assertEqual(four_way.verdict([c("for"), c(None)])[0], "supported")
        self.assertIn("1 by direction only", four_way.verdict([c("for"), c(None)])[1])

    def test_claim_terms_and_absences(self):
        self.assertEqual(four_way.claim_reading("A better", True), "for")
        self.assertEqual(four_way.claim_reading("A better", False), "against")
        self.assertEqual(four_way.claim_reading("B better", True), "against")
        self.assertEqual(four_way.claim_reading("equivalent", False), "equivalent")
        resolved = lambda r: pc.Comparison("x", True, r in ("for", "against"), r)  # noqa: E731
        # "does not improve": the improvement is against, no improvement (or worse) for.
        self.assertEqual(pc.absence(resolved("for")).reading, "against")
        self.assertEqual(pc.absence(resolved("against")).reading, "for")
        self.assertEqual(pc.absence(resolved("equivalent")).reading, "for")
        self.assertEqual(pc.absence(resolved("undecided")).reading, "undecided")
        # "about constant": a difference either way is against.
        both = resolved("against")
        self.assertEqual(pc.absence(both, happens=both.resolved).reading, "against")

    def test_lookup_finds_either_order_and_flips(self):
        stat = [{"study": "I", "system": "duffing", "model": m, "axis": "n_train", "column": col}
                for m in ("NODE-RK2", "PHNN-S-DG") for col in ("25", "100")]
        rows = [{"a": "I/duffing/NODE-RK2/25", "b": "I/duffing/PHNN-S-DG/25", "delta": "1.5",
                 "reading": "B better"}]
        fw = four_way.FourWay.of_rows(rows, stat)
        node = ("duffing", "NODE-RK2", "25", "small", "none")
        dg = ("duffing", "PHNN-S-DG", "25", "small", "none")
        self.assertEqual(fw.reading(node, dg), "B better")
        self.assertEqual(fw.reading(dg, node), "A better")
        with self.assertRaises(KeyError):
            fw.reading(node, ("duffing", "PHNN-S-DG", "100", "small", "none"))


class Recording(four_way.FourWay):
    """A FourWay that keeps every look-up: (a key, b key, reading of a against b)."""

    def __init__(self, base):
        super().__init__(base.readings, base.names, base.delta)
        self.asked = []

    def reading(self, a_key, b_key):
        r = super().reading(a_key, b_key)
        self.asked.append((a_key, b_key, r))
        return r


def key_of_selector(selector):
    system, models, n_train, size, reg = selector.split("/")
    labels = {m.upper() for m in models.split("+")}
    return system, labels, n_train, size, reg


@unittest.skipIf(PHNN is None, "needs the phnn binary")
class OnTrainedFile(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="phnn_four_way_")
        cls.sweep = os.path.join(ROOT, "tests", "fixtures", "claims-2026-11-28.toml")
        cls.path = os.path.join(cls.dir, "claims.h5")
        subprocess.run([PHNN, "sweep", cls.sweep, "--out", cls.path], check=True,
                       stdout=subprocess.DEVNULL)
        cls.stat = run_csv("reduce", cls.path, "--format", "csv")
        cls.runs = run_csv("reduce", cls.path, "--per-run")
        cls.csv = run_csv("reduce", cls.path, "--comparisons")
        cls.fw = Recording(four_way.FourWay.of_rows(cls.csv, cls.stat))
        pc.FOUR_WAY = cls.fw
        try:
            cls.claims = pc.all_claims(pc.Results(cls.stat, cls.runs))
        finally:
            pc.FOUR_WAY = None

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_paper_claims_reads_the_reducers_row_of_each_comparison(self):
        by_names = {(r["a"], r["b"]): r["reading"] for r in self.csv}
        self.assertGreater(len(self.fw.asked), 100)
        for a, b, reading in self.fw.asked:
            found = [(na, nb) for na in self.fw.names[a] for nb in self.fw.names[b]
                     if (na, nb) in by_names or (nb, na) in by_names]
            self.assertTrue(found, (a, b))
            for na, nb in found:  # every table that shows both cells reads them alike
                direct = by_names.get((na, nb)) or four_way.FLIP[by_names[(nb, na)]]
                self.assertEqual(direct, reading, (na, nb))
        seen = {r for _, _, r in self.fw.asked}
        self.assertTrue({"undecided", "equivalent"} <= seen and seen & {"A better", "B better"},
                        seen)

    def test_the_adaptive_four_way_rule_grows_exactly_the_undecided_comparisons(self):
        toml = subprocess.run([sys.executable, os.path.join(ROOT, "analysis", "paper_claims.py"),
                               self.path, "--write-comparisons"], check=True, capture_output=True,
                              text=True, env=dict(os.environ, PHNN=PHNN)).stdout
        rule = os.path.join(self.dir, "rule.toml")
        with open(self.sweep) as f, open(rule, "w") as out:
            out.write(f.read() + '\n[adaptive]\nmax_seeds = 8\nbatch = 2\nrule = "comparisons"\n'
                      'reading = "four-way"\n' + toml + "\n")
        grown = {(r["system"], r["model_label"], r["n_train"], r["size"], r["regularizer"])
                 for r in run_csv("reduce", self.path, "--rule", rule, "--per-run")
                 if int(r["seed"]) >= 6}
        undecided = {k for a, b, r in self.fw.asked if r == "undecided" for k in (a, b)}
        decided = {k for a, b, r in self.fw.asked if r != "undecided" for k in (a, b)}
        self.assertTrue(undecided and decided - undecided)
        self.assertEqual(grown, undecided)

    def test_stability_is_deterministic_and_runs_every_statement(self):
        args = [sys.executable, os.path.join(ROOT, "analysis", "paper_claims.py"), self.path,
                "--reading", "four-way", "--stability", "4"]
        env = dict(os.environ, PHNN=PHNN)
        first = subprocess.run(args, check=True, capture_output=True, text=True, env=env).stdout
        again = subprocess.run(args, check=True, capture_output=True, text=True, env=env).stdout
        self.assertEqual(first, again)
        self.assertIn("same verdict in resamples", first)
        self.assertIn("drawn jointly", first)
        for tag in ("I.1", "II.4", "III.1", "§6.4"):
            self.assertIn(f"| {tag} |", first)


if __name__ == "__main__":
    unittest.main()
