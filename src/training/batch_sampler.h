// src/training/batch_sampler.h — per-member minibatch order of the trainer
// (private to src/training). Touches no file.
#pragma once

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <torch/torch.h>

#include "phnn/data/counter_rng.h"
#include "training/state_bytes.h"

namespace phnn {

// Per-member minibatch order: member e reshuffles its own permutation every
// epoch from its own stream, so its batches do not depend on the stack.
class BatchSampler {
 public:
  BatchSampler(const std::vector<int>& seeds, int n, int batch) : n_(n), batch_(batch) {
    for (int s : seeds) {
      rngs_.emplace_back(mix64(static_cast<std::uint64_t>(s) ^ 0x7368756666ULL));
      std::vector<int64_t> p(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) p[static_cast<std::size_t>(i)] = i;
      perms_.push_back(p);
    }
  }
  // [E, b] indices of the next minibatch.
  torch::Tensor next() {
    const int64_t E = static_cast<int64_t>(perms_.size());
    if (n_ <= batch_) {
      return torch::arange(n_, torch::kLong).unsqueeze(0).expand({E, n_}).contiguous();
    }
    if (cursor_ == 0) {
      for (std::size_t e = 0; e < perms_.size(); ++e) {  // Fisher-Yates
        auto& p = perms_[e];
        for (std::size_t i = p.size() - 1; i > 0; --i) {
          std::swap(p[i], p[rngs_[e].below(i + 1)]);
        }
      }
    }
    const int size = std::min(batch_, n_ - cursor_);
    auto idx = torch::empty({E, size}, torch::kLong);
    auto a = idx.accessor<int64_t, 2>();
    for (int64_t e = 0; e < E; ++e)
      for (int j = 0; j < size; ++j)
        a[e][j] = perms_[static_cast<std::size_t>(e)][static_cast<std::size_t>(cursor_ + j)];
    cursor_ += size;
    if (cursor_ >= n_) cursor_ = 0;
    return idx;
  }

  // Position in the epoch, each member's permutation and stream: a sampler
  // restored from them gives the same batches as this one from here on.
  void save(internal::StateWriter* out) const {
    out->put<std::int32_t>(cursor_);
    for (std::size_t e = 0; e < perms_.size(); ++e) {
      out->put<std::uint64_t>(rngs_[e].counter());
      out->put_vector(perms_[e]);
    }
  }
  void restore(internal::StateReader* in) {
    cursor_ = in->get<std::int32_t>();
    for (std::size_t e = 0; e < perms_.size(); ++e) {
      rngs_[e] = CounterRng(rngs_[e].key(), in->get<std::uint64_t>());
      perms_[e] = in->get_vector<int64_t>();
      if (perms_[e].size() != static_cast<std::size_t>(n_)) {
        throw std::invalid_argument("training state: a batch order of another N_train");
      }
    }
  }

 private:
  int n_, batch_, cursor_ = 0;
  std::vector<CounterRng> rngs_;
  std::vector<std::vector<int64_t>> perms_;
};

}  // namespace phnn
