// src/data/ph_dataset.cpp — data sets of any PhSystem (ph_dataset.h): the
// sampling designs (the paper's Algorithms 1-4 in their general forms, box
// and energy-interval draws) and the DG trajectories behind the splits.
#include "phnn/data/ph_dataset.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "phnn/common/check.h"
#include "phnn/common/cr_math.h"
#include "phnn/data/counter_rng.h"
#include "phnn/integrators/ph_steps.h"
#include "data/input_signals.h"

namespace phnn {

using internal::input_samples;
using internal::uniform_in_ranges;

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
constexpr int kMaxRejections = 1000000;

std::string vec_text(const VecX& x) {
  std::ostringstream os;
  os << "(";
  for (int i = 0; i < x.size(); ++i) os << (i ? ", " : "") << x(i);
  os << ")";
  return os.str();
}

// H(x) at a drawn state: finite and >= 0, else an error at the file's H.
double checked_energy(const PhSystem& system, const VecX& x) {
  const double h = system.hamiltonian(x);
  if (!std::isfinite(h) || h < 0.0) {
    std::ostringstream os;
    os << system.energy_location() << ": H = " << h << " at the drawn initial state x = "
       << vec_text(x) << (std::isfinite(h) ? " is negative" : " is not finite");
    if (std::isfinite(h)) {
      os << negative_energy_advice(system, system.initial_design().box, h);
    } else {
      os << "; an energy must be finite where initial states are drawn: fix H or shrink initial.box";
    }
    throw std::invalid_argument(os.str());
  }
  return h;
}

// Components are drawn from the last to the first: the order of the
// built-in Algorithm 2 (p before q), so the Duffing file reproduces it.
VecX draw_in_box(const InitialConditionDesign& d, CounterRng* rng) {
  VecX x(static_cast<int>(d.box.size()));
  for (int i = static_cast<int>(x.size()) - 1; i >= 0; --i) {
    x(i) = rng->uniform(d.box[static_cast<std::size_t>(i)][0], d.box[static_cast<std::size_t>(i)][1]);
  }
  return x;
}

// Algorithm 1 with q = sqrt(2 E0 / H_qq(0)) sin(theta), p = sqrt(2 E0 /
// H_pp(0)) cos(theta) (= the paper's sqrt(2 E0 / k), sqrt(2 m E0)).
VecX algorithm1(const PhSystem& system, const InitialConditionDesign& d,
                const DatasetOptions& options, CounterRng* rng) {
  const double theta = rng->uniform(0.0, kTwoPi);
  const double r = rng->uniform(d.energy_min, d.energy_max);
  const double e0 = options.energy_sampling == EnergySampling::kDirect ? r : std::sqrt(r);
  const MatX h0 = system.hessian(VecX::Zero(2));
  VecX x(2);
  x << std::sqrt(2.0 * e0 / h0(0, 0)) * cr::sin(theta), std::sqrt(2.0 * e0 / h0(1, 1)) * cr::cos(theta);
  return x;
}

VecX initial_state(const PhSystem& system, const DatasetOptions& options, CounterRng* rng) {
  const InitialConditionDesign& d = system.initial_design();
  switch (d.method) {
    case InitialConditionDesign::Method::kAlgorithm1:
      return algorithm1(system, d, options, rng);
    case InitialConditionDesign::Method::kBox: {
      const VecX x = draw_in_box(d, rng);
      checked_energy(system, x);
      return x;
    }
    case InitialConditionDesign::Method::kEnergy:
      break;
  }
  // Algorithm 2: rejection in the box until H(x) lies in [E_min, E_max].
  for (int tries = 0; tries < kMaxRejections; ++tries) {
    const VecX x = draw_in_box(d, rng);
    const double h = checked_energy(system, x);
    if (h >= d.energy_min && h <= d.energy_max) return x;
  }
  std::ostringstream os;
  os << system.initial_location() << ": no initial state with H in [" << d.energy_min << ", "
     << d.energy_max << "] in " << kMaxRejections
     << " draws from the box; widen initial.energy or fit initial.box around that energy shell";
  throw std::invalid_argument(os.str());
}

// s >= 0 with H(s e_1) = e (H(s e_1) increasing in s >= 0): bisection to
// the last bit after doubling. `what` names the design in the error.
double offset_at_energy(const PhSystem& system, double e, const std::string& what,
                        const std::string& where) {
  auto energy = [&](double s) {
    VecX x = VecX::Zero(system.n_x());
    x(0) = s;
    return system.hamiltonian(x);
  };
  double hi = 1e-3;
  for (int it = 0; energy(hi) < e; ++it) {
    PHNN_REQUIRE(it < 60, where << ": " << what << ": H(" << system.state_names()[0]
                                << ", 0) stays below " << e << " J; lower that energy");
    hi *= 2.0;
  }
  double lo = 0.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (energy(mid) < e ? lo : hi) = mid;
  }
  return energy(hi) - e <= e - energy(lo) ? hi : lo;
}

double equilibrium_offset(const PhSystem& system, double e) {
  return offset_at_energy(system, e, "energy-shaping control (E_eq)", system.control_location("energy"));
}

VecX control_input(const PhSystem& system, CounterRng* rng) {
  const ControlDesign& c = system.control_design();
  VecX u = VecX::Zero(system.n_u());
  switch (c.design) {
    case ControlDesign::Design::kConstant:
      u = uniform_in_ranges(c.range, system.n_u(), rng);
      break;
    case ControlDesign::Design::kEnergyShaping: {
      // Algorithm 3: E_eq ~ U(I_Eeq), sign +-1, u = -dH/dq(q*, 0).
      const double e_eq = rng->uniform(c.equilibrium_energy_min, c.equilibrium_energy_max);
      const double sign = rng->uniform() < 0.5 ? -1.0 : 1.0;
      VecX x_star(2);
      x_star << sign * equilibrium_offset(system, e_eq), 0.0;
      u(0) = -system.grad_hamiltonian(x_star)(0);
      break;
    }
    case ControlDesign::Design::kLimitCycle: {
      // Algorithm 4: w ~ U(I_w), u = -w.
      const auto interval = system.self_oscillation_interval();
      u(0) = -rng->uniform(interval[0], interval[1]);
      break;
    }
    case ControlDesign::Design::kSines:
    case ControlDesign::Design::kChirp:
    case ControlDesign::Design::kSteps:
      break;  // input_samples()
  }
  return u;
}

}  // namespace

PhTrajectorySpec ph_trajectory_spec(const PhSystem& system, const DatasetOptions& options,
                                    std::int64_t index) {
  PHNN_REQUIRE(index >= 0 && index < options.num_trajectories,
               "trajectory index " << index << " outside [0, " << options.num_trajectories << ")");
  CounterRng ic = CounterRng::for_trajectory(options.data_seed, system.rng_id(), index,
                                             CounterRng::kInitialCondition);
  CounterRng ctrl =
      CounterRng::for_trajectory(options.data_seed, system.rng_id(), index, CounterRng::kControl);
  PhTrajectorySpec spec;
  spec.x0 = initial_state(system, options, &ic);
  if (system.control_design().time_varying()) {
    spec.inputs = input_samples(system, options, &ctrl);
    spec.u = spec.inputs.front();
  } else {
    spec.u = control_input(system, &ctrl);
  }
  // Finite numbers can still overflow (a range of +-1e308, amplitudes of
  // 1e308): refused at the control table, not as a Newton failure later.
  for (std::size_t k = 0; k < std::max<std::size_t>(spec.inputs.size(), 1); ++k) {
    const VecX& u = spec.input(k);
    PHNN_REQUIRE(u.allFinite(), system.control_location()
                                    << ": the input of trajectory " << index << " is not finite at sample "
                                    << k << " (u = " << u.transpose()
                                    << "): the control's numbers overflow; give ranges and "
                                       "amplitudes of physical size");
  }
  return spec;
}

namespace {

// `num_steps` DG steps at h_gen from spec.x0 under spec's inputs; `label`
// names the trajectory in the Newton failure.
PhTrajectory generate_from(const PhSystem& system, const DatasetOptions& options,
                           const PhTrajectorySpec& spec, const std::string& label, int num_steps) {
  PHNN_REQUIRE(num_steps >= 0, "ph_generate_trajectory: num_steps = " << num_steps << " must be >= 0");
  PhTrajectory traj;
  traj.u = spec.u;
  const int stride = options.stride();
  if (!spec.inputs.empty()) {
    // The samples this trajectory spans (its last state's included).
    const std::size_t samples = static_cast<std::size_t>(num_steps / stride) + 1;
    PHNN_REQUIRE(samples <= spec.inputs.size(),
                 "ph_generate_trajectory: " << num_steps << " steps outrun the input signal ("
                                            << spec.inputs.size() << " samples)");
    traj.inputs.assign(spec.inputs.begin(), spec.inputs.begin() + static_cast<long>(samples));
  }
  traj.states.reserve(static_cast<std::size_t>(num_steps) + 1);
  traj.states.push_back(spec.x0);
  for (int n = 0; n < num_steps; ++n) {
    // Zero-order hold: u of sample floor(n / stride) over the whole step.
    const VecX& u = spec.input(static_cast<std::size_t>(n / stride));
    const PhImplicitStep step = ph_discrete_gradient_step(system, traj.states.back(), u,
                                                          options.generation_step, options.newton);
    if (step.status != StepStatus::kConverged) {
      std::ostringstream msg;
      msg << "data generation: Newton did not converge for system " << system.name() << ", "
          << label << ", step " << n << " (" << to_string(step.status) << " after "
          << step.newton_iterations << " iterations, residual " << step.residual
          << "); loosen newton.tolerance, shorten generation_step or check the system's parameters";
      throw std::runtime_error(msg.str());
    }
    traj.states.push_back(step.x_next);
  }
  return traj;
}

// The states of `traj` at sr_infer (every stride-th), n = 0..steps.
std::vector<VecX> subsampled(const PhTrajectory& traj, int stride, int steps) {
  std::vector<VecX> sub;
  sub.reserve(static_cast<std::size_t>(steps) + 1);
  for (int n = 0; n <= steps; ++n) sub.push_back(traj.states[static_cast<std::size_t>(n * stride)]);
  return sub;
}

}  // namespace

PhTrajectory ph_generate_trajectory(const PhSystem& system, const DatasetOptions& options,
                                    std::int64_t index, int num_steps) {
  PhTrajectory traj = generate_from(system, options, ph_trajectory_spec(system, options, index),
                                    "trajectory " + std::to_string(index), num_steps);
  traj.index = index;
  return traj;
}

namespace {

// Every 64 trajectories, the caller's stop: a long generation ends at a
// signal within ~a trajectory's time x 64 (GenerationStopped).
void check_stop(const GenerationStop& stop, std::int64_t index) {
  if (stop && index % 64 == 0 && stop()) {
    throw GenerationStopped("stopped while generating trajectory " + std::to_string(index));
  }
}

}  // namespace

PhPairSet ph_make_pairs(const PhSystem& system, const DatasetOptions& options, std::int64_t first,
                        int count, const GenerationStop& stop) {
  options.validate();
  const int stride = options.stride();
  const int positions = options.num_pair_positions();
  PhPairSet pairs;
  pairs.step = stride * options.generation_step;
  for (std::int64_t i = first; i < first + count; ++i) {
    check_stop(stop, i);
    CounterRng pick = CounterRng::for_trajectory(options.data_seed, system.rng_id(), i,
                                                 CounterRng::kTrainingPair);
    const int n = static_cast<int>(pick.below(static_cast<std::uint64_t>(positions)));
    const PhTrajectory traj = ph_generate_trajectory(system, options, i, (n + 1) * stride);
    pairs.x.push_back(traj.states[static_cast<std::size_t>(n * stride)]);
    pairs.x_next.push_back(traj.states.back());
    pairs.u.push_back(traj.input(static_cast<std::size_t>(n)));
    pairs.trajectory.push_back(i);
    pairs.position.push_back(n);
  }
  return pairs;
}

PhInferenceSet ph_inference_set(const PhSystem& system, const DatasetOptions& options,
                                const GenerationStop& stop) {
  options.validate();
  const int stride = options.stride();
  const int steps = options.num_inference_steps();
  PhInferenceSet set;
  set.step = stride * options.generation_step;
  for (int j = 0; j < options.num_inference; ++j) {
    const std::int64_t i = options.inference_begin() + j;
    check_stop(stop, i);
    const PhTrajectory traj = ph_generate_trajectory(system, options, i, steps * stride);
    set.trajectory.push_back(i);
    set.u.push_back(traj.u);
    set.states.push_back(subsampled(traj, stride, steps));
    if (!traj.inputs.empty()) set.inputs.push_back(traj.inputs);
  }
  return set;
}

// x0 = s e_1 with H(x0) = E per figure energy; u: the control design's
// central input (Algorithm 4's middle of I_w, u = -(w1 + w2) / 2), else 0.
PhInferenceSet ph_figure_set(const PhSystem& system, const DatasetOptions& options) {
  options.validate();
  const int stride = options.stride();
  const int steps = options.num_inference_steps();
  PhInferenceSet set;
  set.step = stride * options.generation_step;
  PhTrajectorySpec spec;
  spec.u = VecX::Zero(system.n_u());
  if (system.control_design().design == ControlDesign::Design::kLimitCycle) {
    const auto iw = system.self_oscillation_interval();
    spec.u(0) = -0.5 * (iw[0] + iw[1]);
  }
  for (const double e : system.figure_energies()) {
    spec.x0 = VecX::Zero(system.n_x());
    spec.x0(0) = offset_at_energy(system, e, "plots.energies", system.energy_location());
    std::ostringstream label;
    label << "the figure trajectory at H = " << e << " J";
    const PhTrajectory traj = generate_from(system, options, spec, label.str(), steps * stride);
    set.trajectory.push_back(-1);
    set.u.push_back(spec.u);
    set.states.push_back(subsampled(traj, stride, steps));
  }
  return set;
}

PhSystemData labelled_ph_system_data(const PhSystem& system) {
  PhSystemData data;
  data.system_name = system.name();
  data.system_text = system.source_text();
  data.state_names = system.state_names();
  data.state_units = system.state_units();
  data.input_names = system.input_names();
  data.n_w = system.n_w();
  return data;
}

PhSystemData make_ph_system_data(const PhSystem& system, const DatasetOptions& options,
                                 int num_train, const GenerationStop& stop) {
  options.validate();
  PHNN_REQUIRE(num_train >= 1 && num_train <= options.num_train_max,
               "n_train = " << num_train << " outside [1, " << options.num_train_max << "]");
  PhSystemData data = labelled_ph_system_data(system);
  data.options = options;
  data.train = ph_make_pairs(system, options, 0, num_train, stop);
  data.validation =
      ph_make_pairs(system, options, options.validation_begin(), options.num_validation, stop);
  data.inference = ph_inference_set(system, options, stop);
  return data;
}

}  // namespace phnn
