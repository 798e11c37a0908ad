// src/training/cell_trainer_state.cpp — CellTrainer's saved training state
// (CellCheckpointing in phnn/training/trainer.h): everything the remaining
// steps read, so a restored trainer ends bitwise as an uninterrupted one.
// Touches no file (the caller stores the bytes).
#include <stdexcept>

#include "training/cell_trainer.h"
#include "training/state_bytes.h"

namespace phnn {
namespace internal {

namespace {

constexpr char kMagic[] = "phnn-cell-state";
constexpr std::int32_t kVersion = 1;

// What must match for a state to fit this trainer: the member seeds, the
// step count, N_train, the parameter layout and its type.
void put_identity(StateWriter* out, const CellSpec& cell, const torch::Tensor& flat) {
  out->put_string(kMagic);
  out->put<std::int32_t>(kVersion);
  out->put_vector(cell.seeds);
  out->put<std::int32_t>(cell.training.steps);
  out->put<std::int32_t>(cell.n_train);
  out->put<std::int64_t>(flat.numel());
  out->put<std::int32_t>(static_cast<std::int32_t>(flat.scalar_type()));
}

// A state of this cell, or of the same cell at a smaller step budget that
// is a validation step here (continuing it equals training straight
// through: the budget enters nothing before the last step but its
// validation, which this cell makes too).
void check_identity(StateReader* in, const CellSpec& cell, const torch::Tensor& flat) {
  StateWriter expected;
  put_identity(&expected, cell, flat);
  StateReader mine(expected.bytes());
  const bool head = in->get_string() == mine.get_string() &&
                    in->get<std::int32_t>() == mine.get<std::int32_t>() &&
                    in->get_vector<int>() == mine.get_vector<int>();
  const std::int32_t budget = in->get<std::int32_t>();
  mine.get<std::int32_t>();
  const TrainerOptions& t = cell.training;
  const bool budget_fits =
      budget == t.steps ||
      (budget < t.steps && budget % t.eval_every == 0 && t.checkpoints.empty());
  const bool same = head && budget_fits && in->get<std::int32_t>() == mine.get<std::int32_t>() &&
                    in->get<std::int64_t>() == mine.get<std::int64_t>() &&
                    in->get<std::int32_t>() == mine.get<std::int32_t>();
  if (!same) {
    throw std::invalid_argument(
        "training state belongs to another cell (seeds, steps, N_train or model differ)");
  }
}

void put_trace(StateWriter* out, const std::vector<TracePoint>& trace) {
  out->put<std::uint64_t>(trace.size());
  for (const TracePoint& p : trace) {
    out->put(p.step);
    for (double v : {p.elapsed_s, p.train_loss, p.validation_loss, p.kappa, p.sigma_max, p.rho}) {
      out->put(v);
    }
  }
}

std::vector<TracePoint> get_trace(StateReader* in) {
  const auto n = in->get<std::uint64_t>();
  std::vector<TracePoint> trace;
  for (std::uint64_t i = 0; i < n; ++i) {
    TracePoint p;
    p.step = in->get<int>();
    for (double* v : {&p.elapsed_s, &p.train_loss, &p.validation_loss, &p.kappa, &p.sigma_max,
                      &p.rho}) {
      *v = in->get<double>();
    }
    trace.push_back(p);
  }
  return trace;
}

}  // namespace

std::string CellTrainer::save_state(int step) const {
  StateWriter out;
  put_identity(&out, cell_, flat_.values);
  out.put<std::int32_t>(step);
  out.put<std::uint64_t>(next_checkpoint_);
  out.put(elapsed());
  out.put(checkpoint_overhead_s_);
  out.put_tensor(flat_.values);
  out.put_tensor(adam_->first_moment());
  out.put_tensor(adam_->second_moment());
  out.put<std::int64_t>(adam_->steps_taken());
  sampler_->save(&out);
  for (const torch::Tensor& t : best_) out.put_tensor(t);
  for (const torch::Tensor& t : frozen_) out.put_tensor(t);
  out.put_vector(std::vector<std::uint8_t>(alive_.begin(), alive_.end()));
  out.put_vector(diverged_at_);
  out.put_vector(best_val_);
  for (const RunResult& r : results_) {
    put_trace(&out, r.trace);
    out.put<std::int32_t>(r.best_step);
    out.put_vector(r.checkpoint_steps);
    out.put_vector(r.checkpoint_mse);
    out.put_vector(r.checkpoint_train_seconds);
  }
  return out.bytes();
}

void CellTrainer::restore_state(const std::string& state) {
  StateReader in(state);
  check_identity(&in, cell_, flat_.values);
  first_step_ = in.get<std::int32_t>() + 1;
  next_checkpoint_ = in.get<std::uint64_t>();
  elapsed_before_ = in.get<double>();
  checkpoint_overhead_s_ = in.get<double>();
  in.get_tensor(flat_.values);
  torch::Tensor m = torch::empty_like(adam_->first_moment());
  torch::Tensor v = torch::empty_like(adam_->second_moment());
  in.get_tensor(m);
  in.get_tensor(v);
  adam_->restore(m, v, in.get<std::int64_t>());
  sampler_->restore(&in);
  for (torch::Tensor& t : best_) in.get_tensor(t);
  for (torch::Tensor& t : frozen_) in.get_tensor(t);
  const auto alive = in.get_vector<std::uint8_t>();
  diverged_at_ = in.get_vector<int>();
  best_val_ = in.get_vector<double>();
  const auto E = static_cast<std::size_t>(E_);
  if (alive.size() != E || diverged_at_.size() != E || best_val_.size() != E) {
    throw std::invalid_argument("training state: member lists of another length");
  }
  alive_.assign(alive.begin(), alive.end());
  for (RunResult& r : results_) {
    r.trace = get_trace(&in);
    r.best_step = in.get<std::int32_t>();
    r.checkpoint_steps = in.get_vector<int>();
    r.checkpoint_mse = in.get_vector<double>();
    r.checkpoint_train_seconds = in.get_vector<double>();
  }
  if (!in.at_end()) throw std::invalid_argument("training state: bytes left over");
  start_ = Clock::now();
  last_save_ = elapsed();
}

void CellTrainer::save_if_due(int step) {
  if (!checkpointing_) return;
  const bool stop = checkpointing_->stop_requested && checkpointing_->stop_requested();
  const double interval = checkpointing_->interval_s;
  const bool due = interval > 0 && step < opt_.steps && elapsed() - last_save_ >= interval;
  if (!stop && !due) return;
  const auto begin = Clock::now();
  checkpointing_->save(save_state(step), step);
  checkpoint_overhead_s_ += std::chrono::duration<double>(Clock::now() - begin).count();
  last_save_ = elapsed();
  if (stop) throw CellInterrupted(step, opt_.steps);
}

}  // namespace internal
}  // namespace phnn
