// src/training/rollout.cpp
#include "training/rollout.h"

#include <limits>

#include "phnn/common/check.h"
#include "phnn/integrators/discrete_gradient.h"

#include "phnn/training/discrete_step.h"

namespace phnn {

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

ModelOptions inference_model_options(const CellSpec& cell, const SystemData& data) {
  return ModelOptions{cell.model, cell.size, data.system.kind, cell.fused_networks,
                      cell.training.dg_structure_point, torch::kFloat64};
}

Rollouts roll_out(const DynamicsModel& model_ref, const CellSpec& cell, const SystemData& data) {
  PHNN_CHECK(model_ref.options().dtype == torch::kFloat64,
             "roll_out: inference is float64; got a " << model_ref.options().dtype << " model");
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

void fill_inference(const Rollouts& rollouts, int64_t e, double mse, RunResult* r) {
  const int64_t B_inf = rollouts.sq_err.size(1);
  r->newton_failures = rollouts.newton_failures[e].item<int64_t>();
  r->trajectory_errors.resize(static_cast<std::size_t>(B_inf));
  r->diverged_rollouts = 0;
  for (int64_t i = 0; i < B_inf; ++i) {
    const bool div = rollouts.diverged[e][i].item<bool>();
    r->trajectory_errors[static_cast<std::size_t>(i)] =
        div ? std::numeric_limits<double>::infinity()
            : rollouts.sq_err[e][i].item<double>() / rollouts.steps;
    r->diverged_rollouts += div;
  }
  r->mse = mse;
}

FigureReferences figure_references(const SystemData& data) {
  const FigureSetup fig = figure_setup(data.system);
  return {reference_trajectory(data.system, data.options, fig.x0_05, fig.u),
          reference_trajectory(data.system, data.options, fig.x0_075, fig.u)};
}

void fill_figures(const Rollouts& rollouts, int64_t e, const FigureReferences& references,
                  RunResult* r) {
  const auto fig_e = rollouts.figure[e].contiguous();
  const auto fa = fig_e.accessor<double, 3>();
  for (int n = 0; n <= rollouts.steps; ++n) {
    r->figure_prediction_05.push_back(fa[n][0][0]);
    r->figure_prediction_05.push_back(fa[n][0][1]);
    r->figure_prediction_075.push_back(fa[n][1][0]);
    r->figure_prediction_075.push_back(fa[n][1][1]);
  }
  r->figure_reference_05 = references.at_05;
  r->figure_reference_075 = references.at_075;
}

}  // namespace phnn
