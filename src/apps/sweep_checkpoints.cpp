// src/apps/sweep_checkpoints.cpp — see apps/sweep_checkpoints.h. Touches
// the item and rung state files under `<results>.journal/` only.
#include "apps/sweep_checkpoints.h"

#include <cstdio>
#include <iostream>

#include "phnn/store/cell_checkpoint.h"

namespace phnn {
namespace apps {

ItemCheckpoints::ItemCheckpoints(const std::string& out, const std::string& key,
                                 double interval_s, std::function<bool()> stop, std::string prefix)
    : path_(cell_checkpoint_path(out, key)), key_(key), prefix_(std::move(prefix)) {
  adopt(path_, key_);
  checkpointing_.interval_s = interval_s;
  checkpointing_.stop_requested = std::move(stop);
  checkpointing_.save = [this](const std::string& state, int step) {
    try {
      write_cell_checkpoint(path_, CellCheckpoint{key_, state, step});
      saved_step_ = step;
    } catch (const std::exception& e) {
      if (!warned_) {
        std::fprintf(stderr, "%scannot save the training state (%s); training goes on\n",
                     prefix_.c_str(), e.what());
      }
      warned_ = true;
    }
  };
}

void ItemCheckpoints::remove() const { remove_cell_checkpoint(path_); }

void ItemCheckpoints::go_on_from(const std::string& path, const std::string& key) {
  if (resume_step_ == 0) adopt(path, key);
}

void ItemCheckpoints::adopt(const std::string& path, const std::string& key) {
  CellCheckpoint saved;
  std::string problem;
  if (read_cell_checkpoint(path, &saved, &problem) && saved.key == key) {
    checkpointing_.resume_from = std::move(saved.state);
    resume_step_ = saved.step;
  } else if (!problem.empty()) {
    std::fprintf(stderr, "%s%s; training the item from the start\n", prefix_.c_str(),
                 problem.c_str());
  }
}

void ItemCheckpoints::keep_final(const std::string& path, const std::string& key) {
  checkpointing_.save_final = [this, path, key](const std::string& state, int step) {
    try {
      write_cell_checkpoint(path, CellCheckpoint{key, state, step});
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%scannot keep the rung's training state (%s); the next rung trains "
                   "from the start\n", prefix_.c_str(), e.what());
    }
  };
}

}  // namespace apps
}  // namespace phnn
