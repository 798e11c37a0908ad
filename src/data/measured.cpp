// src/data/measured.cpp — recorded trajectories (MeasuredTrajectory,
// [measurement]), the options and entry points of the split (its passes:
// measured_scan.cpp, trajectory_split.cpp, recording_split.cpp) and a
// generated set's trajectories back (include/phnn/data/measured.h). In
// memory only.
#include "phnn/data/measured.h"

#include <algorithm>
#include <cmath>

#include "phnn/common/check.h"
#include "data/measured_checks.h"

namespace phnn {

void apply_measurement(const MeasurementMap& map, const MeasuredTrajectory& recorded,
                       MeasuredTrajectory* out) {
  const auto nr = map.recorded().size(), nx = static_cast<std::size_t>(map.n_x());
  PHNN_CHECK(static_cast<std::size_t>(recorded.n_x) == nr,
             "a recording of " << recorded.n_x << " columns for " << nr << " recorded ones");
  out->id = recorded.id;
  out->n_x = static_cast<int>(nx);
  out->n_u = recorded.n_u;
  out->t = recorded.t;
  out->u = recorded.u;
  out->source = recorded.source;
  out->line = recorded.line;
  out->x.resize(recorded.size() * nx);
  for (std::size_t k = 0; k < recorded.size(); ++k) {
    double* x = out->x.data() + k * nx;
    map.states(recorded.x.data() + k * nr, x);
    if (!std::all_of(x, x + nx, [](double v) { return std::isfinite(v); })) {
      internal::fail(recorded.where(k) + ": [measurement] (" + map.describe() + ") gives a state "
                     "that is NaN or infinite; repair the sample or the expression");
    }
  }
}

void apply_measurement(const MeasurementMap& map, std::vector<MeasuredTrajectory>* trajectories) {
  if (map.identity()) return;
  MeasuredTrajectory states;
  for (MeasuredTrajectory& m : *trajectories) {
    apply_measurement(map, m, &states);
    m.x = std::move(states.x);
    m.n_x = states.n_x;
  }
}

void MeasuredTrajectory::add(double time, const double* state, const double* input) {
  t.push_back(time);
  x.insert(x.end(), state, state + n_x);
  u.insert(u.end(), input, input + n_u);
}

bool MeasuredTrajectory::same_input(std::size_t k, std::size_t ref) const {
  const auto w = static_cast<std::size_t>(n_u);
  return std::equal(u.begin() + static_cast<long>(k * w), u.begin() + static_cast<long>((k + 1) * w),
                    u.begin() + static_cast<long>(ref * w));
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

TrajectorySource trajectories_of(const std::vector<MeasuredTrajectory>& all) {
  return [&all](const TrajectoryVisitor& visit) {
    for (const MeasuredTrajectory& m : all) visit(m);
  };
}

MeasuredDataSet split_measured_stream(const PhSystem& system, const TrajectorySource& source,
                                      const ImportOptions& options, std::string* summary) {
  options.validate();
  return options.split == ImportSplit::kBlocks
             ? internal::split_recordings_in_blocks(system, source, options, summary)
             : internal::split_by_trajectories(system, source, options, summary);
}

PhSystemData to_ph_system_data(MeasuredDataSet set) {
  PhSystemData data = std::move(set.data);
  data.train = set.train.to_pair_set();
  data.validation = set.validation.to_pair_set();
  data.inference = set.inference.to_inference_set();
  return data;
}

PhSystemData split_measured_data(const PhSystem& system,
                                 std::vector<MeasuredTrajectory> trajectories,
                                 const ImportOptions& options, std::string* summary) {
  return to_ph_system_data(split_measured_stream(system, trajectories_of(trajectories), options, summary));
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
