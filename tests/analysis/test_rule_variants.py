#!/usr/bin/env python3
"""Unit tests of analysis/rule_variants.py: a variant's sweep file and the table's counts.

    /usr/bin/python3 tests/analysis/test_rule_variants.py
"""
import os
import sys
import tomllib
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "analysis"))
import rule_variants as rv  # noqa: E402

BASE = """name = "p"
[grid]
seeds = "0-9"
[adaptive]
max_seeds = 40
batch = 5
rule = "comparisons"
futility = true      # a comment
comparisons = [
  ["a/b/25/small/none", "a/c/25/small/none"],
]
"""


class VariantToml(unittest.TestCase):
    def test_keys_replaced_added_and_comparisons_kept(self):
        name, keys = rv.parse_variant("fw=reading:four-way,futility:false,stop_confidence:0.99")
        self.assertEqual(name, "fw")
        text = rv.variant_toml(BASE, keys)
        t = tomllib.loads(text)
        self.assertEqual(t["adaptive"]["reading"], "four-way")
        self.assertIs(t["adaptive"]["futility"], False)
        self.assertEqual(t["adaptive"]["stop_confidence"], 0.99)
        self.assertEqual(t["adaptive"]["batch"], 5)
        self.assertEqual(t["adaptive"]["comparisons"],
                         [["a/b/25/small/none", "a/c/25/small/none"]])
        self.assertEqual(t["grid"], {"seeds": "0-9"})
        self.assertEqual(text.count("futility"), 1)

    def test_the_base_rule_and_bad_specs(self):
        self.assertEqual(rv.variant_toml(BASE, rv.parse_variant("lean=")[1]), BASE)
        for bad in ("=futility:true", "x=futility", "x=:true", "x=futility:"):
            with self.assertRaises(ValueError):
                rv.parse_variant(bad)
        with self.assertRaises(ValueError):
            rv.variant_toml('name = "p"\n', {})


class Row(unittest.TestCase):
    def test_counts_stable_same_and_both(self):
        reference = {"I.1": ("mixed", 0.5), "I.2": ("partly", 1.0), "I.3": ("supported", 0.95)}
        own = {"I.1": ("mixed", 0.95), "I.2": ("mixed", 0.99), "I.3": ("supported", 0.6)}
        # stable: I.1, I.2; same: I.1, I.3; both: I.1.
        self.assertEqual(rv.row("r", 10, 0.394, own, reference), "| r | 10 | 39 % | 2 | 2 | 1 |")


if __name__ == "__main__":
    unittest.main()
