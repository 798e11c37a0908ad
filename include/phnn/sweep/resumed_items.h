// include/phnn/sweep/resumed_items.h — work items with a saved training
// state (phnn/store/cell_checkpoint.h) planned again exactly as they were,
// so they go on from it whatever the new plan would group
// (docs/DECISIONS.md, "Preemptible cells").
#pragma once

#include <string>
#include <vector>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/work_plan.h"

namespace phnn {

/// What identifies an item's state: "<sweep key>\n<run id> <run id>...", the
/// sweep key being what else a state must match (phnn sweep: the sweep
/// text's hash, the build's git commit and the thread count).
std::string item_key(const Grid& grid, const std::vector<int>& runs,
                     const std::string& sweep_hash);

/// Rank 0 before planning: every saved state whose runs are all still in
/// `pending` (one cell, this sweep key) becomes an item of exactly those
/// runs, and its runs leave `pending`; a state whose runs are all in `keep`
/// (runs trained ahead of the round in progress, per cell) stays for a later
/// round; states of finished or foreign runs, of another build, and scratch
/// files of a save cut short are deleted. Returns the items' runs
/// (Grid::runs indices), in file order.
std::vector<std::vector<int>> resumed_groups(const Grid& grid,
                                             std::vector<std::vector<int>>* pending,
                                             const std::string& out,
                                             const std::string& sweep_hash,
                                             const std::vector<std::vector<int>>& keep = {});

/// The plan's items with the resumed groups first (they are partly done
/// and go on at once).
std::vector<WorkItem> with_resumed(const Grid& grid, const std::vector<std::vector<int>>& groups,
                                   std::vector<WorkItem> planned);

}  // namespace phnn
