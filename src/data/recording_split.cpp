// src/data/recording_split.cpp — a few long recordings into a data set by
// time blocks (ImportSplit::kBlocks of split_measured_stream,
// include/phnn/data/measured.h; docs/METHOD.md "Measured data"): per
// recording a training, a validation and an inference block in time order,
// every sample pair inside a block, inference windows inside the last
// block. The first pass cuts the blocks and draws every pair's row, the
// second copies each recording's pairs to their rows. In memory only;
// touches nothing but its arguments.
#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "data/measured_checks.h"
#include "phnn/data/counter_rng.h"
#include "phnn/data/measured.h"

namespace phnn {
namespace internal {
namespace {

// Sample ranges [0, b1), [b1, b2), [b2, n) of one recording.
struct Blocks {
  std::size_t b1 = 0, b2 = 0, n = 0;
};

// b1 = round(f_train N), b2 = b1 + round(f_validation N); every block >= 2
// samples (one pair, or a window of one step).
Blocks cut(const RecordingScan& scan, std::size_t i, const ImportOptions& o) {
  Blocks b;
  b.n = static_cast<std::size_t>(scan[i].samples);
  if (b.n > static_cast<std::size_t>(INT_MAX)) {
    fail(scan.where(i) + " has " + std::to_string(b.n) + " samples; phnn takes at most " +
         std::to_string(INT_MAX) + " per recording: split it in two");
  }
  const double n = static_cast<double>(b.n);
  b.b1 = static_cast<std::size_t>(std::llround(o.train_fraction * n));
  b.b2 = b.b1 + static_cast<std::size_t>(std::llround(o.validation_fraction * n));
  if (b.b1 < 2 || b.b2 < b.b1 + 2 || b.b2 + 2 > b.n) {
    fail(scan.where(i) + " has " + std::to_string(b.n) + " samples: blocks of " +
         g(o.train_fraction) + ", " + g(o.validation_fraction) + " and the rest of them leave " +
         std::to_string(b.b1) + ", " + std::to_string(b.b2 - std::min(b.b1, b.b2)) + " and " +
         std::to_string(b.n - std::min(b.n, b.b2)) +
         " samples; every block needs at least 2: record longer or change --blocks");
  }
  return b;
}

// A (recording, sample) pair: a window's recording and first sample.
using PairRef = std::pair<std::size_t, std::size_t>;

// The first k of a Fisher-Yates shuffle of `refs` by `rng` (k = size: all).
void shuffle_prefix(std::vector<std::uint32_t>* refs, std::size_t k, CounterRng rng) {
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

// What the first pass decides, recording by recording in id order (r):
// its blocks; the time-order index of its first training and validation
// pair among all recordings' (prefix sums, R + 1 entries); the row of each
// training pair (the time order shuffled by stream kBlockPairOrder); the
// validation pairs kept (time-order indices, ascending: all, or
// num_validation drawn by stream kBlockValidation); the inference windows
// (w samples from start, round-robin) and, sorted by recording, (r, window).
struct BlockPlan {
  std::vector<Blocks> blocks;
  std::vector<std::size_t> train_first, validation_first;
  std::vector<std::uint32_t> train_row, validation_kept;
  std::size_t w = 0;
  std::vector<PairRef> starts, windows_by_recording;
};

// 0, 1, ..., count - 1 as 32-bit indices (a pair's place among count).
std::vector<std::uint32_t> indices(std::size_t count, const char* what) {
  if (count > std::numeric_limits<std::uint32_t>::max()) {
    fail("the recordings hold " + std::to_string(count) + " " + what + " pairs; phnn import "
         "takes at most " + std::to_string(std::numeric_limits<std::uint32_t>::max()) +
         ": import fewer recordings or give the block a smaller share with --blocks");
  }
  std::vector<std::uint32_t> out(count);
  std::iota(out.begin(), out.end(), 0u);
  return out;
}

BlockPlan plan_blocks(const PhSystem& system, const RecordingScan& scan,
                      const std::vector<std::uint32_t>& order, const ImportOptions& o, double h) {
  BlockPlan p;
  p.train_first.push_back(0);
  p.validation_first.push_back(0);
  for (const std::uint32_t i : order) {
    p.blocks.push_back(cut(scan, i, o));
    p.train_first.push_back(p.train_first.back() + p.blocks.back().b1 - 1);
    p.validation_first.push_back(p.validation_first.back() + p.blocks.back().b2 - p.blocks.back().b1 - 1);
  }
  p.w = window_samples(p.blocks, o, h);
  p.starts = window_starts(p.blocks, p.w, static_cast<std::size_t>(o.num_inference));
  for (std::size_t q = 0; q < p.starts.size(); ++q) p.windows_by_recording.emplace_back(p.starts[q].first, q);
  std::sort(p.windows_by_recording.begin(), p.windows_by_recording.end());
  {
    std::vector<std::uint32_t> shuffled = indices(p.train_first.back(), "training");
    shuffle_prefix(&shuffled, shuffled.size(),
                   CounterRng::for_trajectory(o.data_seed, system.rng_id(), 0, CounterRng::kBlockPairOrder));
    p.train_row = inverse(shuffled);
  }
  p.validation_kept = indices(p.validation_first.back(), "validation");
  const auto cap = static_cast<std::size_t>(o.num_validation);
  if (p.validation_kept.size() > cap) {
    shuffle_prefix(&p.validation_kept, cap,
                   CounterRng::for_trajectory(o.data_seed, system.rng_id(), 0, CounterRng::kBlockValidation));
    std::sort(p.validation_kept.begin(), p.validation_kept.end());
  }
  return p;
}

// The second pass for recording r (`m`): its training pairs to their rows,
// its kept validation pairs to theirs (in time order), its windows.
void copy_recording(const BlockPlan& p, std::size_t r, const MeasuredTrajectory& m,
                    MeasuredDataSet* set, WindowCollector* windows) {
  const Blocks& b = p.blocks[r];
  for (std::size_t n = 0; n + 1 < b.b1; ++n) set_pair(&set->train, p.train_row[p.train_first[r] + n], m, n);
  const auto& kept = p.validation_kept;
  const auto lo = std::lower_bound(kept.begin(), kept.end(), p.validation_first[r]);
  const auto hi = std::lower_bound(lo, kept.end(), p.validation_first[r + 1]);
  for (auto it = lo; it != hi; ++it) {
    set_pair(&set->validation, static_cast<std::size_t>(it - kept.begin()), m,
             b.b1 + (*it - p.validation_first[r]));
  }
  const auto by_recording = [](const PairRef& a, const PairRef& c) { return a.first < c.first; };
  const auto mine = std::equal_range(p.windows_by_recording.begin(), p.windows_by_recording.end(),
                                     PairRef{r, 0}, by_recording);
  for (auto it = mine.first; it != mine.second; ++it) {
    windows->add(it->second, m, p.starts[it->second].second);
  }
}

// What the options, the split attribute and the summary say of the cut.
void describe(MeasuredDataSet* set, const BlockPlan& p, const ImportOptions& o, double h,
              std::size_t recordings, std::string* summary) {
  DatasetOptions& d = set->data.options;
  record_timing(&d, o.data_seed, h, p.w);
  d.alpha = 0.0;
  for (const Blocks& b : p.blocks) d.alpha = std::max(d.alpha, h * static_cast<double>(b.b1 - 1));
  d.num_trajectories = static_cast<int>(recordings);
  d.num_train_max = static_cast<int>(set->train.size());
  d.num_validation = static_cast<int>(set->validation.size());
  d.num_inference = static_cast<int>(set->inference.size());
  const double rest = 1.0 - o.train_fraction - o.validation_fraction;
  set->data.split = "blocks: train " + g(o.train_fraction) + ", validation " + g(o.validation_fraction) +
                    ", inference " + g(rest) + " of each recording's samples, in time order; "
                    "inference windows of " + std::to_string(p.w) + " samples (" + g(d.beta) + " s)";
  if (!summary) return;
  const std::size_t validation_pairs = p.validation_first.back(), kept = set->validation.size();
  const std::size_t windows = set->inference.size();
  *summary += std::to_string(recordings) + " recording" + (recordings == 1 ? "" : "s") +
              " cut in time: training " + g(o.train_fraction) + ", validation " +
              g(o.validation_fraction) + ", inference " + g(rest) + " of each one's samples\n";
  *summary += std::to_string(set->train.size()) + " training pairs (every pair of the training "
              "blocks), " + std::to_string(kept) + " validation pairs" +
              (validation_pairs > kept ? " (drawn from " + std::to_string(validation_pairs) + ")"
                                       : std::string()) +
              ", " + std::to_string(windows) + " inference window" + (windows == 1 ? "" : "s") +
              " of " + g(d.beta) + " s\n";
}

}  // namespace

// Pass 1: every recording checked, sorted by id, the common step, the plan;
// pass 2: each recording's pairs and windows to their places.
MeasuredDataSet split_recordings_in_blocks(const PhSystem& system, const TrajectorySource& source,
                                           const ImportOptions& o, std::string* summary) {
  RecordingScan scan(system.n_x(), system.n_u(), o.time_tolerance);
  source([&](const MeasuredTrajectory& m) { scan.add(m); });
  if (scan.size() == 0) fail("no recording was read; give at least one CSV or HDF5 file with samples");
  scan.throw_check_error();
  const std::vector<std::uint32_t> order = scan.sorted_by_id();
  const double h = scan.common_step(order, o, summary);
  const BlockPlan plan = plan_blocks(system, scan, order, o, h);

  MeasuredDataSet set{labelled_ph_system_data(system),
                      PhPairRows(system.n_x(), system.n_u(), plan.train_row.size()),
                      PhPairRows(system.n_x(), system.n_u(), plan.validation_kept.size()), PhInferenceRows()};
  set.data.train.step = set.data.validation.step = set.data.inference.step = h;
  set.train.step = set.validation.step = h;
  WindowCollector windows(system.n_x(), system.n_u(), plan.starts.size(), plan.w, /*positions=*/true, h);
  const std::vector<std::uint32_t> rank = inverse(order);  // read index -> r
  std::size_t k = 0;
  source([&](const MeasuredTrajectory& m) {
    scan.check_same(k, m);
    copy_recording(plan, rank[k++], m, &set, &windows);
  });
  scan.check_all_seen(k);
  set.inference = windows.finish();
  describe(&set, plan, o, h, scan.size(), summary);
  return set;
}

}  // namespace internal

PhSystemData split_in_blocks(const PhSystem& system, std::vector<MeasuredTrajectory> recordings,
                             const ImportOptions& options, std::string* summary) {
  return to_ph_system_data(
      internal::split_recordings_in_blocks(system, trajectories_of(recordings), options, summary));
}

}  // namespace phnn
