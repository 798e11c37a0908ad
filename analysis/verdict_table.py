#!/usr/bin/env python3
"""The paper's verdicts (analysis/paper_claims.py) side by side for several results files, or for
one adaptive sweep after different rounds: one row per statement, one column per file.

    /usr/bin/python3 analysis/verdict_table.py results/s1-default.h5@0 results/s1-default.h5 \\
        results/s1-haswell.h5@0 results/s1-haswell.h5 [--stability 200]

FILE@K reads an adaptive sweep as it stood after round K (`phnn reduce --round K`; @0: every cell
at its first seeds); FILE@SWEEP (a path, not a number) replays the [adaptive] table of sweep file
SWEEP on FILE's runs (`phnn reduce --rule SWEEP`: what that rule would have concluded). A row
whose verdicts differ is marked; --stability N adds, per column, the share of N bootstrap
resamples of the seeds that give that column's verdict. --decided prints what the resolved
comparisons alone decide instead (paper_claims.decided: holds, for in part, undecided, against,
split, by direction only), blind to the directions of tied medians.
"""
import argparse
import sys

import paper_claims as pc


def verdicts(spec, resamples=0, judge=pc.verdict_name):
    """{tag: (verdict, share or None)} of one FILE[@K] or FILE[@SWEEP]."""
    path, _, at = spec.partition("@")
    extra = () if not at else ("--round", at) if at.isdigit() else ("--rule", at)
    run_rows = pc.reduce_csv(path, "--per-run", *extra)
    stat_rows = pc.reduce_csv(path, *extra)
    claims = pc.all_claims(pc.Results(stat_rows, run_rows))
    stable = pc.stability(stat_rows, run_rows, resamples, judge=judge) if resamples else {}
    return {tag: (judge(comps), stable.get(tag)) for tag, _, comps in claims if comps}


def table(columns, labels):
    """Markdown: statements in the first column's order, then any only the others have."""
    tags = []
    for col in columns:
        tags += [t for t in col if t not in tags]
    lines = ["| # | " + " | ".join(labels) + " | differ |", "|---|" + "---|" * (len(labels) + 1)]
    for tag in tags:
        cells, seen = [], set()
        for col in columns:
            v, share = col.get(tag, ("—", None))
            seen.add(v)
            mark = "" if share is None else f" ({100 * share:.0f} %{'!' if share < pc.STABLE else ''})"
            cells.append(v + mark)
        lines.append(f"| {tag} | " + " | ".join(cells) + f" | {'**yes**' if len(seen) > 1 else ''} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="+", metavar="FILE[@K|@SWEEP]",
                        help="results files; @K: an adaptive sweep after round K; @SWEEP: "
                        "sweep file SWEEP's [adaptive] rule replayed on the file's runs")
    parser.add_argument("--stability", type=int, default=0, metavar="N",
                        help="add each verdict's share of N bootstrap resamples (! below 90 %%)")
    parser.add_argument("--decided", action="store_true",
                        help="what the resolved comparisons alone decide, instead of the verdict")
    args = parser.parse_args(argv)
    judge = pc.decided if args.decided else pc.verdict_name
    columns = [verdicts(f, args.stability, judge) for f in args.files]
    print(table(columns, args.files))
    return 0


if __name__ == "__main__":
    sys.exit(main())
