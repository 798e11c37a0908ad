// src/training/trainer.cpp — train_cell as CellTrainer's phases (class in
// cell_trainer.h): prepare, step / validate / checkpoint, finish (the
// rollouts are in rollout.cpp, the minibatch order in batch_sampler.h,
// CellSpec's checks in cell_spec.cpp, saved training states in
// cell_trainer_state.cpp), in the training precision (float64, or float32
// with float64 inference).
// Size: one class whose phases share the stack, the optimizer and the best weights.
#include "phnn/training/trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include <torch/torch.h>

#include "kernels/ordered_sum.h"
#include "phnn/integrators/step_options.h"
#include "phnn/models/dynamics_model.h"
#include "phnn/training/discrete_step.h"
#include "phnn/kernels/flat_adam.h"
#include "phnn/training/regularizers.h"
#include "training/cell_trainer.h"
#include "training/rollout.h"

namespace phnn {

CellInterrupted::CellInterrupted(int at_step, int total_steps)
    : std::runtime_error("training stopped after step " + std::to_string(at_step) + " of " +
                         std::to_string(total_steps) + "; its state was saved"),
      step(at_step) {}

namespace internal {

namespace {

// The first `count` rows of a row-major [.][width] array as [count, width]
// in `dtype` (float32: the float64 data rounded).
torch::Tensor to_tensor(const std::vector<double>& v, std::size_t count, int width,
                        torch::ScalarType dtype) {
  const auto rows = static_cast<int64_t>(count);
  return torch::from_blob(const_cast<double*>(v.data()), {rows, width}, torch::kFloat64)
      .clone()
      .to(dtype);
}

// The model a cell trains: the inference model (float64) unless training is
// float32, which runs on the reference networks (the fused kernels are
// float64 only) with the float64 initialization rounded.
ModelOptions training_model_options(const CellSpec& cell, const CellData& data) {
  ModelOptions options = inference_model_options(cell, data);
  if (cell.training.precision == Precision::kFloat32) {
    options.dtype = torch::kFloat32;
    options.fused_networks = false;
  }
  return options;
}

}  // namespace

CellTrainer::CellTrainer(const CellSpec& cell, const CellData& data,
                         const ProgressCallback& progress, const CellCheckpointing* checkpointing)
    : cell_(cell), data_(data), opt_(cell.training), progress_(progress),
      E_(static_cast<int64_t>(cell.seeds.size())), h_(data.step),
      penalty_(jacobian_penalty(cell.regularizer, opt_)), checkpointing_(checkpointing) {
  std::vector<std::uint64_t> seeds(cell.seeds.begin(), cell.seeds.end());
  model_ = DynamicsModel::create(training_model_options(cell, data), seeds);
  if (model_->options().dtype != torch::kFloat64) {
    inference_model_ = DynamicsModel::create(inference_model_options(cell, data), seeds);
  }
  // One contiguous leaf for the whole stack: Adam in a handful of ops.
  flat_ = model_->flatten_parameters();
  params_ = model_->parameters();
  grads_ = model_->unflatten(flat_.gradients);
  adam_ = std::make_unique<FlatAdam>(flat_.values, flat_.gradients, opt_);
  t_ = make_tensors();
  const auto E = static_cast<std::size_t>(E_);
  results_.resize(E);
  alive_.assign(E, true);
  diverged_at_.assign(E, -1);
  best_val_.assign(E, std::numeric_limits<double>::infinity());
  for (const auto& p : params_) {
    best_.push_back(p.detach().clone());
    frozen_.push_back(p.detach().clone());
  }
  sampler_ = std::make_unique<BatchSampler>(cell_.seeds, cell_.n_train, opt_.batch_size);
  if (checkpointing_ && !checkpointing_->resume_from.empty()) {
    restore_state(checkpointing_->resume_from);
  }
}

CellTrainer::Tensors CellTrainer::make_tensors() const {
  const auto N = static_cast<std::size_t>(cell_.n_train);
  const std::size_t V = data_.validation.count;
  const int nx = data_.n_x, nu = data_.n_u;
  const torch::ScalarType dtype = model_->options().dtype;
  Tensors t;
  t.x = to_tensor(data_.train.x, N, nx, dtype);
  t.x_next = to_tensor(data_.train.x_next, N, nx, dtype);
  t.u = to_tensor(data_.train.u, N, nu, dtype);
  t.x_all = t.x.unsqueeze(0).expand({E_, -1, -1});
  t.x_next_all = t.x_next.unsqueeze(0).expand({E_, -1, -1});
  t.u_all = t.u.unsqueeze(0).expand({E_, -1, -1});
  t.xv = to_tensor(data_.validation.x, V, nx, dtype).unsqueeze(0).expand({E_, -1, -1});
  t.xv_next = to_tensor(data_.validation.x_next, V, nx, dtype).unsqueeze(0).expand({E_, -1, -1});
  t.uv = to_tensor(data_.validation.u, V, nu, dtype).unsqueeze(0).expand({E_, -1, -1});
  return t;
}

torch::Tensor CellTrainer::discrete_step(const torch::Tensor& x, const torch::Tensor& xn,
                                         const torch::Tensor& u,
                                         const torch::Tensor& f_at_x) const {
  return training_step(*model_, cell_.integrator, x, xn, u, h_, opt_.dg_min_dx_norm, f_at_x);
}

// Pairs per chunk of a validation pass: the jets of a chunk, not of all
// 2 500 pairs, are what a pass holds (an n_x = 8 large cell of 10 members
// peaked at 2 GB unchunked). Every row's step depends on that row alone
// (per-row GEMM chains, row-wise heads), and the loss sums the same terms
// in the same order, so chunking changes the memory, not the bits
// (tests/training/trainer_test.cpp, which sets other sizes through
// set_step_chunk).
static int64_t step_chunk = 500;

void set_step_chunk(int64_t rows) { step_chunk = rows; }

// DG4's pass holds the op-by-op order-2 jets of its chunk: up to 4.3 GB
// RSS for 500 pairs of an n_x = 8 large cell of 10 members. It takes at
// most twice a DG4 rollout chunk (rollout.h's dg4_chunk_rows: 80 pairs
// there; the 2-state cells keep 500).
torch::Tensor CellTrainer::data_loss(const torch::Tensor& x, const torch::Tensor& xn,
                                     const torch::Tensor& u, const torch::Tensor& f_at_x) const {
  const int64_t B = x.size(1);
  const int64_t chunk =
      cell_.integrator == IntegratorKind::kDg4
          ? std::min(step_chunk, 2 * dg4_chunk_rows(x.size(0), x.size(2), u.size(2)))
          : step_chunk;
  if (f_at_x.defined() || torch::GradMode::is_enabled() || B <= chunk) {
    return discrete_loss(xn, discrete_step(x, xn, u, f_at_x), h_, opt_.loss_norm);
  }
  std::vector<torch::Tensor> parts;
  for (int64_t s = 0; s < B; s += chunk) {
    const int64_t len = std::min(chunk, B - s);
    const torch::Tensor us = u.size(1) == B ? u.narrow(1, s, len) : u;
    parts.push_back(discrete_step(x.narrow(1, s, len), xn.narrow(1, s, len), us, {}));
  }
  return discrete_loss(xn, torch::cat(parts, /*dim=*/1), h_, opt_.loss_norm);
}

// Steps first_step_..steps (1.. unless a saved state was restored).
// Steps until the budget, or until no member is alive. A state restored
// with every member dead (a smaller [search] rung's final one) trains no
// further, as training straight through stopped there.
void CellTrainer::train() {
  const auto any_alive = [this] {
    return std::any_of(alive_.begin(), alive_.end(), [](bool a) { return a; });
  };
  if (first_step_ == 1) validate(0);
  int last = first_step_ - 1;
  const int first = any_alive() ? first_step_ : opt_.steps + 1;
  for (int s = first; s <= opt_.steps; ++s) {
    last = s;
    step(s, *sampler_);
    if (s % opt_.eval_every == 0 || s == opt_.steps) validate(s);
    if (next_checkpoint_ < opt_.checkpoints.size() && s == opt_.checkpoints[next_checkpoint_]) {
      if (s < opt_.steps) checkpoint(s);  // the last step's is the final inference
      ++next_checkpoint_;
    }
    if (!any_alive()) break;
    save_if_due(s);
  }
  last_step_ = last;
  if (checkpointing_ && checkpointing_->save_final) checkpointing_->save_final(save_state(last), last);
}

// One Adam step on a minibatch (every pair when N <= batch: no gather).
void CellTrainer::step(int step, BatchSampler& sampler) {
  const bool full_batch = cell_.n_train <= opt_.batch_size;
  const auto idx = full_batch ? torch::Tensor() : sampler.next();
  const auto x = full_batch ? t_.x_all : t_.x.index({idx});
  const auto xn = full_batch ? t_.x_next_all : t_.x_next.index({idx});
  const auto u = full_batch ? t_.u_all : t_.u.index({idx});
  adam_->zero_grad();
  const auto loss = loss_and_gradients(x, xn, u);
  std::vector<int64_t> dead;
  freeze_non_finite(loss, step, &dead);
  const auto dead_idx = torch::tensor(dead, torch::kLong);
  if (!dead.empty()) {
    for (const auto& g : grads_) g.index_fill_(0, dead_idx, 0.0);
  }
  adam_->step();
  if (!dead.empty()) {
    torch::NoGradGuard no_grad;
    for (std::size_t k = 0; k < params_.size(); ++k) {
      params_[k].index_copy_(0, dead_idx, frozen_[k].index_select(0, dead_idx));
    }
  }
}

// L_d per member (+ the regularizer's penalty) on a minibatch, its parameter
// gradients added into the flat gradient buffer: by the model's hand-written
// step where it has one (no graph; autograd's values to round-off, NODE's
// bitwise), else by autograd.
torch::Tensor CellTrainer::loss_and_gradients(const torch::Tensor& x, const torch::Tensor& xn,
                                              const torch::Tensor& u) {
  const bool regularized = cell_.regularizer != Regularizer::kNone;
  if (opt_.loss_norm == LossNorm::kMeanL1) {
    const torch::Tensor loss =
        model_->mean_l1_step(cell_.integrator, x, xn, u, h_, opt_.dg_min_dx_norm, penalty_);
    if (loss.defined()) return loss;
  }
  // A regularizer needs df/dx at the batch; the same evaluation's f is an
  // explicit step's first stage, so RK2/RK4 do not evaluate f(x) twice.
  const FieldEval at_x = regularized ? model_->field(x, u, true) : FieldEval{};
  auto loss = data_loss(x, xn, u, at_x.f);
  if (regularized) {
    const auto stats = jacobian_stats(at_x.dfdx, opt_.jacobian_eps);
    loss = loss + regularizer_penalty(cell_.regularizer, stats, opt_);
  }
  loss.sum().backward();
  return loss;
}

// A member whose loss is non-finite is frozen at its last finite weights;
// *dead lists every frozen member.
void CellTrainer::freeze_non_finite(const torch::Tensor& loss, int step,
                                    std::vector<int64_t>* dead) {
  const auto finite = torch::isfinite(loss.detach());
  const auto finite_a = finite.accessor<bool, 1>();
  for (int64_t e = 0; e < E_; ++e) {
    const auto ue = static_cast<std::size_t>(e);
    if (alive_[ue] && !finite_a[e]) {
      alive_[ue] = false;
      diverged_at_[ue] = step;
      torch::NoGradGuard no_grad;
      for (std::size_t k = 0; k < params_.size(); ++k) frozen_[k][e].copy_(params_[k][e]);
    }
    if (!alive_[ue]) dead->push_back(e);
  }
}

// Validation point: losses and Jacobian statistics into the trace, best
// weights kept per member.
void CellTrainer::validate(int step) {
  torch::NoGradGuard no_grad;
  const auto val = data_loss(t_.xv, t_.xv_next, t_.uv);
  const auto train = data_loss(t_.x_all, t_.x_next_all, t_.u_all);
  const auto stats = jacobian_stats(model_->field(t_.x_all, t_.u_all, true).dfdx, opt_.jacobian_eps);
  const auto kappa = internal::ordered_mean(stats.kappa, 1),
             sigma = internal::ordered_mean(stats.sigma_max, 1),
             rho = internal::ordered_mean(stats.rho, 1);
  std::vector<int64_t> improved;
  std::vector<double> live_best;
  for (int64_t e = 0; e < E_; ++e) {
    const auto ue = static_cast<std::size_t>(e);
    if (!alive_[ue]) continue;
    TracePoint tp;
    tp.step = step;
    tp.elapsed_s = elapsed();
    tp.train_loss = train[e].item<double>();
    tp.validation_loss = val[e].item<double>();
    tp.kappa = kappa[e].item<double>();
    tp.sigma_max = sigma[e].item<double>();
    tp.rho = rho[e].item<double>();
    results_[ue].trace.push_back(tp);
    // The weights kept for inference: the lowest validation loss so far, or
    // (inference_weights = final) the latest.
    const bool keep = opt_.inference_weights == InferenceWeights::kFinal ||
                      (std::isfinite(tp.validation_loss) && tp.validation_loss < best_val_[ue]);
    if (keep) {
      best_val_[ue] = tp.validation_loss;
      results_[ue].best_step = step;
      improved.push_back(e);
    }
    live_best.push_back(best_val_[ue]);
  }
  if (!improved.empty()) {
    const auto idx = torch::tensor(improved, torch::kLong);
    for (std::size_t k = 0; k < params_.size(); ++k) {
      best_[k].index_copy_(0, idx, params_[k].detach().index_select(0, idx));
    }
  }
  report_progress(step, std::move(live_best));
}

void CellTrainer::report_progress(int step, std::vector<double> live_best) const {
  if (!progress_) return;
  TrainProgress p;
  p.step = step;
  p.total_steps = opt_.steps;
  p.elapsed_s = elapsed();
  if (!live_best.empty()) {
    const auto middle = live_best.begin() + static_cast<long>(live_best.size() / 2);
    std::nth_element(live_best.begin(), middle, live_best.end());
    p.best_validation_loss = *middle;
  }
  progress_(p);
}

Rollouts CellTrainer::roll_out_best(const std::function<bool()>& stop) {
  torch::NoGradGuard no_grad;
  const std::vector<torch::Tensor> target =
      inference_model_ ? inference_model_->parameters() : params_;
  for (std::size_t k = 0; k < target.size(); ++k) target[k].copy_(best_[k]);
  return roll_out(inference_model_ ? *inference_model_ : *model_, cell_, data_, stop);
}

void CellTrainer::interrupt_before_inference(const std::string& state) {
  checkpointing_->save(state, last_step_);
  throw CellInterrupted(last_step_, opt_.steps);
}

// Inference of the best weights so far at a step budget; the training
// weights are restored bitwise (or untouched: float32 training rolls out
// inference_model_), so training goes on unchanged.
void CellTrainer::checkpoint(int step) {
  const auto begin = Clock::now();
  const double train_s = train_seconds_per_run();
  torch::NoGradGuard no_grad;
  std::vector<torch::Tensor> current;
  if (!inference_model_) {
    for (const torch::Tensor& p : params_) current.push_back(p.detach().clone());
  }
  const std::vector<double> mse = member_mse(roll_out_best());
  for (std::size_t k = 0; k < current.size(); ++k) params_[k].copy_(current[k]);
  for (std::size_t e = 0; e < results_.size(); ++e) {
    results_[e].checkpoint_steps.push_back(step);
    results_[e].checkpoint_mse.push_back(mse[e]);
    results_[e].checkpoint_train_seconds.push_back(train_s);
  }
  checkpoint_overhead_s_ += std::chrono::duration<double>(Clock::now() - begin).count();
}

// Inference with each member's kept weights (best-validation or final), then
// the results.
std::vector<RunResult> CellTrainer::finish() {
  torch::NoGradGuard no_grad;
  const double train_s = train_seconds_per_run();
  if (opt_.skip_inference) {  // a [search] rung before the last: no rollouts
    for (int64_t e = 0; e < E_; ++e) fill_result(e, nullptr, kNoMse, train_s, elapsed());
    return std::move(results_);
  }
  // A stop asked before or during the rollouts (a signal; an ahead item at
  // its round's end) saves the state of the last step: the cell goes on
  // from it straight to inference, bitwise as if never stopped.
  const std::function<bool()> stop = checkpointing_ ? checkpointing_->stop_requested : nullptr;
  const std::string state = stop ? save_state(last_step_) : std::string();
  if (stop && stop()) interrupt_before_inference(state);
  Rollouts rollouts;
  try {
    rollouts = roll_out_best(stop);
  } catch (const RolloutStopped&) {
    interrupt_before_inference(state);
  }
  const double wall = elapsed();
  const std::vector<double> mse = member_mse(rollouts);
  for (int64_t e = 0; e < E_; ++e) {
    fill_result(e, &rollouts, mse[static_cast<std::size_t>(e)], train_s, wall);
  }
  return std::move(results_);
}

// `rollouts` null: no inference (TrainerOptions::skip_inference), MSE NaN.
void CellTrainer::fill_result(int64_t e, const Rollouts* rollouts, double mse, double train_s,
                              double wall) {
  RunResult& r = results_[static_cast<std::size_t>(e)];
  r.steps = opt_.steps;
  r.parameter_count = model_->parameter_count();
  r.best_validation_loss = best_val_[static_cast<std::size_t>(e)];
  r.wall_time_s = wall / static_cast<double>(E_);
  r.train_seconds = train_s;
  r.mse = mse;
  if (rollouts) fill_with_rollouts(e, *rollouts, mse, train_s, &r);
  // The weights the rollouts used (float32 training: upcast, exactly).
  for (const torch::Tensor& best : best_) {
    const torch::Tensor w = best[e].to(torch::kFloat64).contiguous();
    r.weights.insert(r.weights.end(), w.data_ptr<double>(), w.data_ptr<double>() + w.numel());
  }
  r.status = RunStatus::kDone;
  std::ostringstream msg;
  if (diverged_at_[static_cast<std::size_t>(e)] >= 0) {
    r.status = RunStatus::kDiverged;
    msg << "training loss non-finite at step " << diverged_at_[static_cast<std::size_t>(e)]
        << "; inference used the "
        << (opt_.inference_weights == InferenceWeights::kFinal ? "last weights before it"
                                                               : "best weights")
        << " (step " << r.best_step << "). ";
  }
  if (r.diverged_rollouts > 0) {
    r.status = RunStatus::kDiverged;
    msg << r.diverged_rollouts << " of " << r.trajectory_errors.size()
        << " rollouts diverged (non-finite or |x| > " << opt_.divergence_norm << "). ";
  }
  if (!rollouts) {
    msg << "No inference: a [search] rung before the last, decided on its validation loss. ";
  }
  if (r.newton_failures > 0) {
    msg << r.newton_failures << " DG Newton steps did not converge.";
  }
  r.message = msg.str();
}

// The results a member's rollouts give: inference errors, the budget
// checkpoints not reached in the loop, the figure trajectories.
void CellTrainer::fill_with_rollouts(int64_t e, const Rollouts& rollouts, double mse,
                                     double train_s, RunResult* r) const {
  fill_inference(rollouts, e, mse, r);
  // Budgets not reached in the loop (the last step, or every member
  // diverged earlier): the final best weights are the best up to them.
  while (r->checkpoint_steps.size() < opt_.checkpoints.size()) {
    r->checkpoint_steps.push_back(opt_.checkpoints[r->checkpoint_steps.size()]);
    r->checkpoint_mse.push_back(r->mse);
    r->checkpoint_train_seconds.push_back(train_s);
  }
  fill_figures(rollouts, e, data_, r);
}

}  // namespace internal

namespace {

std::vector<RunResult> train_cell_data(const CellSpec& cell, const CellData& data,
                                       const ProgressCallback& progress,
                                       std::unique_ptr<DynamicsModel>* trained,
                                       const CellCheckpointing* checkpointing) {
  validate_cell(cell, data);
  internal::CellTrainer trainer(cell, data, progress, checkpointing);
  trainer.train();
  std::vector<RunResult> results = trainer.finish();
  if (trained) *trained = trainer.release_model();
  return results;
}

}  // namespace

std::vector<RunResult> train_cell(const CellSpec& cell, const PhSystemData& data,
                                  const PhSystem& system, const ProgressCallback& progress,
                                  std::unique_ptr<DynamicsModel>* trained,
                                  const CellCheckpointing* checkpointing) {
  return train_cell_data(cell, make_cell_data(data, system), progress, trained, checkpointing);
}

}  // namespace phnn
