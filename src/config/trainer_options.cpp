// src/config/trainer_options.cpp — training settings and run statuses: names,
// parsers, validation (LibTorch-free).
#include "phnn/config/trainer_options.h"

#include <cmath>
#include <stdexcept>

#include "phnn/common/check.h"
#include "phnn/config/run_result.h"

namespace phnn {

std::string to_string(Regularizer reg) {
  switch (reg) {
    case Regularizer::kNone: return "none";
    case Regularizer::kCn: return "cn";
    case Regularizer::kSn: return "sn";
    case Regularizer::kSr: return "sr";
  }
  return "unknown";
}

Regularizer parse_regularizer(const std::string& name) {
  for (Regularizer r : {Regularizer::kNone, Regularizer::kCn, Regularizer::kSn, Regularizer::kSr}) {
    if (name == to_string(r)) return r;
  }
  throw std::invalid_argument("unknown regularizer \"" + name +
                              "\"; expected one of: none, cn, sn, sr");
}

std::string to_string(LossNorm norm) {
  switch (norm) {
    case LossNorm::kMeanL1: return "mean-l1";
    case LossNorm::kSumL1: return "sum-l1";
    case LossNorm::kMse: return "mse";
  }
  return "unknown";
}

std::vector<LossNorm> all_loss_norms() {
  return {LossNorm::kMeanL1, LossNorm::kSumL1, LossNorm::kMse};
}

std::string to_string(Precision precision) {
  switch (precision) {
    case Precision::kFloat64: return "float64";
    case Precision::kFloat32: return "float32";
  }
  return "unknown";
}

std::vector<Precision> all_precisions() { return {Precision::kFloat64, Precision::kFloat32}; }

Precision parse_precision(const std::string& name) {
  for (Precision p : all_precisions()) {
    if (name == to_string(p)) return p;
  }
  throw std::invalid_argument("unknown precision \"" + name + "\"; expected one of: float64, float32");
}

std::string to_string(InferenceWeights weights) {
  switch (weights) {
    case InferenceWeights::kBestValidation: return "best-validation";
    case InferenceWeights::kFinal: return "final";
  }
  return "unknown";
}

std::vector<InferenceWeights> all_inference_weights() {
  return {InferenceWeights::kBestValidation, InferenceWeights::kFinal};
}

std::string to_string(RunStatus status) {
  switch (status) {
    case RunStatus::kPending: return "pending";
    case RunStatus::kDone: return "done";
    case RunStatus::kDiverged: return "diverged";
    case RunStatus::kFailed: return "failed";
  }
  return "unknown";
}

RunStatus parse_run_status(const std::string& name) {
  for (RunStatus s : {RunStatus::kPending, RunStatus::kDone, RunStatus::kDiverged, RunStatus::kFailed}) {
    if (name == to_string(s)) return s;
  }
  throw std::invalid_argument("unknown run status \"" + name +
                              "\"; expected one of: pending, done, diverged, failed");
}

double TrainerOptions::weight(Regularizer reg) const {
  switch (reg) {
    case Regularizer::kCn: return lambda_cn;
    case Regularizer::kSn: return lambda_sn;
    case Regularizer::kSr: return lambda_sr;
    case Regularizer::kNone: break;
  }
  return 0.0;
}

void TrainerOptions::set_weight(Regularizer reg, double value) {
  if (reg == Regularizer::kCn) lambda_cn = value;
  if (reg == Regularizer::kSn) lambda_sn = value;
  if (reg == Regularizer::kSr) lambda_sr = value;
}

void TrainerOptions::validate() const {
  auto fail = [](const char* field, double value, const char* constraint) {
    PHNN_REQUIRE(false, "Invalid TrainerOptions: " << field << " = " << value
                                                   << "; violated constraint: " << constraint
                                                   << ".");
  };
  if (steps < 0) fail("steps", steps, "steps >= 0");
  if (!(learning_rate > 0.0) || !std::isfinite(learning_rate))
    fail("learning_rate", learning_rate, "learning_rate > 0");
  if (!(adam_beta1 >= 0.0 && adam_beta1 < 1.0)) fail("adam_beta1", adam_beta1, "0 <= beta1 < 1");
  if (!(adam_beta2 >= 0.0 && adam_beta2 < 1.0)) fail("adam_beta2", adam_beta2, "0 <= beta2 < 1");
  if (!(adam_eps > 0.0)) fail("adam_eps", adam_eps, "adam_eps > 0");
  if (batch_size < 1) fail("batch_size", batch_size, "batch_size >= 1");
  if (eval_every < 1) fail("eval_every", eval_every, "eval_every >= 1");
  if (!(lambda_cn >= 0.0)) fail("lambda_cn", lambda_cn, "lambda_cn >= 0");
  if (!(lambda_sn >= 0.0)) fail("lambda_sn", lambda_sn, "lambda_sn >= 0");
  if (!(lambda_sr >= 0.0)) fail("lambda_sr", lambda_sr, "lambda_sr >= 0");
  if (!(jacobian_eps > 0.0)) fail("jacobian_eps", jacobian_eps, "jacobian_eps > 0");
  if (!(newton_tolerance > 0.0)) fail("newton_tolerance", newton_tolerance, "newton_tolerance > 0");
  if (newton_max_iterations < 1)
    fail("newton_max_iterations", newton_max_iterations, "newton_max_iterations >= 1");
  if (!(dg_min_dx_norm >= 0.0)) fail("dg_min_dx_norm", dg_min_dx_norm, "dg_min_dx_norm >= 0");
  if (!(divergence_norm > 0.0)) fail("divergence_norm", divergence_norm, "divergence_norm > 0");
  for (std::size_t i = 0; i < checkpoints.size(); ++i) {
    const int s = checkpoints[i];
    if (s < 1 || s > steps) fail("checkpoints", s, "1 <= checkpoint <= steps");
    if (s % eval_every != 0 && s != steps)
      fail("checkpoints", s, "a checkpoint is a validation step (a multiple of eval_every, or steps)");
    if (i > 0 && s <= checkpoints[i - 1]) fail("checkpoints", s, "strictly increasing");
  }
}

}  // namespace phnn
