#!/usr/bin/env python3
"""Adaptive rules replayed side by side on one results file: per rule, the runs it asks for, its
cost by the cost model against every cell at max_seeds, how many of the paper's verdicts are stable
in the four-way reading, and how many equal the file's own verdicts (read without a rule: on a file
with every cell at max_seeds, the verdicts of all the seeds).

    /usr/bin/python3 analysis/rule_variants.py results/paper-40.h5 sweeps/paper-adaptive.toml \\
        --variant "lean=" \\
        --variant "four-way, futility=reading:four-way,futility:true" \\
        --variant "four-way, batch 10=reading:four-way,futility:false,grow:both,batch:10" \\
        --stability 200

Each --variant is NAME=KEY:VALUE,...: BASE's [adaptive] table with those keys set (values in TOML:
true, 0.99, 10; anything else is a string), its `comparisons` kept. Every rule reads the same
runs (`phnn reduce --rule`), so the table compares rules, not seeds. Needs every run a rule asks
for in FILE (a file with every cell at max_seeds, e.g. sweeps/paper-40.toml's, has them all);
missing runs are counted as pending and named on stderr by adaptive_cost.py's rule.
The phnn binary: $PHNN, else build/phnn.
"""
import argparse
import os
import re
import sys
import tempfile

import adaptive_cost
import paper_claims

STABLE = 0.9


def toml_value(text):
    """A --variant value as TOML: booleans and numbers as written, anything else quoted."""
    if text in ("true", "false") or re.fullmatch(r"-?\d+(\.\d*)?([eE]-?\d+)?", text):
        return text
    return '"' + text.replace('"', '\\"') + '"'


def parse_variant(spec):
    """'NAME=key:value,key:value' -> (NAME, {key: TOML text})."""
    name, _, body = spec.partition("=")
    if not name:
        raise ValueError(f"--variant {spec!r}: give NAME=KEY:VALUE,... (NAME= for BASE's own rule)")
    keys = {}
    for item in filter(None, body.split(",")):
        key, sep, value = item.partition(":")
        if not sep or not key.strip() or not value.strip():
            raise ValueError(f"--variant {spec!r}: {item!r} is not KEY:VALUE")
        keys[key.strip()] = toml_value(value.strip())
    return name, keys


def variant_toml(base_text, keys):
    """BASE's text with its [adaptive] table's scalar keys replaced or added (comparisons and every
    other table unchanged). The table must be BASE's last, as in the shipped sweep files."""
    head, sep, table = base_text.partition("[adaptive]\n")
    if not sep:
        raise ValueError("the base sweep file has no [adaptive] table")
    lines = table.splitlines(keepends=True)
    cut = next((i for i, line in enumerate(lines) if line.startswith("comparisons")), len(lines))
    kept = [line for line in lines[:cut]
            if "=" not in line or line.split("=", 1)[0].strip() not in keys]
    added = [f"{k} = {v}\n" for k, v in keys.items()]
    return head + sep + "".join(kept + added + lines[cut:])


def verdicts(path, extra, resamples):
    """{tag: (verdict, share of resamples that agree)} of the paper's statements read four-way."""
    run_rows = paper_claims.reduce_csv(path, "--per-run", *extra)
    stat_rows = paper_claims.reduce_csv(path, *extra)
    stable = paper_claims.read_four_way(path, stat_rows, run_rows, resamples, extra) or {}
    named = paper_claims.four_way_verdicts(stat_rows, run_rows, paper_claims.FOUR_WAY)
    return {tag: (v, stable.get(tag, float("nan"))) for tag, v in named.items() if v != "no data"}


def rule_cost(path, sweep):
    """(runs asked for, cost-model share of every cell at max_seeds) of SWEEP's rule on PATH."""
    s, _, _ = adaptive_cost.summarize_sweep(path, sweep, rule=True)
    return s["runs"], s["model_trained"] / s["model_full"]


def row(name, runs, share, own, reference):
    stable = sum(1 for _, s in own.values() if s >= STABLE)
    same = sum(1 for t, (v, _) in own.items() if reference.get(t, (None,))[0] == v)
    both = sum(1 for t, (v, s) in own.items() if s >= STABLE and reference.get(t, (None,))[0] == v)
    return f"| {name} | {runs} | {100 * share:.0f} % | {stable} | {same} | {both} |"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="results file holding every run the rules ask for")
    parser.add_argument("base", help="sweep file whose [adaptive] table the variants change")
    parser.add_argument("--variant", action="append", required=True, metavar="NAME=KEY:VALUE,...")
    parser.add_argument("--stability", type=int, default=200, metavar="N",
                        help="joint seed resamples per reading (default 200)")
    args = parser.parse_args(argv)
    try:
        variants = [parse_variant(v) for v in args.variant]
    except ValueError as e:
        parser.error(str(e))
    base_text = open(args.base).read()
    reference = verdicts(args.results, (), args.stability)
    lines = ["| rule | runs | cost | stable | same as the file | stable and same |",
             "|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for name, keys in variants:
            sweep = os.path.join(tmp, "variant.toml")
            with open(sweep, "w") as f:
                f.write(variant_toml(base_text, keys))
            runs, share = rule_cost(args.results, sweep)
            own = verdicts(args.results, ("--rule", sweep), args.stability)
            lines.append(row(name, runs, share, own, reference))
            print(lines[-1], file=sys.stderr)
    stable = sum(1 for _, s in reference.values() if s >= STABLE)
    lines.append(f"| the file itself | | | {stable} | {len(reference)} | {stable} |")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
