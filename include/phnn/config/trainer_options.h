// include/phnn/config/trainer_options.h — training settings, no LibTorch.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "phnn/common/enum_names.h"
#include "phnn/config/model_config.h"

namespace phnn {

/// Jacobian regularizer (eq:condition-number-loss, eq:spectral-norm-loss,
/// eq:stiffness-ratio-loss; docs/METHOD.md §4).
enum class Regularizer { kNone = 0, kCn = 1, kSn = 2, kSr = 3 };
inline constexpr EnumNames<Regularizer, 4> kRegularizerNames{
    "regularizer",
    {{{Regularizer::kNone, "none"}, {Regularizer::kCn, "cn"}, {Regularizer::kSn, "sn"},
      {Regularizer::kSr, "sr"}}}};
inline std::string to_string(Regularizer reg) { return kRegularizerNames.name(reg); }
/// Throws std::invalid_argument naming the value and the allowed values.
inline Regularizer parse_regularizer(const std::string& name) { return kRegularizerNames.parse(name); }

/// Norm of the discrete loss L_d (docs/METHOD.md §4, "Loss"), with e the
/// error x_{n+1} - x_hat_{n+1} of a pair and h the step:
///   kMeanL1 (the default): mean over pairs and both components of |e_i| / h;
///   kSumL1: mean over pairs of (|e_q| + |e_p|) / h, i.e. 2 x kMeanL1, the
///           paper's 1-norm of the scaled error;
///   kMse:   mean over pairs and both components of e_i^2 / h^2.
enum class LossNorm { kMeanL1 = 0, kSumL1 = 1, kMse = 2 };
inline constexpr EnumNames<LossNorm, 3> kLossNormNames{
    "loss norm", {{{LossNorm::kMeanL1, "mean-l1"}, {LossNorm::kSumL1, "sum-l1"}, {LossNorm::kMse, "mse"}}}};
inline std::string to_string(LossNorm norm) { return kLossNormNames.name(norm); }
/// Every LossNorm, default first.
inline std::vector<LossNorm> all_loss_norms() { return kLossNormNames.all(); }

/// Floating-point type of training (docs/DECISIONS.md, "Ablation knobs"):
///   kFloat64 (the default): everything in float64;
///   kFloat32: the data pairs, parameters, forward, backward, regularizer,
///             Adam and the validation losses in float32 (PyTorch's default
///             dtype), on the op-by-op reference networks; inference stays
///             float64, from the float32 best weights upcast (exactly).
enum class Precision { kFloat64 = 0, kFloat32 = 1 };
inline constexpr EnumNames<Precision, 2> kPrecisionNames{
    "precision", {{{Precision::kFloat64, "float64"}, {Precision::kFloat32, "float32"}}}};
inline std::string to_string(Precision precision) { return kPrecisionNames.name(precision); }
/// Every Precision, default first.
inline std::vector<Precision> all_precisions() { return kPrecisionNames.all(); }
/// Throws std::invalid_argument naming both.
inline Precision parse_precision(const std::string& name) { return kPrecisionNames.parse(name); }

/// The weights inference uses (docs/DECISIONS.md, "Ablation knobs"):
///   kBestValidation (the default): each member's weights at its lowest
///             validation loss (a validation point: step 0, every eval_every
///             steps, the last step);
///   kFinal:   the weights at the member's last validation point, i.e. after
///             the last step (or, for a member whose training diverged, at
///             the last validation point before).
enum class InferenceWeights { kBestValidation = 0, kFinal = 1 };
inline constexpr EnumNames<InferenceWeights, 2> kInferenceWeightsNames{
    "inference weights",
    {{{InferenceWeights::kBestValidation, "best-validation"}, {InferenceWeights::kFinal, "final"}}}};
inline std::string to_string(InferenceWeights weights) { return kInferenceWeightsNames.name(weights); }
/// Every InferenceWeights, default first.
inline std::vector<InferenceWeights> all_inference_weights() { return kInferenceWeightsNames.all(); }

/// Optimizer and schedule of one run (docs/METHOD.md §4). Defaults: docs/METHOD.md.
struct TrainerOptions {
  /// Adam steps.
  int steps = 50000;
  double learning_rate = 1e-3;
  double adam_beta1 = 0.9;
  double adam_beta2 = 0.999;
  double adam_eps = 1e-8;
  /// Minibatch size; all pairs when N_train <= batch_size, otherwise a
  /// reshuffle per epoch with a short last batch.
  int batch_size = 64;
  /// Validation loss at step 0, every eval_every steps and at the last step.
  int eval_every = 500;
  /// Regularizer weights.
  double lambda_cn = 1e-6;
  double lambda_sn = 1e-6;
  double lambda_sr = 1e-4;
  /// Norm of L_d, in training and validation alike (best weights are those
  /// of the lowest validation loss in this norm).
  LossNorm loss_norm = LossNorm::kMeanL1;
  /// Floating-point type of training; inference is float64 either way.
  Precision precision = Precision::kFloat64;
  /// Which weights inference (and every checkpoint) rolls out.
  InferenceWeights inference_weights = InferenceWeights::kBestValidation;
  /// Eps in kappa = s_max / (s_min + eps) and rho = max|Re l| / (min|Re l| + eps).
  double jacobian_eps = 1e-6;
  /// DG/DG4 inference Newton (docs/METHOD.md §4): a row has converged when its
  /// residual max |dx - h f_bar| <= newton_tolerance; at most
  /// newton_max_iterations updates.
  double newton_tolerance = 1e-12;
  int newton_max_iterations = 20;
  /// Where the DG step evaluates PHNN-JR's R_theta(x, u), in training and at
  /// inference alike (ModelOptions::dg_structure_point).
  DgStructurePoint dg_structure_point = DgStructurePoint::kMidpoint;
  /// DG training fallback threshold tau on ||dx||.
  double dg_min_dx_norm = 6e-6;
  /// Divergence: a rollout state with ||x|| > divergence_norm (or non-finite).
  double divergence_norm = 1e6;
  /// Step budgets at which the inference MSE of the best-validation weights
  /// seen so far is also evaluated (RunResult::checkpoints): one training run
  /// answers "how good after s steps" for every s, bitwise what a run with
  /// steps = s would give (the first s steps and their validations are the
  /// same). Strictly increasing, each <= steps and a validation step
  /// (a multiple of eval_every, or steps itself). Empty: none.
  std::vector<int> checkpoints;
  /// No inference after training (a [search] rung before the last, which is
  /// decided on the validation loss): the runs' MSE is NaN, with no
  /// trajectory errors or figures. Enters the run id only when set.
  bool skip_inference = false;

  /// The weight of `reg` (lambda_cn, lambda_sn or lambda_sr); 0 for kNone.
  double weight(Regularizer reg) const;
  /// Sets the weight of `reg`; nothing for kNone.
  void set_weight(Regularizer reg, double value);

  /// Throws std::invalid_argument naming the field, value and constraint.
  void validate() const;
};

}  // namespace phnn
