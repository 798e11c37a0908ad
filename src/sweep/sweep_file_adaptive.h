// src/sweep/sweep_file_adaptive.h — the [adaptive] table of a sweep file
// (sweeps/FORMAT.md): its keys, its comparisons' cell selectors, and what it
// does to the studies' seeds. Internal to the parser.
#pragma once

#include "phnn/sweep/sweep_file.h"
#include "sweep/sweep_file_values.h"

namespace phnn {

/// Reads the keys of [adaptive] (`e` is the table's entry): max_seeds, batch,
/// rule, comparisons. Fails at the line of an unknown key or a bad value.
AdaptiveSpec read_adaptive_table(const Entry& e, const ValueReader& values);

/// With the studies built: every study must have the same `seeds` (round 0),
/// at most max_seeds of them; each comparison's selectors must name cells of
/// some study (and no study may vary `lambdas`, which a selector cannot name).
/// Then extends every study's seeds to max_seeds (the next seed numbers
/// above the largest). `line`: of the [adaptive] header.
void apply_adaptive(SweepSpec* spec, int line, const ValueReader& values);

}  // namespace phnn
