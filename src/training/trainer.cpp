// src/training/trainer.cpp
#include "phnn/training/trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include <torch/torch.h>

#include "phnn/common/check.h"
#include "phnn/data/counter_rng.h"
#include "phnn/integrators/discrete_gradient.h"
#include "phnn/models/dynamics_model.h"
#include "phnn/training/discrete_step.h"
#include "phnn/training/flat_adam.h"
#include "phnn/training/regularizers.h"

namespace phnn {

namespace {

// A non-finite value in the data would turn every member's loss into NaN
// (all frozen at step 0) or every rollout error into NaN: refuse the data
// instead, naming the set, the index and the fix.
void require_finite_pairs(const PairSet& pairs, std::size_t count, const char* what) {
  for (std::size_t i = 0; i < std::min(count, pairs.size()); ++i) {
    PHNN_REQUIRE(pairs.x[i].allFinite() && pairs.x_next[i].allFinite() && std::isfinite(pairs.u[i]),
                 "Invalid data: " << what << " pair " << i << " has a non-finite value (x = ("
                                  << pairs.x[i](0) << ", " << pairs.x[i](1) << "), x_next = ("
                                  << pairs.x_next[i](0) << ", " << pairs.x_next[i](1)
                                  << "), u = " << pairs.u[i]
                                  << "); regenerate the data set (phnn data) or fix its source");
  }
}

void require_finite_data(const SystemData& data, int n_train) {
  require_finite_pairs(data.train, static_cast<std::size_t>(n_train), "training");
  require_finite_pairs(data.validation, data.validation.size(), "validation");
  const InferenceSet& inf = data.inference;
  for (std::size_t i = 0; i < inf.size(); ++i) {
    bool finite = std::isfinite(inf.u[i]);
    std::size_t bad_step = 0;
    for (std::size_t n = 0; finite && n < inf.states[i].size(); ++n) {
      finite = inf.states[i][n].allFinite();
      bad_step = n;
    }
    PHNN_REQUIRE(finite, "Invalid data: inference trajectory "
                             << i << " has a non-finite value (input u or the state at step "
                             << bad_step
                             << "); regenerate the data set (phnn data) or fix its source");
  }
}

}  // namespace

void CellSpec::validate(const SystemData& data) const {
  training.validate();
  PHNN_REQUIRE(!(model == ModelKind::kNode && is_discrete_gradient(integrator)),
               "Invalid CellSpec: integrator = " << to_string(integrator)
                   << " with model = node; the discrete gradient needs a Hamiltonian (use rk2 "
                      "or rk4, or phnn-s / phnn-jr)");
  PHNN_REQUIRE(n_train >= 1 && static_cast<std::size_t>(n_train) <= data.train.size(),
               "Invalid CellSpec: n_train = " << n_train << "; the data set has "
                                              << data.train.size() << " training pairs");
  PHNN_REQUIRE(!seeds.empty(), "Invalid CellSpec: no seeds");
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    PHNN_REQUIRE(seeds[i] >= 0, "Invalid CellSpec: seed = " << seeds[i] << " must be >= 0");
    for (std::size_t j = 0; j < i; ++j) {
      PHNN_REQUIRE(seeds[i] != seeds[j], "Invalid CellSpec: seed " << seeds[i] << " listed twice");
    }
  }
  PHNN_REQUIRE(!data.validation.x.empty(), "Invalid CellSpec: the data set has no validation pairs");
  require_finite_data(data, n_train);
}

FigureSetup figure_setup(const OscillatorOptions& system) {
  auto q_at_energy = [&](double energy) {
    const double b = 0.5 * system.stiffness;
    const double a = system.kind == SystemKind::kDuffing ? 0.25 * system.cubic_stiffness : 0.0;
    return std::sqrt(2.0 * energy / (b + std::sqrt(b * b + 4.0 * a * energy)));
  };
  FigureSetup setup;
  setup.x0_05 = Vec2(q_at_energy(0.5), 0.0);
  setup.x0_075 = Vec2(q_at_energy(0.75), 0.0);
  if (system.kind == SystemKind::kSelfSustained) {
    const auto iw = Oscillator(system).self_oscillation_interval();
    setup.u = -0.5 * (iw[0] + iw[1]);
  }
  return setup;
}

std::vector<double> reference_trajectory(const OscillatorOptions& system,
                                         const DatasetOptions& options, const Vec2& x0, double u) {
  const Oscillator osc(system);
  const int stride = options.stride();
  const int steps = options.num_inference_steps();
  std::vector<double> out;
  out.reserve(2 * static_cast<std::size_t>(steps + 1));
  Vec2 x = x0;
  for (int n = 0; n <= steps; ++n) {
    out.push_back(x(0));
    out.push_back(x(1));
    if (n == steps) break;
    for (int k = 0; k < stride; ++k) {
      const auto step = discrete_gradient_step(osc, x, u, options.generation_step, options.newton);
      PHNN_REQUIRE(step.status == StepStatus::kConverged,
                   "reference_trajectory: Newton failed at step " << n);
      x = step.x_next;
    }
  }
  return out;
}

namespace {

using Clock = std::chrono::steady_clock;

torch::Tensor to_tensor(const std::vector<Vec2>& v, std::size_t count) {
  auto t = torch::empty({static_cast<int64_t>(count), 2}, torch::kFloat64);
  auto a = t.accessor<double, 2>();
  for (std::size_t i = 0; i < count; ++i) {
    a[static_cast<int64_t>(i)][0] = v[i](0);
    a[static_cast<int64_t>(i)][1] = v[i](1);
  }
  return t;
}

torch::Tensor to_tensor(const std::vector<double>& v, std::size_t count) {
  return torch::tensor(std::vector<double>(v.begin(), v.begin() + static_cast<long>(count)),
                       torch::kFloat64)
      .unsqueeze(-1);
}

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

 private:
  int n_, batch_, cursor_ = 0;
  std::vector<CounterRng> rngs_;
  std::vector<std::vector<int64_t>> perms_;
};

}  // namespace

namespace {

// The autoregressive rollouts of Eq. 31 for every member of the stack:
// the inference trajectories, then the two figure trajectories (rows B_inf,
// B_inf + 1), from the model's current weights.
struct Rollouts {
  torch::Tensor sq_err;           // [E, B_inf]: sum over steps of |x - x_ref|^2
  torch::Tensor diverged;         // [E, B_inf + 2]
  torch::Tensor newton_failures;  // [E]
  torch::Tensor figure;           // [E, steps + 1, 2, 2] (NaN after divergence)
  int steps = 0;
};

Rollouts roll_out(const DynamicsModel& model_ref, const CellSpec& cell, const SystemData& data) {
  torch::NoGradGuard no_grad;
  const DynamicsModel* model = &model_ref;
  const TrainerOptions& opt = cell.training;
  const int64_t E = model_ref.members();
  const bool use_dg = is_discrete_gradient(cell.integrator);
  const InferenceSet& inf = data.inference;
  const int64_t B_inf = static_cast<int64_t>(inf.size());
  const int steps = static_cast<int>(inf.states.empty() ? 0 : inf.states[0].size() - 1);
  const FigureSetup fig = figure_setup(data.system);
  // Rows: the inference trajectories, then the two figure trajectories.
  const int64_t B = B_inf + 2;
  auto x0 = torch::empty({B, 2}, torch::kFloat64);
  auto u0 = torch::empty({B, 1}, torch::kFloat64);
  auto ref = torch::empty({steps + 1, B_inf, 2}, torch::kFloat64);
  {
    auto xa = x0.accessor<double, 2>();
    auto ua = u0.accessor<double, 2>();
    auto ra = ref.accessor<double, 3>();
    for (int64_t i = 0; i < B_inf; ++i) {
      const auto ui = static_cast<std::size_t>(i);
      xa[i][0] = inf.states[ui][0](0);
      xa[i][1] = inf.states[ui][0](1);
      ua[i][0] = inf.u[ui];
      for (int n = 0; n <= steps; ++n) {
        ra[n][i][0] = inf.states[ui][static_cast<std::size_t>(n)](0);
        ra[n][i][1] = inf.states[ui][static_cast<std::size_t>(n)](1);
      }
    }
    xa[B_inf][0] = fig.x0_05(0);
    xa[B_inf][1] = fig.x0_05(1);
    xa[B_inf + 1][0] = fig.x0_075(0);
    xa[B_inf + 1][1] = fig.x0_075(1);
    ua[B_inf][0] = ua[B_inf + 1][0] = fig.u;
  }
  const double h_inf = inf.step;
  auto x = x0.unsqueeze(0).expand({E, B, 2}).contiguous();
  const auto u = u0.unsqueeze(0).expand({E, B, 1}).contiguous();
  auto diverged = torch::zeros({E, B}, torch::kBool);
  auto sq_err = torch::zeros({E, B_inf}, torch::kFloat64);
  auto newton_failures = torch::zeros({E}, torch::kLong);
  std::vector<torch::Tensor> figure_states{x.narrow(1, B_inf, 2).clone()};
  DgInferenceOptions dg_options;
  dg_options.tolerance = opt.newton_tolerance;
  dg_options.max_iterations = opt.newton_max_iterations;
  dg_options.min_dx_norm = opt.dg_min_dx_norm;
  DgNewtonJacobian newton_jacobian;  // carried along the rollout
  for (int n = 1; n <= steps; ++n) {
    torch::Tensor next;
    if (use_dg) {
      const auto s = cell.integrator == IntegratorKind::kDg4
                         ? dg4_inference_step(*model, x, u, h_inf, dg_options)
                         : dg_inference_step(*model, x, u, h_inf, dg_options, &newton_jacobian);
      next = s.x_next;
      newton_failures += (s.converged.logical_not() & diverged.logical_not()).sum(-1);
    } else {
      next = explicit_step(*model, cell.integrator, x, u, h_inf);
    }
    const auto bad = torch::isfinite(next).all(-1).logical_not() |
                     (next.norm(2, -1) > opt.divergence_norm);
    diverged = diverged | bad;
    x = torch::where(diverged.unsqueeze(-1), torch::zeros_like(next), next);
    const auto diff = x.narrow(1, 0, B_inf) - ref[n].unsqueeze(0);
    sq_err += (diff * diff).sum(-1);
    figure_states.push_back(torch::where(diverged.narrow(1, B_inf, 2).unsqueeze(-1),
                                         torch::full_like(next.narrow(1, B_inf, 2), NAN),
                                         next.narrow(1, B_inf, 2)));
  }
  Rollouts out;
  out.sq_err = sq_err;
  out.diverged = diverged;
  out.newton_failures = newton_failures;
  out.figure = torch::stack(figure_states, 1);
  out.steps = steps;
  return out;
}

// Eq. 31 per member from the rollouts: the mean over the inference
// trajectories of their mean squared error, +inf if any diverged.
std::vector<double> member_mse(const Rollouts& r) {
  const int64_t E = r.sq_err.size(0), B_inf = r.sq_err.size(1);
  std::vector<double> out(static_cast<std::size_t>(E));
  for (int64_t e = 0; e < E; ++e) {
    double total = 0.0;
    for (int64_t i = 0; i < B_inf; ++i) {
      total += r.diverged[e][i].item<bool>() ? std::numeric_limits<double>::infinity()
                                             : r.sq_err[e][i].item<double>() / r.steps;
    }
    out[static_cast<std::size_t>(e)] = B_inf ? total / static_cast<double>(B_inf) : 0.0;
  }
  return out;
}

}  // namespace

std::vector<RunResult> train_cell(const CellSpec& cell, const SystemData& data,
                                  const ProgressCallback& progress,
                                  std::unique_ptr<DynamicsModel>* trained) {
  cell.validate(data);
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  const TrainerOptions& opt = cell.training;
  const int64_t E = static_cast<int64_t>(cell.seeds.size());
  std::vector<std::uint64_t> seeds(cell.seeds.begin(), cell.seeds.end());
  std::unique_ptr<DynamicsModel> model =
      DynamicsModel::create(
          ModelOptions{cell.model, cell.size, data.system.kind, cell.fused_networks}, seeds);
  // One contiguous leaf for the whole stack: Adam in a handful of ops.
  const DynamicsModel::FlatParameters flat = model->flatten_parameters();
  const std::vector<torch::Tensor> params = model->parameters();  // alias flat.values
  const std::vector<torch::Tensor> grads = model->unflatten(flat.gradients);
  FlatAdam adam(flat.values, flat.gradients, opt);

  const int N = cell.n_train;
  const double h = data.train.step;
  const auto X = to_tensor(data.train.x, static_cast<std::size_t>(N));
  const auto Xn = to_tensor(data.train.x_next, static_cast<std::size_t>(N));
  const auto U = to_tensor(data.train.u, static_cast<std::size_t>(N));
  const std::size_t V = data.validation.size();
  const auto Xv = to_tensor(data.validation.x, V).unsqueeze(0).expand({E, -1, -1});
  const auto Xvn = to_tensor(data.validation.x_next, V).unsqueeze(0).expand({E, -1, -1});
  const auto Uv = to_tensor(data.validation.u, V).unsqueeze(0).expand({E, -1, -1});
  const auto Xall = X.unsqueeze(0).expand({E, -1, -1});
  const auto Xnall = Xn.unsqueeze(0).expand({E, -1, -1});
  const auto Uall = U.unsqueeze(0).expand({E, -1, -1});

  // L_d (Eq. 30): mean over batch and state components of |x_{n+1} - x_hat| / h.
  auto data_loss = [&](const torch::Tensor& x, const torch::Tensor& xn, const torch::Tensor& u) {
    const auto x_hat =
        cell.integrator == IntegratorKind::kDg   ? dg_training_step(*model, x, xn, u, h, opt.dg_min_dx_norm)
        : cell.integrator == IntegratorKind::kDg4 ? dg4_training_step(*model, x, xn, u, h, opt.dg_min_dx_norm)
                                                  : explicit_step(*model, cell.integrator, x, u, h);
    return ((xn - x_hat).abs() / h).mean({1, 2});
  };

  std::vector<RunResult> results(static_cast<std::size_t>(E));
  std::vector<bool> alive(static_cast<std::size_t>(E), true);
  std::vector<int> diverged_at(static_cast<std::size_t>(E), -1);
  std::vector<double> best_val(static_cast<std::size_t>(E), std::numeric_limits<double>::infinity());
  std::vector<torch::Tensor> best, frozen;
  for (const auto& p : params) {
    best.push_back(p.detach().clone());
    frozen.push_back(p.detach().clone());
  }

  auto evaluate = [&](int step) {
    torch::NoGradGuard no_grad;
    const auto val = data_loss(Xv, Xvn, Uv);
    const auto train = data_loss(Xall, Xnall, Uall);
    const auto stats = jacobian_stats(model->field(Xall, Uall, true).dfdx, opt.jacobian_eps);
    const auto kappa = stats.kappa.mean(-1), sigma = stats.sigma_max.mean(-1),
               rho = stats.rho.mean(-1);
    std::vector<int64_t> improved;
    std::vector<double> live_best;
    for (int64_t e = 0; e < E; ++e) {
      const auto ue = static_cast<std::size_t>(e);
      if (!alive[ue]) continue;
      TracePoint tp;
      tp.step = step;
      tp.elapsed_s = elapsed();
      tp.train_loss = train[e].item<double>();
      tp.validation_loss = val[e].item<double>();
      tp.kappa = kappa[e].item<double>();
      tp.sigma_max = sigma[e].item<double>();
      tp.rho = rho[e].item<double>();
      results[ue].trace.push_back(tp);
      if (std::isfinite(tp.validation_loss) && tp.validation_loss < best_val[ue]) {
        best_val[ue] = tp.validation_loss;
        results[ue].best_step = step;
        improved.push_back(e);
      }
      live_best.push_back(best_val[ue]);
    }
    if (!improved.empty()) {
      const auto idx = torch::tensor(improved, torch::kLong);
      for (std::size_t k = 0; k < params.size(); ++k) {
        best[k].index_copy_(0, idx, params[k].detach().index_select(0, idx));
      }
    }
    if (progress) {
      TrainProgress p;
      p.step = step;
      p.total_steps = opt.steps;
      p.elapsed_s = elapsed();
      if (!live_best.empty()) {
        std::nth_element(live_best.begin(), live_best.begin() + static_cast<long>(live_best.size() / 2),
                         live_best.end());
        p.best_validation_loss = live_best[live_best.size() / 2];
      }
      progress(p);
    }
  };

  BatchSampler sampler(cell.seeds, N, opt.batch_size);
  evaluate(0);
  // Inference of the best weights so far at a step budget; the training
  // weights are restored bitwise, so training goes on unchanged.
  double checkpoint_overhead_s = 0.0;
  std::size_t next_checkpoint = 0;
  auto checkpoint = [&](int step) {
    const auto begin = Clock::now();
    const double train_s = (elapsed() - checkpoint_overhead_s) / static_cast<double>(E);
    torch::NoGradGuard no_grad;
    std::vector<torch::Tensor> current;
    for (std::size_t k = 0; k < params.size(); ++k) {
      current.push_back(params[k].detach().clone());
      params[k].copy_(best[k]);
    }
    const std::vector<double> mse = member_mse(roll_out(*model, cell, data));
    for (std::size_t k = 0; k < params.size(); ++k) params[k].copy_(current[k]);
    for (std::size_t e = 0; e < results.size(); ++e) {
      results[e].checkpoint_steps.push_back(step);
      results[e].checkpoint_mse.push_back(mse[e]);
      results[e].checkpoint_train_seconds.push_back(train_s);
    }
    checkpoint_overhead_s += std::chrono::duration<double>(Clock::now() - begin).count();
  };
  // Every pair in every step when N <= batch: no gather needed.
  const bool full_batch = N <= opt.batch_size;
  for (int step = 1; step <= opt.steps; ++step) {
    const auto idx = full_batch ? torch::Tensor() : sampler.next();
    const auto x = full_batch ? Xall : X.index({idx});
    const auto xn = full_batch ? Xnall : Xn.index({idx});
    const auto u = full_batch ? Uall : U.index({idx});
    auto loss = data_loss(x, xn, u);
    if (cell.regularizer != Regularizer::kNone) {
      const auto stats = jacobian_stats(model->field(x, u, true).dfdx, opt.jacobian_eps);
      loss = loss + regularizer_penalty(cell.regularizer, stats, opt);
    }
    adam.zero_grad();
    loss.sum().backward();
    // A member whose loss is non-finite is frozen at its last finite weights.
    const auto finite = torch::isfinite(loss.detach());
    const auto finite_a = finite.accessor<bool, 1>();
    std::vector<int64_t> dead;
    for (int64_t e = 0; e < E; ++e) {
      const auto ue = static_cast<std::size_t>(e);
      if (alive[ue] && !finite_a[e]) {
        alive[ue] = false;
        diverged_at[ue] = step;
        torch::NoGradGuard no_grad;
        for (std::size_t k = 0; k < params.size(); ++k) frozen[k][e].copy_(params[k][e]);
      }
      if (!alive[ue]) dead.push_back(e);
    }
    const auto dead_idx = torch::tensor(dead, torch::kLong);
    if (!dead.empty()) {
      for (const auto& g : grads) g.index_fill_(0, dead_idx, 0.0);
    }
    adam.step();
    if (!dead.empty()) {
      torch::NoGradGuard no_grad;
      for (std::size_t k = 0; k < params.size(); ++k) {
        params[k].index_copy_(0, dead_idx, frozen[k].index_select(0, dead_idx));
      }
    }
    if (step % opt.eval_every == 0 || step == opt.steps) evaluate(step);
    if (next_checkpoint < opt.checkpoints.size() && step == opt.checkpoints[next_checkpoint]) {
      if (step < opt.steps) checkpoint(step);  // the last step's is the final inference
      ++next_checkpoint;
    }
    if (std::none_of(alive.begin(), alive.end(), [](bool a) { return a; })) break;
  }

  // Inference with each member's best-validation weights (SPEC.md §4).
  torch::NoGradGuard no_grad;
  const double train_s = (elapsed() - checkpoint_overhead_s) / static_cast<double>(E);
  for (std::size_t k = 0; k < params.size(); ++k) params[k].copy_(best[k]);

  const Rollouts rollouts = roll_out(*model, cell, data);
  const InferenceSet& inf = data.inference;
  const int64_t B_inf = static_cast<int64_t>(inf.size());
  const int steps = rollouts.steps;
  const FigureSetup fig = figure_setup(data.system);
  const auto& sq_err = rollouts.sq_err;
  const auto& diverged = rollouts.diverged;
  const auto& newton_failures = rollouts.newton_failures;
  const auto fig_stack = rollouts.figure;  // [E, steps+1, 2, 2]
  const double wall = elapsed();
  const std::vector<double> final_mse = member_mse(rollouts);
  const auto ref05 = reference_trajectory(data.system, data.options, fig.x0_05, fig.u);
  const auto ref075 = reference_trajectory(data.system, data.options, fig.x0_075, fig.u);
  const double inf_value = std::numeric_limits<double>::infinity();
  for (int64_t e = 0; e < E; ++e) {
    RunResult& r = results[static_cast<std::size_t>(e)];
    r.steps = opt.steps;
    r.parameter_count = model->parameter_count();
    r.best_validation_loss = best_val[static_cast<std::size_t>(e)];
    r.wall_time_s = wall / static_cast<double>(E);
    r.newton_failures = newton_failures[e].item<int64_t>();
    r.trajectory_errors.resize(static_cast<std::size_t>(B_inf));
    r.diverged_rollouts = 0;
    for (int64_t i = 0; i < B_inf; ++i) {
      const bool div = diverged[e][i].item<bool>();
      r.trajectory_errors[static_cast<std::size_t>(i)] =
          div ? inf_value : sq_err[e][i].item<double>() / steps;
      r.diverged_rollouts += div;
    }
    r.mse = final_mse[static_cast<std::size_t>(e)];
    // Budgets not reached in the loop (the last step, or every member
    // diverged earlier): the final best weights are the best up to them.
    while (r.checkpoint_steps.size() < opt.checkpoints.size()) {
      r.checkpoint_steps.push_back(opt.checkpoints[r.checkpoint_steps.size()]);
      r.checkpoint_mse.push_back(r.mse);
      r.checkpoint_train_seconds.push_back(train_s);
    }
    auto fig_e = fig_stack[e].contiguous();
    auto fa = fig_e.accessor<double, 3>();
    for (int n = 0; n <= steps; ++n) {
      r.figure_prediction_05.push_back(fa[n][0][0]);
      r.figure_prediction_05.push_back(fa[n][0][1]);
      r.figure_prediction_075.push_back(fa[n][1][0]);
      r.figure_prediction_075.push_back(fa[n][1][1]);
    }
    r.figure_reference_05 = ref05;
    r.figure_reference_075 = ref075;
    std::ostringstream msg;
    r.status = RunStatus::kDone;
    if (diverged_at[static_cast<std::size_t>(e)] >= 0) {
      r.status = RunStatus::kDiverged;
      msg << "training loss non-finite at step " << diverged_at[static_cast<std::size_t>(e)]
          << "; inference used the best weights (step " << r.best_step << "). ";
    }
    if (r.diverged_rollouts > 0) {
      r.status = RunStatus::kDiverged;
      msg << r.diverged_rollouts << " of " << B_inf << " rollouts diverged (non-finite or |x| > "
          << opt.divergence_norm << "). ";
    }
    if (r.newton_failures > 0) {
      msg << r.newton_failures << " DG Newton steps did not converge.";
    }
    r.message = msg.str();
  }
  if (trained) *trained = std::move(model);
  return results;
}

}  // namespace phnn
