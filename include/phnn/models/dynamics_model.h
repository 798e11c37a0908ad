// include/phnn/models/dynamics_model.h — the learned vector field f_theta of
// a stack of E independent models (one per seed).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <torch/torch.h>

#include "phnn/config/model_config.h"
#include "phnn/models/stacked_mlp.h"
#include "phnn/systems/oscillators.h"

namespace phnn {

/// Shapes: x, dx [E, B, n_x]; u [E, B, n_u]; f [E, B, n_x]; df/dx [E, B, n_x, n_x]
/// (n_x = 2, n_u = 1 for the built-in systems)
/// (row = component of f, column = component of x).
struct FieldEval {
  torch::Tensor f;
  torch::Tensor dfdx;  // undefined unless asked for
};

/// A Jacobian regularizer for a hand-written step: the penalty per member
/// [E] of df/dx [E, B, n_x, n_x], and in *dfdx_bar the adjoint of the
/// penalties' sum w.r.t. df/dx. Empty: no regularizer.
using JacobianPenalty =
    std::function<torch::Tensor(const torch::Tensor& dfdx, torch::Tensor* dfdx_bar)>;

/// Options of a model stack.
struct ModelOptions {
  ModelKind kind = ModelKind::kPhnnJr;
  ModelSize size = ModelSize::kSmall;
  /// Supplies S (PHNN-S) or J (PHNN-JR): the known interconnection structure.
  SystemKind structure = SystemKind::kHarmonic;
  /// Networks through the fused autograd node (StackedMlpOptions::fused);
  /// false selects the op-by-op reference path (tests, benchmarks).
  bool fused_networks = true;
  /// Where the DG field evaluates PHNN-JR's R_theta (the other models and
  /// DG4 ignore it): x + dx/2 (default) or x.
  DgStructurePoint dg_structure_point = DgStructurePoint::kMidpoint;
  /// Type of the parameters and of every computation: kFloat64, or kFloat32
  /// (float32 training, TrainerOptions::precision) on the reference path
  /// only (the fused kernels are float64). Parameters are initialized in
  /// float64 either way and then rounded, so a float32 model starts from the
  /// float64 model's weights rounded to float32.
  torch::ScalarType dtype = torch::kFloat64;
  /// The structure of the n-dimensional models of general_ph.h (every
  /// system's); unset, that of the built-in `structure` (builtin_structure).
  std::shared_ptr<const ModelStructure> general = nullptr;
};

/// Base of NODE, PHNN-S and PHNN-JR. Every method is batched over members.
class DynamicsModel {
 public:
  virtual ~DynamicsModel() = default;

  /// Continuous f_theta(x, u); df/dx by forward-mode jets when asked.
  virtual FieldEval field(const torch::Tensor& x, const torch::Tensor& u,
                          bool with_jacobian) const = 0;
  /// True for PHNN-S and PHNN-JR (they have H_theta and support DG).
  virtual bool is_port_hamiltonian() const { return false; }
  /// Inverse-explicit DG field (docs/METHOD.md §4): gradH replaced by the Gonzalez
  /// discrete gradient dg_theta(x, dx); R_theta at x + dx/2, or at x with
  /// ModelOptions::dg_structure_point = kStart.
  virtual torch::Tensor discrete_gradient_field(const torch::Tensor& x, const torch::Tensor& dx,
                                                const torch::Tensor& u,
                                                double min_dx_norm) const;
  /// The DG field f_bar(x, dx, u) and its Jacobian d f_bar / d dx [E, B, n_x, n_x]
  /// (row = component of f_bar), for Newton at inference (PH models only).
  virtual FieldEval discrete_gradient_field_with_jacobian(const torch::Tensor& x,
                                                          const torch::Tensor& dx,
                                                          const torch::Tensor& u,
                                                          double min_dx_norm) const;
  /// Fourth-order DG (docs/METHOD.md "Fourth-order schemes"; PH models
  /// only): x_next = x + h f, with f = F(m, e) + h^2 C in FieldEval::f, where
  /// m = x + dx/2, e = the AVF discrete gradient of H_theta along dx, and in
  /// FieldEval::dfdx the Jacobian A = dF/dx at (m, e) [E, B, n_x, n_x] that C
  /// uses (Newton at inference takes I - (h/2) A as its matrix).
  virtual FieldEval discrete_gradient4_field(const torch::Tensor& x, const torch::Tensor& dx,
                                             const torch::Tensor& u, double h,
                                             double min_dx_norm) const;
  /// A hand-written training step, where the model has one: the loss L_d
  /// of an explicit step (`integrator`: RK2, the explicit midpoint rule, or
  /// RK4) in the mean-L1 norm per member [E]
  /// (discrete_loss with LossNorm::kMeanL1), plus `penalty` of df/dx at x if
  /// one is given (the trainer's regularized loss), with its parameter
  /// gradients added into the flat gradient buffer (after
  /// flatten_parameters), without the graph: NODE's in the same operations
  /// and order as autograd's backward of that loss (the same bits), the PH
  /// models' equal to it to round-off (gradH in reverse mode). Undefined
  /// where there is none (the caller runs autograd); today: NODE, PHNN-S
  /// and PHNN-JR on fused float64 networks (models/manual_step.h).
  virtual torch::Tensor explicit_mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                                              const torch::Tensor& x_next,
                                              const torch::Tensor& u, double h,
                                              const JacobianPenalty& penalty) const;
  /// The same for the DG training step (dg_training_step): PHNN-S and PHNN-JR.
  virtual torch::Tensor dg_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                        const torch::Tensor& u, double h, double min_dx_norm,
                                        const JacobianPenalty& penalty) const;
  /// The same for the DG4 training step (dg4_training_step): PHNN-S and PHNN-JR.
  virtual torch::Tensor dg4_mean_l1_step(const torch::Tensor& x, const torch::Tensor& x_next,
                                         const torch::Tensor& u, double h, double min_dx_norm,
                                         const JacobianPenalty& penalty) const;
  /// The hand-written training step of `integrator`: one of the three above
  /// (undefined where the model has none).
  torch::Tensor mean_l1_step(IntegratorKind integrator, const torch::Tensor& x,
                             const torch::Tensor& x_next, const torch::Tensor& u, double h,
                             double min_dx_norm, const JacobianPenalty& penalty) const;
  /// H_theta(x) [E, B] and gradH_theta(x) [E, B, n_x] (PH models only).
  virtual torch::Tensor hamiltonian(const torch::Tensor& x) const;
  virtual torch::Tensor grad_hamiltonian(const torch::Tensor& x) const;

  std::vector<torch::Tensor> parameters() const;
  /// Moves every parameter into one contiguous buffer: the parameters stay
  /// separate leaves but alias slices of it, and their gradients alias
  /// slices of a second buffer, so an optimizer can update the whole stack
  /// in a handful of ops on {values, gradients}. (Views of one flat leaf
  /// would instead cost a full-size zero fill per parameter in backward.)
  struct FlatParameters {
    torch::Tensor values, gradients;
  };
  FlatParameters flatten_parameters();
  /// Views of a tensor laid out like the flat buffers, shaped like parameters().
  std::vector<torch::Tensor> unflatten(const torch::Tensor& flat_like) const;
  int64_t members() const { return members_; }
  /// Trainable parameters of one member.
  long parameter_count() const;
  const ModelOptions& options() const { return options_; }
  /// The networks, for per-component parameter counts and tests.
  const std::vector<const StackedMlp*> networks() const;

  /// Builds the model stack, member e initialized from seeds[e]: the
  /// n-dimensional models of general_ph.h on options.general, or on the
  /// built-in system's structure when that is unset.
  static std::unique_ptr<DynamicsModel> create(const ModelOptions& options,
                                               const std::vector<std::uint64_t>& seeds);

 protected:
  DynamicsModel(ModelOptions options, int64_t members)
      : options_(options), members_(members) {}
  std::vector<std::unique_ptr<StackedMlp>> nets_;

 private:
  ModelOptions options_;
  int64_t members_;
};

/// A built-in system's structure for the n-state models: its S (rows dq/dt,
/// dp/dt, w, y; columns dH/dq, dH/dp, z, u) and J (PHNN-JR's, on (dH/dq,
/// dH/dp, u)), row-major; n_x = 2, n_w = 1, n_u = 1.
ModelStructure builtin_structure(SystemKind kind);

}  // namespace phnn
