// src/data/recording_split.cpp — a few long recordings into a data set by
// time blocks (split_in_blocks, include/phnn/data/measured.h; docs/METHOD.md
// "Measured data"): per recording a training, a validation and an inference
// block in time order, every sample pair inside a block, inference windows
// inside the last block. In memory only; touches nothing but its arguments.
#include <algorithm>
#include <climits>
#include <cmath>
#include <utility>

#include "data/measured_checks.h"
#include "phnn/data/counter_rng.h"
#include "phnn/data/measured.h"

namespace phnn {
namespace {

using internal::fail;
using internal::g;

// Sample ranges [0, b1), [b1, b2), [b2, n) of one recording.
struct Blocks {
  std::size_t b1 = 0, b2 = 0, n = 0;
};

// b1 = round(f_train N), b2 = b1 + round(f_validation N); every block >= 2
// samples (one pair, or a window of one step).
Blocks cut(const MeasuredTrajectory& m, const ImportOptions& o) {
  Blocks b;
  b.n = m.size();
  if (b.n > static_cast<std::size_t>(INT_MAX)) {
    fail(m.where(0) + " has " + std::to_string(b.n) + " samples; phnn takes at most " +
         std::to_string(INT_MAX) + " per recording: split it in two");
  }
  const double n = static_cast<double>(b.n);
  b.b1 = static_cast<std::size_t>(std::llround(o.train_fraction * n));
  b.b2 = b.b1 + static_cast<std::size_t>(std::llround(o.validation_fraction * n));
  if (b.b1 < 2 || b.b2 < b.b1 + 2 || b.b2 + 2 > b.n) {
    fail(m.where(0) + " has " + std::to_string(b.n) + " samples: blocks of " +
         g(o.train_fraction) + ", " + g(o.validation_fraction) + " and the rest of them leave " +
         std::to_string(b.b1) + ", " + std::to_string(b.b2 - std::min(b.b1, b.b2)) + " and " +
         std::to_string(b.n - std::min(b.n, b.b2)) +
         " samples; every block needs at least 2: record longer or change --blocks");
  }
  return b;
}

// A pair (recording index, sample n): (x_n, u_n, x_n+1) of that recording.
using PairRef = std::pair<std::size_t, std::size_t>;

// Every pair with both samples in [begin, end) of each recording, in time order.
std::vector<PairRef> block_pairs(const std::vector<Blocks>& blocks, bool training) {
  std::vector<PairRef> refs;
  for (std::size_t r = 0; r < blocks.size(); ++r) {
    const std::size_t begin = training ? 0 : blocks[r].b1, end = training ? blocks[r].b1 : blocks[r].b2;
    for (std::size_t n = begin; n + 1 < end; ++n) refs.emplace_back(r, n);
  }
  return refs;
}

// The first k of a Fisher-Yates shuffle of `refs` by `rng` (k = size: all).
void shuffle_prefix(std::vector<PairRef>* refs, std::size_t k, CounterRng rng) {
  for (std::size_t i = 0; i < k && i + 1 < refs->size(); ++i) {
    const std::size_t j = i + static_cast<std::size_t>(rng.below(refs->size() - i));
    std::swap((*refs)[i], (*refs)[j]);
  }
  refs->resize(std::min(k, refs->size()));
}

// Window starts b2, b2 + W, ... with the whole window in [b2, n), taken
// round-robin over the recordings (window k of every recording before
// window k + 1 of any), at most `cap`: (recording, start).
std::vector<PairRef> window_starts(const std::vector<Blocks>& blocks, std::size_t w, std::size_t cap) {
  std::vector<PairRef> out;
  for (std::size_t k = 0;; ++k) {
    bool any = false;
    for (std::size_t r = 0; r < blocks.size() && out.size() < cap; ++r) {
      const std::size_t start = blocks[r].b2 + k * w;
      if (start + w <= blocks[r].n) out.emplace_back(r, start), any = true;
    }
    if (!any || out.size() >= cap) return out;
  }
}

// W = round(window / h) + 1 samples, or the shortest inference block.
std::size_t window_samples(const std::vector<Blocks>& blocks, const ImportOptions& o, double h) {
  std::size_t shortest = blocks[0].n - blocks[0].b2, longest = 0;
  for (const Blocks& b : blocks) {
    shortest = std::min(shortest, b.n - b.b2), longest = std::max(longest, b.n - b.b2);
  }
  if (o.window == 0) return shortest;
  const auto w = static_cast<std::size_t>(std::llround(o.window / h)) + 1;
  if (w < 2) fail("--window " + g(o.window) + " s is shorter than one sample step (" + g(h) + " s)");
  if (w > longest) {
    fail("--window " + g(o.window) + " s (" + std::to_string(w) + " samples) is longer than every "
         "inference block (the longest holds " + std::to_string(longest) + " samples, " +
         g(h * static_cast<double>(longest - 1)) + " s): shorten --window or give the inference "
         "block a larger share with --blocks");
  }
  return w;
}

}  // namespace

PhSystemData split_in_blocks(const PhSystem& system, std::vector<MeasuredTrajectory> recs,
                             const ImportOptions& o, std::string* summary) {
  if (recs.empty()) fail("no recording was read; give at least one CSV or HDF5 file with samples");
  for (const MeasuredTrajectory& m : recs) internal::check_trajectory(m, system.n_x(), system.n_u());
  internal::sort_by_id(&recs);
  const double h = internal::common_step(recs, o, summary);
  std::vector<Blocks> blocks;
  for (const MeasuredTrajectory& m : recs) blocks.push_back(cut(m, o));

  PhSystemData data = labelled_ph_system_data(system);
  data.train.step = data.validation.step = data.inference.step = h;
  std::vector<PairRef> train = block_pairs(blocks, true), validation = block_pairs(blocks, false);
  const std::size_t validation_pairs = validation.size();
  shuffle_prefix(&train, train.size(),
                 CounterRng::for_trajectory(o.data_seed, system.rng_id(), 0, CounterRng::kBlockPairOrder));
  if (validation.size() > static_cast<std::size_t>(o.num_validation)) {
    shuffle_prefix(&validation, static_cast<std::size_t>(o.num_validation),
                   CounterRng::for_trajectory(o.data_seed, system.rng_id(), 0, CounterRng::kBlockValidation));
    std::sort(validation.begin(), validation.end());
  }
  for (const auto& [r, n] : train) internal::add_pair(recs[r], n, &data.train);
  for (const auto& [r, n] : validation) internal::add_pair(recs[r], n, &data.validation);
  const std::size_t w = window_samples(blocks, o, h);
  const std::vector<PairRef> starts = window_starts(blocks, w, static_cast<std::size_t>(o.num_inference));
  internal::add_windows(recs, starts, w, /*positions=*/true, &data.inference);

  DatasetOptions& d = data.options;
  internal::record_timing(&d, o.data_seed, h, w);
  d.alpha = 0.0;
  for (const Blocks& b : blocks) d.alpha = std::max(d.alpha, h * static_cast<double>(b.b1 - 1));
  d.num_trajectories = static_cast<int>(recs.size());
  d.num_train_max = static_cast<int>(data.train.size());
  d.num_validation = static_cast<int>(data.validation.size());
  d.num_inference = static_cast<int>(data.inference.size());
  const double rest = 1.0 - o.train_fraction - o.validation_fraction;
  data.split = "blocks: train " + g(o.train_fraction) + ", validation " + g(o.validation_fraction) +
               ", inference " + g(rest) + " of each recording's samples, in time order; inference "
               "windows of " + std::to_string(w) + " samples (" + g(d.beta) + " s)";
  if (summary) {
    *summary += std::to_string(recs.size()) + " recording" + (recs.size() == 1 ? "" : "s") +
                " cut in time: training " + g(o.train_fraction) + ", validation " +
                g(o.validation_fraction) + ", inference " + g(rest) + " of each one's samples\n";
    *summary += std::to_string(data.train.size()) + " training pairs (every pair of the training "
                "blocks), " + std::to_string(data.validation.size()) + " validation pairs" +
                (validation_pairs > data.validation.size()
                     ? " (drawn from " + std::to_string(validation_pairs) + ")" : std::string()) +
                ", " + std::to_string(data.inference.size()) + " inference window" +
                (data.inference.size() == 1 ? "" : "s") + " of " + g(d.beta) + " s\n";
  }
  return data;
}

}  // namespace phnn
