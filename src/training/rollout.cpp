// src/training/rollout.cpp — the inference phase of a cell (training/rollout.h):
// rollouts of every member, Eq. 31, figure trajectories. Touches no file.
#include "training/rollout.h"

#include <algorithm>
#include <limits>
#include <vector>

#include "kernels/ordered_sum.h"
#include "phnn/common/check.h"

#include "phnn/training/discrete_step.h"

namespace phnn {

ModelOptions inference_model_options(const CellSpec& cell, const CellData& data) {
  return ModelOptions{cell.model, cell.size, SystemKind::kHarmonic, cell.fused_networks,
                      cell.training.dg_structure_point, torch::kFloat64, data.general};
}

namespace {
// [steps, B, n_u]: u_n of the inference rows, then the figure rows; undefined
// when the inputs are constant.
torch::Tensor step_inputs(const CellData& data, int64_t B_inf, int64_t F, int steps) {
  if (data.inference_inputs.empty()) return {};
  const int64_t nu = data.n_u;
  auto out = torch::empty({steps, B_inf + F, nu}, torch::kFloat64);
  out.narrow(1, 0, B_inf)
      .copy_(torch::from_blob(const_cast<double*>(data.inference_inputs.data()), {B_inf, steps, nu},
                              torch::kFloat64)
                 .transpose(0, 1));
  for (int64_t k = 0; k < F; ++k) {
    out.select(1, B_inf + k)
        .copy_(torch::from_blob(const_cast<double*>(data.figure_inputs[k].data()), {steps, nu},
                                torch::kFloat64));
  }
  return out;
}

// Rows per chunk of a DG4 Newton step: 0 = dg4_chunk_rows (rollout.h), else
// this many (tests). Every row's iterates depend on that row alone (per-row
// GEMM chains and jets, per-row Newton decisions; a chunk that stops early
// holds converged rows only, which keep their solution in a longer loop
// too), so chunking changes the memory, not the bits.
int64_t dg4_rollout_chunk = 0;

// inference_step of `integrator`; DG4 on the rows [s, s + chunk) in turn
// (its jets are what a rollout holds), the others on every row at once. Only
// DG4 is ever chunked: it keeps no Newton cache and always reports
// `converged`, which the chunks' concatenation needs.
DgInferenceStep step_in_chunks(const DynamicsModel& model, IntegratorKind integrator,
                               const torch::Tensor& x, const torch::Tensor& u, double h,
                               const DgInferenceOptions& options, DgNewtonJacobian* cache) {
  const int64_t B = x.size(1);
  const int64_t chunk = integrator != IntegratorKind::kDg4 ? B
                        : dg4_rollout_chunk > 0            ? dg4_rollout_chunk
                                                : dg4_chunk_rows(x.size(0), x.size(2), u.size(2));
  if (B <= chunk) return inference_step(model, integrator, x, u, h, options, cache);
  std::vector<torch::Tensor> next, converged;
  DgInferenceStep out;
  for (int64_t s = 0; s < B; s += chunk) {
    const int64_t len = std::min(chunk, B - s);
    const DgInferenceStep part =
        inference_step(model, integrator, x.narrow(1, s, len), u.narrow(1, s, len), h, options);
    next.push_back(part.x_next);
    converged.push_back(part.converged);
    out.iterations = std::max(out.iterations, part.iterations);
    out.jacobian_evaluations += part.jacobian_evaluations;
  }
  out.x_next = torch::cat(next, /*dim=*/1);
  out.converged = torch::cat(converged, /*dim=*/1);
  return out;
}
}  // namespace

void set_dg4_rollout_chunk(int64_t rows) { dg4_rollout_chunk = rows; }

// The op-by-op order-2 jets of DG4 (port_hamiltonian.cpp) hold products of
// [E, rows, n_x, n_x, m, m] doubles (m = n_x + n_u). Measured on an n_x = 8
// large cell of 10 members: ~8 MB RSS per validation pair and ~25 MB per
// Newton row, 4.3 GB for 500 pairs. 2^21 doubles per chunk of such a
// product: 40 rows there; n_x <= 6 with 10 members is not chunked (>= 118).
int64_t dg4_chunk_rows(int64_t members, int64_t n_x, int64_t n_u) {
  const int64_t m = n_x + n_u, per_row = members * n_x * n_x * m * m;
  return std::max<int64_t>(16, (int64_t{1} << 21) / std::max<int64_t>(per_row, 1));
}

Rollouts roll_out(const DynamicsModel& model_ref, const CellSpec& cell, const CellData& data,
                  const std::function<bool()>& stop) {
  PHNN_CHECK(model_ref.options().dtype == torch::kFloat64,
             "roll_out: inference is float64; got a " << model_ref.options().dtype << " model");
  torch::NoGradGuard no_grad;
  const DynamicsModel* model = &model_ref;
  const TrainerOptions& opt = cell.training;
  const int64_t E = model_ref.members();
  const int64_t nx = data.n_x, nu = data.n_u;
  const int64_t B_inf = static_cast<int64_t>(data.inference_count);
  const int steps = data.inference_steps;
  // Rows: the inference trajectories, then the figure trajectories (if any).
  const int64_t F = data.has_figures ? 2 : 0;
  const int64_t B = B_inf + F;
  // states [B_inf][steps + 1][n_x] -> ref [steps + 1, B_inf, n_x]; x0 = ref[0].
  const auto ref = torch::from_blob(const_cast<double*>(data.inference_states.data()),
                                    {B_inf, steps + 1, nx}, torch::kFloat64)
                       .transpose(0, 1)
                       .contiguous();
  auto x0 = torch::empty({B, nx}, torch::kFloat64);
  auto u0 = torch::empty({B, nu}, torch::kFloat64);
  x0.narrow(0, 0, B_inf).copy_(ref[0]);
  u0.narrow(0, 0, B_inf)
      .copy_(torch::from_blob(const_cast<double*>(data.inference_u.data()), {B_inf, nu},
                              torch::kFloat64));
  for (int64_t k = 0; k < F; ++k) {
    for (int64_t j = 0; j < nx; ++j) x0[B_inf + k][j] = data.figure_x0[k][j];
    for (int64_t j = 0; j < nu; ++j) u0[B_inf + k][j] = data.figure_u[k][j];
  }
  const double h_inf = data.inference_step;
  auto x = x0.unsqueeze(0).expand({E, B, nx}).contiguous();
  const auto u_constant = u0.unsqueeze(0).expand({E, B, nu}).contiguous();
  // Time-varying inputs: the recorded u_n of every row, replayed step by step.
  const torch::Tensor u_steps = step_inputs(data, B_inf, F, steps);  // [steps, B, n_u] or undefined
  auto diverged = torch::zeros({E, B}, torch::kBool);
  auto sq_err = torch::zeros({E, B_inf}, torch::kFloat64);
  auto newton_failures = torch::zeros({E}, torch::kLong);
  std::vector<torch::Tensor> figure_states;
  if (F > 0) figure_states.push_back(x.narrow(1, B_inf, F).clone());
  DgInferenceOptions dg_options;
  dg_options.tolerance = opt.newton_tolerance;
  dg_options.max_iterations = opt.newton_max_iterations;
  dg_options.min_dx_norm = opt.dg_min_dx_norm;
  DgNewtonJacobian newton_jacobian;  // carried along the rollout
  for (int n = 1; n <= steps; ++n) {
    if (stop && n % kRolloutStopEvery == 0 && stop()) throw RolloutStopped{};
    const torch::Tensor u =
        u_steps.defined() ? u_steps[n - 1].unsqueeze(0).expand({E, B, nu}).contiguous() : u_constant;
    const DgInferenceStep s =
        step_in_chunks(*model, cell.integrator, x, u, h_inf, dg_options, &newton_jacobian);
    const torch::Tensor& next = s.x_next;
    if (s.converged.defined()) {
      newton_failures += (s.converged.logical_not() & diverged.logical_not()).sum(-1);
    }
    const auto bad = torch::isfinite(next).all(-1).logical_not() |
                     (internal::ordered_sum(next * next, 1).sqrt() > opt.divergence_norm);
    diverged = diverged | bad;
    x = torch::where(diverged.unsqueeze(-1), torch::zeros_like(next), next);
    const auto diff = x.narrow(1, 0, B_inf) - ref[n].unsqueeze(0);
    sq_err += internal::ordered_sum(diff * diff, 1);
    if (F > 0) {
      figure_states.push_back(torch::where(diverged.narrow(1, B_inf, F).unsqueeze(-1),
                                           torch::full_like(next.narrow(1, B_inf, F), NAN),
                                           next.narrow(1, B_inf, F)));
    }
  }
  Rollouts out;
  out.sq_err = sq_err;
  out.diverged = diverged;
  out.newton_failures = newton_failures;
  if (F > 0) out.figure = torch::stack(figure_states, 1);
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

void fill_figures(const Rollouts& rollouts, int64_t e, const CellData& data, RunResult* r) {
  if (!data.has_figures) return;
  const auto fig_e = rollouts.figure[e].contiguous();
  const auto fa = fig_e.accessor<double, 3>();
  for (int n = 0; n <= rollouts.steps; ++n) {
    for (int64_t j = 0; j < data.n_x; ++j) r->figure_prediction_05.push_back(fa[n][0][j]);
    for (int64_t j = 0; j < data.n_x; ++j) r->figure_prediction_075.push_back(fa[n][1][j]);
  }
  r->figure_reference_05 = data.figure_references[0];
  r->figure_reference_075 = data.figure_references[1];
}

}  // namespace phnn
