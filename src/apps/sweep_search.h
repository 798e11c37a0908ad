// src/apps/sweep_search.h — what `phnn sweep` adds for a [search] sweep
// (successive halving, phnn/sweep/search.h): the rung state each item keeps
// for the next rung and goes on from, the round line, the dry run.
#pragma once

#include <string>
#include <vector>

#include "apps/sweep_checkpoints.h"
#include "phnn/sweep/adaptive.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/work_plan.h"

namespace phnn {
namespace apps {

/// The item of `runs` (one cell, at one rung) goes on from the previous
/// rung's final state of the same configuration and seeds, if it is in the
/// journal directory of `out` under the same `build_key` (the binary and
/// thread count), and keeps its own final state unless it is at the last
/// rung. Nothing for sweeps without [search].
void link_rung_states(const SweepSpec& spec, const Grid& grid, const std::vector<int>& runs,
                      const std::string& out, const std::string& build_key,
                      ItemCheckpoints* checkpoints);

/// "phnn sweep: search rung 1 (15000 steps): 9 configurations go on ..." for
/// the rung in progress.
std::string search_round_line(const SweepSpec& spec, const AdaptiveState& state);

/// "search complete after rung 2: ..." or "" (not complete, or no [search]).
std::string search_complete_line(const SweepSpec& spec, const Grid& grid,
                                 const AdaptiveState& state);

/// --dry-run of a [search] sweep: rung 0's schedule, then the cost model's
/// estimate of the rungs (each group keeping ceil(n / eta), going on from
/// the rung before) against every configuration trained to the last rung.
std::string search_dry_run(const SweepSpec& spec, const Grid& grid, const std::vector<int>& ranks,
                           const SplitOptions& split);

}  // namespace apps
}  // namespace phnn
