// src/data/measured.cpp — recorded trajectories into a data set (checks,
// sample rate, split, pair draws) and a generated set's trajectories back
// (include/phnn/data/measured.h). In memory only.
#include "phnn/data/measured.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "phnn/common/check.h"
#include "phnn/common/cr_math.h"
#include "data/measured_checks.h"
#include "phnn/data/counter_rng.h"

namespace phnn {
namespace internal {

void fail(const std::string& message) { throw MeasuredDataError(message); }

std::string g(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

// Shapes, finite values, >= 2 samples, increasing time.
void check_trajectory(const MeasuredTrajectory& m, int nx, int nu) {
  const std::size_t n = m.size();
  PHNN_CHECK(m.n_x == nx && m.n_u == nu && m.x.size() == n * static_cast<std::size_t>(nx) &&
                 m.u.size() == n * static_cast<std::size_t>(nu),
             "ragged trajectory from the reader");
  if (n < 2) {
    fail(m.where(0) + " has " + std::to_string(n) + " sample; a training pair (x_n, x_n+1) needs "
         "at least 2: drop it or record longer");
  }
  const auto finite = [](const double* v, int count) {
    return std::all_of(v, v + count, [](double a) { return std::isfinite(a); });
  };
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(m.t[k]) || !finite(m.x.data() + k * static_cast<std::size_t>(nx), nx) ||
        !finite(m.u.data() + k * static_cast<std::size_t>(nu), nu)) {
      fail(m.where(k) + ": a value is NaN or infinite; remove "
           "or repair the sample (phnn needs every state and input finite)");
    }
    if (k > 0 && !(m.t[k] > m.t[k - 1])) {
      fail(m.where(k) + ": t = " + g(m.t[k]) +
           " does not increase (previous " + g(m.t[k - 1]) + "); sort the samples by time");
    }
  }
}

namespace {

// h of one trajectory, checked uniform: every step within tol h of the
// median step (a gap or one bad stamp cannot shift the reference), then h =
// (t_N-1 - t_0) / (N - 1), the most accurate estimate once uniform.
double uniform_step(const MeasuredTrajectory& m, double tolerance) {
  std::vector<double> steps;
  for (std::size_t k = 1; k < m.t.size(); ++k) steps.push_back(m.t[k] - m.t[k - 1]);
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (std::size_t k = 1; k < m.t.size(); ++k) {
    const double dt = steps[k - 1];
    if (std::abs(dt - median) > tolerance * median) {
      fail(m.where(k) + ": t jumps by " + g(dt) + " s where the trajectory's step is " + g(median) +
           " s (" + (dt > 1.5 * median ? "a gap" : "jitter") +
           "); phnn needs uniform sampling: resample the recording or split it at the gap");
    }
  }
  return (m.t.back() - m.t.front()) / static_cast<double>(m.t.size() - 1);
}

}  // namespace

// The common step h = 1 / rate: given, or from the time columns (snapped
// to an integer rate within 1e-9).
double common_step(const std::vector<MeasuredTrajectory>& all, const ImportOptions& o,
                   std::string* summary) {
  double h0 = 0.0;
  const MeasuredTrajectory* first = nullptr;
  for (const MeasuredTrajectory& m : all) {
    const double h = uniform_step(m, o.time_tolerance);
    if (!first) {
      first = &m, h0 = h;
    } else if (std::abs(h - h0) > o.time_tolerance * h0) {
      fail(m.where(0) + " is sampled every " + g(h) + " s, " + first->where(0) + " every " + g(h0) +
           " s; phnn needs one sampling rate: resample one of them");
    }
  }
  if (o.sample_rate > 0) {
    if (std::abs(h0 * o.sample_rate - 1.0) > o.time_tolerance) {
      fail("--sample-rate " + g(o.sample_rate) + " Hz disagrees with the time column (" +
           first->where(0) + " is sampled at " + g(1.0 / h0) + " Hz); drop --sample-rate or fix t");
    }
    if (summary) *summary += "sample rate " + g(o.sample_rate) + " Hz (given)\n";
    return 1.0 / o.sample_rate;
  }
  const double rate = 1.0 / h0, whole = std::round(rate);
  if (whole >= 1 && std::abs(rate - whole) <= 1e-9 * rate) {
    if (summary) *summary += "sample rate " + g(whole) + " Hz (from t)\n";
    return 1.0 / whole;
  }
  if (summary) *summary += "sample rate " + g(rate) + " Hz (from t, not an integer)\n";
  return h0;
}

// Sorted by id, ids unique.
void sort_by_id(std::vector<MeasuredTrajectory>* all) {
  std::stable_sort(all->begin(), all->end(),
                   [](const MeasuredTrajectory& a, const MeasuredTrajectory& b) { return a.id < b.id; });
  for (std::size_t i = 1; i < all->size(); ++i) {
    if ((*all)[i].id == (*all)[i - 1].id) {
      fail((*all)[i].where(0) + " was already read at " + (*all)[i - 1].where(0) +
           " (a trajectory's rows must be contiguous and its id unique); give each trajectory "
           "its own id");
    }
  }
}

void add_pair(const MeasuredTrajectory& m, std::size_t n, PhPairSet* pairs) {
  pairs->x.push_back(m.state(n));
  pairs->x_next.push_back(m.state(n + 1));
  pairs->u.push_back(m.input(n));
  pairs->trajectory.push_back(m.id);
  pairs->position.push_back(static_cast<int>(n));
}

void add_windows(const std::vector<MeasuredTrajectory>& all,
                 const std::vector<std::pair<std::size_t, std::size_t>>& windows, std::size_t w,
                 bool positions, PhInferenceSet* inference) {
  bool varying = false;
  for (const auto& [i, start] : windows) {
    for (std::size_t k = start + 1; k < start + w && !varying; ++k) varying = !all[i].same_input(k, start);
  }
  for (const auto& [i, start] : windows) {
    const MeasuredTrajectory& m = all[i];
    inference->trajectory.push_back(m.id);
    if (positions) inference->position.push_back(static_cast<std::int64_t>(start));
    inference->u.push_back(m.input(start));
    std::vector<VecX> states, inputs;
    for (std::size_t k = start; k < start + w; ++k) {
      states.push_back(m.state(k));
      if (varying) inputs.push_back(m.input(k));
    }
    inference->states.push_back(std::move(states));
    if (varying) inference->inputs.push_back(std::move(inputs));
  }
}

void record_timing(DatasetOptions* o, std::uint64_t data_seed, double h, std::size_t samples) {
  o->data_seed = data_seed;
  o->sample_rate = 1.0 / h;
  o->generation_step = h;
  o->period = 1.0;
  o->beta = h * static_cast<double>(samples - 1);
}

}  // namespace internal

namespace {

using internal::fail;
using internal::g;

// The pair (x_n, x_n+1) of a trajectory: n uniform among the positions
// with t_n+1 - t_0 <= window (all when window = 0), keyed by its id.
void draw_pair(const PhSystem& system, const MeasuredTrajectory& m, const ImportOptions& o,
               PhPairSet* pairs) {
  int positions = static_cast<int>(m.t.size()) - 1;
  if (o.pair_window > 0) {
    positions = 0;
    while (positions + 1 < static_cast<int>(m.t.size()) &&
           m.t[static_cast<std::size_t>(positions) + 1] - m.t[0] <= o.pair_window * (1 + 1e-9)) {
      ++positions;
    }
    if (positions == 0) {
      fail(m.where(0) + ": no pair ends within --pair-window " + g(o.pair_window) + " s of its "
           "start (the second sample is at " + g(m.t[1] - m.t[0]) + " s); widen the window");
    }
  }
  CounterRng pick = CounterRng::for_trajectory(o.data_seed, system.rng_id(), m.id,
                                               CounterRng::kTrainingPair);
  internal::add_pair(m, static_cast<std::size_t>(pick.below(static_cast<std::uint64_t>(positions))),
                     pairs);
}

// Sorted by id; unique ids; shuffled by split_seed (Fisher-Yates on one
// counter stream) when it is >= 0.
void order_for_split(std::vector<MeasuredTrajectory>* all, const ImportOptions& o) {
  internal::sort_by_id(all);
  if (o.split_seed < 0) return;
  CounterRng rng(mix64(static_cast<std::uint64_t>(o.split_seed) ^ 0x73706c6974ULL));  // "split"
  for (std::size_t i = all->size(); i > 1; --i) {
    std::swap((*all)[i - 1], (*all)[static_cast<std::size_t>(rng.below(i))]);
  }
}

}  // namespace

void apply_measurement(const MeasurementMap& map, std::vector<MeasuredTrajectory>* trajectories) {
  if (map.identity()) return;
  const auto nr = map.recorded().size(), nx = static_cast<std::size_t>(map.n_x());
  for (MeasuredTrajectory& m : *trajectories) {
    PHNN_CHECK(static_cast<std::size_t>(m.n_x) == nr, "a recording of " << m.n_x << " columns for "
                                                                        << nr << " recorded ones");
    std::vector<double> x(m.size() * nx);
    for (std::size_t k = 0; k < m.size(); ++k) {
      map.states(m.x.data() + k * nr, x.data() + k * nx);
      if (!std::all_of(x.begin() + static_cast<long>(k * nx), x.begin() + static_cast<long>((k + 1) * nx),
                       [](double v) { return std::isfinite(v); })) {
        internal::fail(m.where(k) + ": [measurement] (" + map.describe() + ") gives a state that "
                       "is NaN or infinite; repair the sample or the expression");
      }
    }
    m.x = std::move(x);
    m.n_x = static_cast<int>(nx);
  }
}

void MeasuredTrajectory::add(double time, const double* state, const double* input) {
  t.push_back(time);
  x.insert(x.end(), state, state + n_x);
  u.insert(u.end(), input, input + n_u);
}

VecX MeasuredTrajectory::state(std::size_t k) const {
  return Eigen::Map<const VecX>(x.data() + k * static_cast<std::size_t>(n_x), n_x);
}

VecX MeasuredTrajectory::input(std::size_t k) const {
  return Eigen::Map<const VecX>(u.data() + k * static_cast<std::size_t>(n_u), n_u);
}

bool MeasuredTrajectory::same_input(std::size_t k, std::size_t ref) const {
  const auto w = static_cast<std::size_t>(n_u);
  return std::equal(u.begin() + static_cast<long>(k * w), u.begin() + static_cast<long>((k + 1) * w),
                    u.begin() + static_cast<long>(ref * w));
}

void MeasuredTrajectory::shrink() {
  t.shrink_to_fit();
  x.shrink_to_fit();
  u.shrink_to_fit();
  line.shrink_to_fit();
}

std::string MeasuredTrajectory::where(std::size_t k) const {
  if (k < line.size()) return source + ":" + std::to_string(line[k]) + ": trajectory " + std::to_string(id);
  return source + ": trajectory " + std::to_string(id) + (k > 0 ? ", sample " + std::to_string(k) : "");
}

void ImportOptions::validate() const {
  PHNN_REQUIRE(num_validation >= 1, "num_validation = " << num_validation << " must be >= 1");
  PHNN_REQUIRE(num_inference >= 1, "num_inference = " << num_inference << " must be >= 1");
  PHNN_REQUIRE(std::isfinite(pair_window) && pair_window >= 0,
               "pair_window = " << pair_window << " must be >= 0 (0: the whole trajectory)");
  PHNN_REQUIRE(std::isfinite(sample_rate) && sample_rate >= 0,
               "sample_rate = " << sample_rate << " must be >= 0 (0: from the time column)");
  PHNN_REQUIRE(time_tolerance > 0 && time_tolerance < 0.5,
               "time_tolerance = " << time_tolerance << " must be in (0, 0.5)");
  if (split != ImportSplit::kBlocks) return;
  PHNN_REQUIRE(train_fraction > 0 && validation_fraction > 0 &&
                   train_fraction + validation_fraction < 1,
               "blocks " << train_fraction << ", " << validation_fraction << ": the training and "
               "validation shares must be > 0 and leave an inference block (sum < 1)");
  PHNN_REQUIRE(std::isfinite(window) && window >= 0,
               "window = " << window << " must be >= 0 (0: the whole inference block)");
  PHNN_REQUIRE(pair_window == 0 && split_seed < 0,
               "pair_window and split_seed belong to the split by trajectories; blocks use every "
               "pair of a block, in time order");
}

namespace {

// Trajectories [first, end) of `all` as inference trajectories, cut to the
// shortest (internal::add_windows: from sample 0). Frees them; returns the
// samples kept.
std::size_t add_inference_trajectories(std::vector<MeasuredTrajectory>* all,
                                       std::size_t infer_begin, PhInferenceSet* out) {
  std::size_t samples = (*all)[infer_begin].size();
  std::vector<std::pair<std::size_t, std::size_t>> windows;
  for (std::size_t i = infer_begin; i < all->size(); ++i) {
    samples = std::min(samples, (*all)[i].size());
    windows.emplace_back(i, 0);
  }
  internal::add_windows(*all, windows, samples, /*positions=*/false, out);
  for (std::size_t i = infer_begin; i < all->size(); ++i) (*all)[i] = MeasuredTrajectory();
  return samples;
}

// ImportSplit::kTrajectories (split_measured_data's step 2).
PhSystemData split_by_trajectories(const PhSystem& system,
                                   std::vector<MeasuredTrajectory> trajectories,
                                   const ImportOptions& options, std::string* summary) {
  const long total = static_cast<long>(trajectories.size());
  const long held = static_cast<long>(options.num_validation) + options.num_inference;
  if (total < held + 1) {
    fail("the data hold " + std::to_string(total) + " trajectories; " +
         std::to_string(options.num_validation) + " for validation, " +
         std::to_string(options.num_inference) + " for inference and at least 1 for training "
         "need " + std::to_string(held + 1) + ": lower --num-validation / --num-inference or "
         "record more trajectories");
  }
  for (const MeasuredTrajectory& m : trajectories) {
    internal::check_trajectory(m, system.n_x(), system.n_u());
  }
  order_for_split(&trajectories, options);
  const double h = internal::common_step(trajectories, options, summary);
  const std::size_t num_train = static_cast<std::size_t>(total - held);
  const std::size_t infer_begin = num_train + static_cast<std::size_t>(options.num_validation);

  PhSystemData data = labelled_ph_system_data(system);
  data.train.step = data.validation.step = data.inference.step = h;
  for (std::size_t i = 0; i < infer_begin; ++i) {
    draw_pair(system, trajectories[i], options, i < num_train ? &data.train : &data.validation);
  }
  const std::size_t samples = add_inference_trajectories(&trajectories, infer_begin, &data.inference);

  // What the options record: the rate, the split sizes, the window and the
  // inference duration; no generation.
  DatasetOptions& o = data.options;
  internal::record_timing(&o, options.data_seed, h, samples);
  double longest = 0.0;
  for (std::size_t i = 0; i < infer_begin; ++i) {
    longest = std::max(longest, trajectories[i].t.back() - trajectories[i].t.front());
  }
  o.alpha = std::min(options.pair_window > 0 ? options.pair_window : longest, o.beta);
  o.num_trajectories = static_cast<int>(total);
  o.num_train_max = static_cast<int>(num_train);
  o.num_validation = options.num_validation;
  o.num_inference = options.num_inference;
  data.split = "trajectories: one pair per training or validation trajectory, the last " +
               std::to_string(options.num_inference) + " for inference, " +
               (options.split_seed >= 0 ? "shuffled by split seed " + std::to_string(options.split_seed)
                                        : std::string("in the order of their ids"));
  if (summary) {
    *summary += std::to_string(num_train) + " training, " + std::to_string(options.num_validation) +
                " validation, " + std::to_string(options.num_inference) + " inference trajectories" +
                (options.split_seed >= 0 ? " (shuffled by split seed " +
                                               std::to_string(options.split_seed) + ")"
                                         : " (in the order of their ids)") + "\n";
    *summary += "inference trajectories cut to " + std::to_string(samples) + " samples (" +
                g(o.beta) + " s), the shortest of them\n";
  }
  return data;
}

}  // namespace

PhSystemData split_measured_data(const PhSystem& system,
                                 std::vector<MeasuredTrajectory> trajectories,
                                 const ImportOptions& options, std::string* summary) {
  options.validate();
  return options.split == ImportSplit::kBlocks
             ? split_in_blocks(system, std::move(trajectories), options, summary)
             : split_by_trajectories(system, std::move(trajectories), options, summary);
}

std::vector<MeasuredTrajectory> generated_trajectories(const PhSystem& system,
                                                       const PhSystemData& data) {
  const DatasetOptions& o = data.options;
  const int stride = o.stride(), positions = o.num_pair_positions();
  const double h = data.train.step;
  std::vector<MeasuredTrajectory> out;
  // inputs: per sample (time-varying designs), else empty and u throughout.
  const auto add = [&](std::int64_t id, const VecX& u, const std::vector<VecX>& inputs,
                       const std::vector<VecX>& states) {
    MeasuredTrajectory m(static_cast<int>(system.n_x()), static_cast<int>(u.size()));
    m.id = id;
    m.source = "generated";
    for (std::size_t n = 0; n < states.size(); ++n) {
      m.add(static_cast<double>(n) * h, states[n].data(), (inputs.empty() ? u : inputs[n]).data());
    }
    out.push_back(std::move(m));
  };
  for (const PhPairSet* pairs : {&data.train, &data.validation}) {
    for (std::size_t i = 0; i < pairs->size(); ++i) {
      const PhTrajectory traj =
          ph_generate_trajectory(system, o, pairs->trajectory[i], positions * stride);
      std::vector<VecX> sub;
      for (int n = 0; n <= positions; ++n) sub.push_back(traj.states[static_cast<std::size_t>(n * stride)]);
      const auto n = static_cast<std::size_t>(pairs->position[i]);
      PHNN_CHECK(sub[n] == pairs->x[i] && sub[n + 1] == pairs->x_next[i] && traj.input(n) == pairs->u[i],
                 "trajectory " << pairs->trajectory[i] << " regenerated differs from its pair");
      add(pairs->trajectory[i], traj.u, traj.inputs, sub);
    }
  }
  for (std::size_t i = 0; i < data.inference.size(); ++i) {
    add(data.inference.trajectory[i], data.inference.u[i],
        data.inference.inputs.empty() ? std::vector<VecX>{} : data.inference.inputs[i],
        data.inference.states[i]);
  }
  return out;
}

}  // namespace phnn
