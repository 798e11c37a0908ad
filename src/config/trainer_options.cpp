// src/config/trainer_options.cpp — training settings: regularizer weights and
// validation (LibTorch-free; the names are in the header).
#include "phnn/config/trainer_options.h"

#include <cmath>
#include <stdexcept>

#include "phnn/common/check.h"
#include "phnn/config/run_result.h"

namespace phnn {

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
