// src/data/trajectory_split.cpp — many short recorded trajectories into a
// data set, one role each (ImportSplit::kTrajectories of
// split_measured_stream, include/phnn/data/measured.h; docs/METHOD.md
// "Measured data"): the first pass orders them, the second reduces each
// training or validation trajectory to its drawn pair and keeps the
// inference ones. In memory only; touches nothing but its arguments.
#include <algorithm>
#include <limits>

#include "data/measured_checks.h"
#include "phnn/data/counter_rng.h"

namespace phnn {
namespace internal {
namespace {

// The split order: sorted by id (unique ids), then shuffled by split_seed
// (Fisher-Yates on one counter stream) when it is >= 0. Read indices.
std::vector<std::uint32_t> split_order(const RecordingScan& scan, const ImportOptions& o) {
  std::vector<std::uint32_t> order = scan.sorted_by_id();
  if (o.split_seed < 0) return order;
  CounterRng rng(mix64(static_cast<std::uint64_t>(o.split_seed) ^ 0x73706c6974ULL));  // "split"
  for (std::size_t i = order.size(); i > 1; --i) {
    std::swap(order[i - 1], order[static_cast<std::size_t>(rng.below(i))]);
  }
  return order;
}

// The positions n a pair (x_n, x_n+1) of `m` may take: those with
// t_n+1 - t_0 <= window (all when window = 0); 0 when none does.
int pair_positions(const MeasuredTrajectory& m, double window) {
  if (window <= 0) return static_cast<int>(m.t.size()) - 1;
  int positions = 0;
  while (positions + 1 < static_cast<int>(m.t.size()) &&
         m.t[static_cast<std::size_t>(positions) + 1] - m.t[0] <= window * (1 + 1e-9)) {
    ++positions;
  }
  return positions;
}

// The pair of one training or validation trajectory, drawn among its
// positions keyed by its id (as generated data's), into row i of `rows`;
// false when it has no position (*error: the message).
bool draw_pair(const PhSystem& system, const MeasuredTrajectory& m, const ImportOptions& o,
               PhPairRows* rows, std::size_t i, std::string* error) {
  const int positions = pair_positions(m, o.pair_window);
  if (positions == 0) {
    *error = m.where(0) + ": no pair ends within --pair-window " + g(o.pair_window) + " s of its "
             "start (the second sample is at " + g(m.t[1] - m.t[0]) + " s); widen the window";
    return false;
  }
  CounterRng pick = CounterRng::for_trajectory(o.data_seed, system.rng_id(), m.id,
                                               CounterRng::kTrainingPair);
  set_pair(rows, i, m, static_cast<std::size_t>(pick.below(static_cast<std::uint64_t>(positions))));
  return true;
}

// What the options and the summary record of the split: the rate, the
// split sizes, the pair window and the inference duration; no generation.
void describe(MeasuredDataSet* set, const ImportOptions& options, double h, std::size_t samples,
              double longest, std::size_t total, std::size_t num_train, std::string* summary) {
  DatasetOptions& o = set->data.options;
  record_timing(&o, options.data_seed, h, samples);
  o.alpha = std::min(options.pair_window > 0 ? options.pair_window : longest, o.beta);
  o.num_trajectories = static_cast<int>(total);
  o.num_train_max = static_cast<int>(num_train);
  o.num_validation = options.num_validation;
  o.num_inference = options.num_inference;
  const std::string order = options.split_seed >= 0
                                ? "shuffled by split seed " + std::to_string(options.split_seed)
                                : std::string("in the order of their ids");
  set->data.split = "trajectories: one pair per training or validation trajectory, the last " +
                    std::to_string(options.num_inference) + " for inference, " + order;
  if (!summary) return;
  *summary += std::to_string(num_train) + " training, " + std::to_string(options.num_validation) +
              " validation, " + std::to_string(options.num_inference) + " inference trajectories (" +
              order + ")\n";
  *summary += "inference trajectories cut to " + std::to_string(samples) + " samples (" +
              g(o.beta) + " s), the shortest of them\n";
}

}  // namespace

// Pass 1: every trajectory checked, ordered (split_order), the common step;
// the last num_inference in that order infer (cut to the shortest), the
// num_validation before them validate, the rest train. Pass 2: each
// trajectory to its row or window as it passes by.
MeasuredDataSet split_by_trajectories(const PhSystem& system, const TrajectorySource& source,
                                      const ImportOptions& options, std::string* summary) {
  RecordingScan scan(system.n_x(), system.n_u(), options.time_tolerance);
  source([&](const MeasuredTrajectory& m) { scan.add(m); });
  const long total = static_cast<long>(scan.size());
  const long held = static_cast<long>(options.num_validation) + options.num_inference;
  if (total < held + 1) {
    fail("the data hold " + std::to_string(total) + " trajectories; " +
         std::to_string(options.num_validation) + " for validation, " +
         std::to_string(options.num_inference) + " for inference and at least 1 for training "
         "need " + std::to_string(held + 1) + ": lower --num-validation / --num-inference or "
         "record more trajectories");
  }
  scan.throw_check_error();
  std::vector<std::uint32_t> order = split_order(scan, options);
  const double h = scan.common_step(order, options, summary);
  const auto num_train = static_cast<std::size_t>(total - held);
  const auto num_validation = static_cast<std::size_t>(options.num_validation);
  const std::size_t infer_begin = num_train + num_validation;
  std::size_t samples = std::numeric_limits<std::size_t>::max();
  for (std::size_t i = infer_begin; i < order.size(); ++i) {
    samples = std::min(samples, static_cast<std::size_t>(scan[order[i]].samples));
  }
  const std::vector<std::uint32_t> place = inverse(order);  // read index -> split position
  std::vector<std::uint32_t>().swap(order);

  MeasuredDataSet set{labelled_ph_system_data(system), PhPairRows(system.n_x(), system.n_u(), num_train),
                      PhPairRows(system.n_x(), system.n_u(), num_validation), PhInferenceRows()};
  set.data.train.step = set.data.validation.step = set.data.inference.step = h;
  set.train.step = set.validation.step = h;
  WindowCollector windows(system.n_x(), system.n_u(), static_cast<std::size_t>(options.num_inference),
                          samples, /*positions=*/false, h);
  double longest = 0.0;
  std::size_t k = 0, first_error = scan.size();
  std::string error;  // draw_pair's, of the first trajectory in split order that fails
  source([&](const MeasuredTrajectory& m) {
    scan.check_same(k, m);
    const std::size_t i = place[k++];
    if (i >= infer_begin) return windows.add(i - infer_begin, m, 0);
    longest = std::max(longest, m.t.back() - m.t.front());
    std::string message;
    const bool drawn = i < num_train
                           ? draw_pair(system, m, options, &set.train, i, &message)
                           : draw_pair(system, m, options, &set.validation, i - num_train, &message);
    if (!drawn && i < first_error) first_error = i, error = message;
  });
  scan.check_all_seen(k);
  if (!error.empty()) fail(error);
  set.inference = windows.finish();
  describe(&set, options, h, samples, longest, scan.size(), num_train, summary);
  return set;
}

}  // namespace internal
}  // namespace phnn
