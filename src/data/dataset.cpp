// src/data/dataset.cpp
#include "phnn/data/dataset.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "phnn/common/check.h"
#include "phnn/common/cr_math.h"
#include "phnn/data/counter_rng.h"

namespace phnn {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

// Integer ratio a / b when it is one to 1e-9 relative; -1 otherwise.
long integer_ratio(double a, double b) {
  const double r = a / b;
  const double n = std::round(r);
  return std::abs(r - n) <= 1e-9 * std::max(1.0, std::abs(r))
             ? static_cast<long>(n)
             : -1;
}

}  // namespace

std::string to_string(EnergySampling sampling) {
  switch (sampling) {
    case EnergySampling::kAlgorithm1: return "algorithm1";
    case EnergySampling::kDirect: return "direct";
  }
  return "unknown";
}

std::vector<EnergySampling> all_energy_samplings() {
  return {EnergySampling::kAlgorithm1, EnergySampling::kDirect};
}

int DatasetOptions::stride() const {
  const long s = integer_ratio(1.0 / generation_step, sample_rate);
  PHNN_REQUIRE(s >= 1, "Invalid DatasetOptions: sr_gen / sample_rate = "
                           << (1.0 / generation_step) << " / " << sample_rate
                           << " is not a positive integer; choose "
                              "generation_step = 1 / (k sample_rate).");
  return static_cast<int>(s);
}

int DatasetOptions::num_pair_positions() const {
  // t_{n+1} = (n + 1) / sr <= alpha T0  <=>  n + 1 <= floor(alpha T0 sr).
  const int count =
      static_cast<int>(std::floor(alpha * period * sample_rate + 1e-9));
  return count;
}

int DatasetOptions::num_inference_steps() const {
  return static_cast<int>(std::floor(beta * period * sample_rate + 1e-9));
}

void DatasetOptions::validate() const {
  auto positive = [](const char* field, double v) {
    PHNN_REQUIRE(std::isfinite(v) && v > 0.0,
                 "Invalid DatasetOptions: " << field << " = " << v
                                            << "; violated constraint: "
                                            << field << " > 0.");
  };
  positive("generation_step", generation_step);
  positive("period", period);
  positive("beta", beta);
  positive("alpha", alpha);
  positive("sample_rate", sample_rate);
  positive("energy_min", energy_min);
  positive("equilibrium_energy_min", equilibrium_energy_min);
  PHNN_REQUIRE(energy_max >= energy_min,
               "Invalid DatasetOptions: energy_max = "
                   << energy_max << " < energy_min = " << energy_min << ".");
  PHNN_REQUIRE(equilibrium_energy_max >= equilibrium_energy_min,
               "Invalid DatasetOptions: equilibrium_energy_max = "
                   << equilibrium_energy_max << " < equilibrium_energy_min = "
                   << equilibrium_energy_min << ".");
  PHNN_REQUIRE(alpha <= beta, "Invalid DatasetOptions: alpha = "
                                  << alpha << " > beta = " << beta << ".");
  PHNN_REQUIRE(num_train_max >= 1 && num_validation >= 1 && num_inference >= 1,
               "Invalid DatasetOptions: split sizes (train "
                   << num_train_max << ", validation " << num_validation
                   << ", inference " << num_inference << ") must be >= 1.");
  PHNN_REQUIRE(num_train_max + num_validation + num_inference <=
                   num_trajectories,
               "Invalid DatasetOptions: the splits need "
                   << num_train_max + num_validation + num_inference
                   << " trajectories but num_trajectories = "
                   << num_trajectories << ".");
  (void)stride();
  PHNN_REQUIRE(num_pair_positions() >= 1,
               "Invalid DatasetOptions: alpha T0 sample_rate = "
                   << alpha * period * sample_rate
                   << " < 1 leaves no training pair.");
  newton.validate();
}

TrajectorySpec trajectory_spec(const Oscillator& system,
                               const DatasetOptions& options,
                               std::int64_t index) {
  PHNN_REQUIRE(index >= 0 && index < options.num_trajectories,
               "trajectory index " << index << " outside [0, "
                                   << options.num_trajectories << ")");
  const int system_id = static_cast<int>(system.kind());
  CounterRng ic = CounterRng::for_trajectory(
      options.data_seed, system_id, index, CounterRng::kInitialCondition);
  CounterRng ctrl = CounterRng::for_trajectory(options.data_seed, system_id,
                                               index, CounterRng::kControl);
  const OscillatorOptions& p = system.options();
  TrajectorySpec spec;
  if (system.kind() == SystemKind::kDuffing) {
    // Algorithm 2: acceptance-rejection in the box around I_E0.
    // q_max solves k q^2 / 2 + k3 q^4 / 4 = E_max (s = q^2, stable root).
    const double b = 0.5 * p.stiffness, a = 0.25 * p.cubic_stiffness;
    const double s_max =
        options.energy_max / (0.5 * b + 0.5 * std::sqrt(b * b + 4.0 * a * options.energy_max));
    const double q_max = std::sqrt(s_max);
    const double p_max = std::sqrt(2.0 * p.mass * options.energy_max);
    for (int tries = 0;; ++tries) {
      PHNN_CHECK(tries < 1000000, "Algorithm 2 rejected 1e6 draws");
      // p is drawn before q: the order GCC gave the two draws when they were
      // the arguments of one constructor call (unspecified in C++), made
      // explicit so that no compiler changes the data.
      const double p_draw = ic.uniform(-p_max, p_max);
      const double q_draw = ic.uniform(-q_max, q_max);
      const Vec2 x(q_draw, p_draw);
      const double h0 = system.hamiltonian(x);
      if (h0 >= options.energy_min && h0 <= options.energy_max) {
        spec.x0 = x;
        break;
      }
    }
  } else {
    // Algorithm 1, as written: theta ~ U(0, 2 pi), r ~ U(E_min, E_max),
    // E0 = sqrt(r) (kDirect: E0 = r), q = sqrt(2 E0 / k) sin(theta),
    // p = sqrt(2 m E0) cos(theta).
    const double theta = ic.uniform(0.0, kTwoPi);
    const double r = ic.uniform(options.energy_min, options.energy_max);
    const double e0 = options.energy_sampling == EnergySampling::kDirect ? r : std::sqrt(r);
    spec.x0 = Vec2(std::sqrt(2.0 * e0 / p.stiffness) * cr::sin(theta),
                   std::sqrt(2.0 * p.mass * e0) * cr::cos(theta));
  }
  if (system.kind() == SystemKind::kSelfSustained) {
    // Algorithm 4: w ~ U(I_w), u = -w.
    const auto interval = system.self_oscillation_interval();
    spec.u = -ctrl.uniform(interval[0], interval[1]);
  } else {
    // Algorithm 3: E_eq ~ U(I_Eeq); q* with H(q*, 0) = E_eq and a random
    // sign; u* = -k q* - k3 q*^3.
    const double e_eq = ctrl.uniform(options.equilibrium_energy_min,
                                     options.equilibrium_energy_max);
    const double sign = ctrl.uniform() < 0.5 ? -1.0 : 1.0;
    const double b = 0.5 * p.stiffness;
    const double a = system.kind() == SystemKind::kDuffing
                         ? 0.25 * p.cubic_stiffness
                         : 0.0;
    // a s^2 + b s = E_eq, s = q*^2 >= 0: s = 2 E / (b + sqrt(b^2 + 4 a E)).
    const double s = 2.0 * e_eq / (b + std::sqrt(b * b + 4.0 * a * e_eq));
    const double q_star = sign * std::sqrt(s);
    const double k3 =
        system.kind() == SystemKind::kDuffing ? p.cubic_stiffness : 0.0;
    spec.u = -p.stiffness * q_star - k3 * q_star * q_star * q_star;
  }
  return spec;
}

Trajectory generate_trajectory(const Oscillator& system,
                               const DatasetOptions& options,
                               std::int64_t index, int num_steps) {
  PHNN_REQUIRE(num_steps >= 0,
               "generate_trajectory: num_steps = " << num_steps
                                                   << " must be >= 0");
  const TrajectorySpec spec = trajectory_spec(system, options, index);
  Trajectory traj;
  traj.index = index;
  traj.u = spec.u;
  traj.states.reserve(static_cast<std::size_t>(num_steps) + 1);
  traj.states.push_back(spec.x0);
  for (int n = 0; n < num_steps; ++n) {
    const DiscreteGradientStep step = discrete_gradient_step(
        system, traj.states.back(), spec.u, options.generation_step,
        options.newton);
    if (step.status != StepStatus::kConverged) {
      std::ostringstream msg;
      msg << "data generation: Newton did not converge for system "
          << to_string(system.kind()) << ", trajectory " << index << ", step "
          << n << " (" << to_string(step.status) << " after "
          << step.newton_iterations << " iterations, residual "
          << step.residual << "); loosen newton.tolerance or check the "
          << "physical parameters";
      throw std::runtime_error(msg.str());
    }
    traj.states.push_back(step.x_next);
  }
  return traj;
}

PairSet make_pairs(const Oscillator& system, const DatasetOptions& options,
                   std::int64_t first, int count) {
  options.validate();
  const int stride = options.stride();
  const int positions = options.num_pair_positions();
  PairSet pairs;
  pairs.step = stride * options.generation_step;
  for (std::int64_t i = first; i < first + count; ++i) {
    CounterRng pick = CounterRng::for_trajectory(
        options.data_seed, static_cast<int>(system.kind()), i,
        CounterRng::kTrainingPair);
    const int n = static_cast<int>(pick.below(static_cast<std::uint64_t>(positions)));
    // Generate only up to the pair's second sample.
    const Trajectory traj =
        generate_trajectory(system, options, i, (n + 1) * stride);
    pairs.x.push_back(traj.states[static_cast<std::size_t>(n * stride)]);
    pairs.x_next.push_back(traj.states.back());
    pairs.u.push_back(traj.u);
    pairs.trajectory.push_back(i);
    pairs.position.push_back(n);
  }
  return pairs;
}

PairSet training_pairs(const Oscillator& system, const DatasetOptions& options,
                       int n_train) {
  PHNN_REQUIRE(n_train >= 1 && n_train <= options.num_train_max,
               "n_train = " << n_train << " outside [1, "
                            << options.num_train_max << "]");
  return make_pairs(system, options, 0, n_train);
}

PairSet validation_pairs(const Oscillator& system,
                         const DatasetOptions& options) {
  return make_pairs(system, options, options.validation_begin(),
                    options.num_validation);
}

InferenceSet inference_set(const Oscillator& system,
                           const DatasetOptions& options) {
  options.validate();
  const int stride = options.stride();
  const int steps = options.num_inference_steps();
  InferenceSet set;
  set.step = stride * options.generation_step;
  for (int j = 0; j < options.num_inference; ++j) {
    const std::int64_t i = options.inference_begin() + j;
    const Trajectory traj = generate_trajectory(system, options, i, steps * stride);
    std::vector<Vec2> sub;
    sub.reserve(static_cast<std::size_t>(steps) + 1);
    for (int n = 0; n <= steps; ++n) {
      sub.push_back(traj.states[static_cast<std::size_t>(n * stride)]);
    }
    set.trajectory.push_back(i);
    set.u.push_back(traj.u);
    set.states.push_back(std::move(sub));
  }
  return set;
}

}  // namespace phnn
