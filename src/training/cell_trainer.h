// src/training/cell_trainer.h — CellTrainer, the phases of train_cell
// (private to src/training): prepare, step / validate / checkpoint, finish
// in trainer.cpp; the saved training state in cell_trainer_state.cpp.
// Touches no file.
#pragma once

#include <chrono>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <torch/torch.h>

#include "phnn/models/dynamics_model.h"
#include "phnn/kernels/flat_adam.h"
#include "phnn/training/trainer.h"
#include "training/batch_sampler.h"
#include "training/cell_data.h"
#include "training/rollout.h"

namespace phnn {
namespace internal {

using Clock = std::chrono::steady_clock;

// One cell's training as named phases (docs: the trainer in one sitting):
//   CellTrainer trainer(cell, data, progress);   // prepare: model, Adam, tensors
//   trainer.train();                             // step / validate / checkpoint
//   results = trainer.finish();                  // best weights, rollouts, results
// Each phase is a member function that fits on a screen; the state they
// share is the members below.
/// Pairs per chunk of the loss passes without gradients (validation, the
/// training set's loss); 500 unless a test sets another size.
void set_step_chunk(int64_t rows);

class CellTrainer {
 public:
  // With `checkpointing` (may be null) training states are saved and, from
  // its resume_from, restored (cell_trainer_state.cpp).
  CellTrainer(const CellSpec& cell, const CellData& data, const ProgressCallback& progress,
              const CellCheckpointing* checkpointing);

  void train();
  std::vector<RunResult> finish();
  // The float64 stack the rollouts used, with the best weights.
  std::unique_ptr<DynamicsModel> release_model() {
    return std::move(inference_model_ ? inference_model_ : model_);
  }

 private:
  // The data of the cell as tensors; *_all / validation ones expanded over
  // the E members (views, no copies).
  struct Tensors {
    torch::Tensor x, x_next, u;              // [N, n_x], [N, n_x], [N, n_u]
    torch::Tensor x_all, x_next_all, u_all;  // [E, N, .]
    torch::Tensor xv, xv_next, uv;           // [E, V, .]
  };
  Tensors make_tensors() const;

  // Wall time of the cell's training so far, across restarts.
  double elapsed() const {
    return elapsed_before_ + std::chrono::duration<double>(Clock::now() - start_).count();
  }
  // L_d (Eq. 30) per member in opt_.loss_norm (discrete_loss): by default the
  // mean over batch and components of |x_{n+1} - x_hat| / h.
  // `f_at_x`, when defined, is f(x, u), reused as an explicit step's first stage.
  // Without it (validation, the training set's loss) the steps are taken a
  // chunk of pairs at a time (set_step_chunk) and the loss over all at once.
  torch::Tensor data_loss(const torch::Tensor& x, const torch::Tensor& xn, const torch::Tensor& u,
                          const torch::Tensor& f_at_x = {}) const;
  // x_hat of the discrete model for the pairs (x, xn, u) [E, B, .].
  torch::Tensor discrete_step(const torch::Tensor& x, const torch::Tensor& xn,
                              const torch::Tensor& u, const torch::Tensor& f_at_x) const;
  void step(int step, BatchSampler& sampler);
  torch::Tensor loss_and_gradients(const torch::Tensor& x, const torch::Tensor& xn,
                                   const torch::Tensor& u);
  void freeze_non_finite(const torch::Tensor& loss, int step, std::vector<int64_t>* dead);
  void validate(int step);
  void report_progress(int step, std::vector<double> live_best) const;
  // Rollouts of the best weights so far, in float64: in the training model (the caller
  // restores its weights if training goes on) or, after float32 training, inference_model_.
  Rollouts roll_out_best(const std::function<bool()>& stop = {});
  // Throws CellInterrupted at the last trained step after saving `state`
  // (taken before the rollouts replaced the weights by the best ones).
  [[noreturn]] void interrupt_before_inference(const std::string& state);
  void checkpoint(int step);
  // The training state after `step` as bytes, and back (cell_trainer_state.cpp).
  std::string save_state(int step) const;
  void restore_state(const std::string& state);
  // Saves the state when the interval has passed or a stop was asked;
  // throws CellInterrupted after saving for a stop.
  void save_if_due(int step);
  double train_seconds_per_run() const {
    return (elapsed() - checkpoint_overhead_s_) / static_cast<double>(E_);
  }
  void fill_result(int64_t e, const Rollouts* rollouts, double mse, double train_s, double wall);
  void fill_with_rollouts(int64_t e, const Rollouts& rollouts, double mse, double train_s,
                          RunResult* r) const;
  static constexpr double kNoMse = std::numeric_limits<double>::quiet_NaN();

  const CellSpec& cell_;
  const CellData& data_;
  const TrainerOptions& opt_;
  const ProgressCallback& progress_;
  Clock::time_point start_ = Clock::now();
  const int64_t E_;
  const double h_;
  // The regularizer's penalty for the hand-written steps (empty: none).
  const JacobianPenalty penalty_;
  std::unique_ptr<DynamicsModel> model_;
  // float32 training only: the float64 stack the rollouts use.
  std::unique_ptr<DynamicsModel> inference_model_;
  DynamicsModel::FlatParameters flat_;
  std::vector<torch::Tensor> params_, grads_;  // alias flat_.values / gradients
  std::unique_ptr<FlatAdam> adam_;
  Tensors t_;
  std::vector<RunResult> results_;
  std::vector<bool> alive_;
  std::vector<int> diverged_at_;
  std::vector<double> best_val_;
  std::vector<torch::Tensor> best_, frozen_;
  double checkpoint_overhead_s_ = 0.0;
  // Restart state: the first step to take, the next budget checkpoint, the
  // time trained before this process, the last save.
  const CellCheckpointing* checkpointing_ = nullptr;
  std::unique_ptr<BatchSampler> sampler_;
  int first_step_ = 1;
  int last_step_ = 0;  // the last step train() took (or restored)
  std::size_t next_checkpoint_ = 0;
  double elapsed_before_ = 0.0;
  double last_save_ = 0.0;
};

}  // namespace internal
}  // namespace phnn
