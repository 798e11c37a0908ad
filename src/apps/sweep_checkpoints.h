// src/apps/sweep_checkpoints.h — preemptible cells in `phnn sweep`: each
// work item's training state saved beside the journals
// (phnn/store/cell_checkpoint.h) while it trains and read back when the item
// is trained again (phnn/sweep/resumed_items.h plans it as it was)
// (docs/DECISIONS.md, "Preemptible cells").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "phnn/training/trainer.h"

namespace phnn {
namespace apps {

/// One item's checkpointing: reads the saved state if there is one
/// (resume_step() > 0), saves every `interval_s` and when `stop` says so
/// (asked at every step: a signal, or the end of the round it trains ahead of),
/// and remove() deletes the state once the item's results are journaled.
/// A state that cannot be written is reported once on stderr and training
/// goes on (it is only lost work, never a lost result).
class ItemCheckpoints {
 public:
  ItemCheckpoints(const std::string& out, const std::string& key, double interval_s,
                  std::function<bool()> stop, std::string prefix);
  ItemCheckpoints(const ItemCheckpoints&) = delete;  // `save` refers to this object
  ItemCheckpoints& operator=(const ItemCheckpoints&) = delete;
  const CellCheckpointing& checkpointing() const { return checkpointing_; }
  /// The step the saved state ends (0: none, start afresh).
  int resume_step() const { return resume_step_; }
  /// Start afresh (the saved state did not fit the cell).
  void forget_state() {
    checkpointing_.resume_from.clear();
    resume_step_ = 0;
  }
  const std::string& path() const { return path_; }
  /// [search]: without a state of its own, the item goes on from the state
  /// at `path` if it is there under `key` (a smaller rung's final state).
  void go_on_from(const std::string& path, const std::string& key);
  /// [search]: the state after the last step goes to `path` under `key`,
  /// for the next rung (a state that cannot be written is reported once:
  /// the next rung then trains from the start).
  void keep_final(const std::string& path, const std::string& key);
  /// The last step saved (0: none).
  int saved_step() const { return saved_step_; }
  void remove() const;

 private:
  // Resumes from the state at `path` if it is there under `key` (a damaged
  // one is reported on stderr and ignored).
  void adopt(const std::string& path, const std::string& key);

  std::string path_, key_, prefix_;
  CellCheckpointing checkpointing_;
  int resume_step_ = 0, saved_step_ = 0;
  bool warned_ = false;
};

}  // namespace apps
}  // namespace phnn
