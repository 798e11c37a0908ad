// include/phnn/store/cell_checkpoint.h — the saved training states of a
// sweep's cells in progress (CellCheckpointing in phnn/training/trainer.h),
// one file per work item beside the journals:
// `<results path>.journal/cell-<16 hex digits>.state`, replaced atomically.
#pragma once

#include <string>
#include <vector>

namespace phnn {

/// One saved state: the work item it belongs to (`key`: the sweep's hash
/// and the run ids of the item, as the sweep writes it) and the trainer's
/// opaque bytes.
struct CellCheckpoint {
  std::string key;
  std::string state;
  /// The training step the state ends (for messages).
  int step = 0;
};

/// Where the state of the item with `key` lives:
/// journal_directory(results_path) + "/cell-" + hex64(fnv1a64(key)) + ".state".
std::string cell_checkpoint_path(const std::string& results_path, const std::string& key);

/// Where the final training state of a [search] rung's item lives, for the
/// next rung's item of the same runs to go on from:
/// journal_directory(results_path) + "/rung-" + hex64(fnv1a64(key)) + ".state"
/// (same layout; list_cell_checkpoints does not list them).
std::string rung_state_path(const std::string& results_path, const std::string& key);

/// Writes `checkpoint` to `path` through `<path>.writing`, fsync, rename and
/// a directory fsync: the file holds the previous state or the whole new
/// one. Creates the journal directory if needed. Throws std::runtime_error
/// naming the file and the system's reason (e.g. a full disk); the previous
/// state is then still there.
void write_cell_checkpoint(const std::string& path, const CellCheckpoint& checkpoint);

/// Reads the state at `path`. Returns false and leaves *out alone if there
/// is none; returns false and sets *problem (if given) to the reason if the
/// file is damaged or torn (its checksum fails) — the caller then trains the
/// item from the start.
///
/// Layout: "phnn-cell-checkpoint 1\n", "step <s>\n", "key <n>\n" and n bytes, "\nstate
/// <m>\n" and m bytes, "\nfnv1a64 <16 hex digits>\n" (FNV-1a 64 of all the
/// bytes before "fnv1a64").
bool read_cell_checkpoint(const std::string& path, CellCheckpoint* out,
                          std::string* problem = nullptr);

/// The state files in the journal directory of `results_path` (paths,
/// sorted); none if there is no directory.
std::vector<std::string> list_cell_checkpoints(const std::string& results_path);

/// Removes the state file at `path` if there is one; never throws.
void remove_cell_checkpoint(const std::string& path);

}  // namespace phnn
