// src/models/head_types.h — what the fused heads of the PH models
// (general_heads.h, general_jet_heads.h) return and keep for their
// backwards: outputs, tapes and adjoints, shared with the hand-written
// steps (manual_step.h). Private to src/models.
#pragma once

#include <torch/torch.h>

namespace phnn {
namespace internal {

/// H [E, B, 1] and gradH [E, B, n] (undefined when not asked for).
struct HamiltonianHead {
  torch::Tensor h, grad;
};
/// What a Hamiltonian head's backward reads (o_g undefined: H only, or
/// gradH in reverse mode), and the adjoints it gives.
struct HamiltonianTape {
  torch::Tensor o, o_g, x, aux;
};
struct HamiltonianAdjoints {
  torch::Tensor o, o_g, x;
};

/// gradH [E, B, n] and the Hessian of H [E, B, n, n] (symmetric; [i][k] =
/// d2H / dx_i dx_k), what their backward reads, and its adjoints.
struct HamiltonianCurvature {
  torch::Tensor grad, hessian;
};
struct CurvatureTape {
  torch::Tensor o, o_g, o_h, x, aux;
};
struct CurvatureAdjoints {
  torch::Tensor o, o_g, o_h, x;
};

/// A field head's adjoints of the effort, the network outputs o and u.
struct JrFieldAdjoints {
  torch::Tensor effort, o, u;
};
/// A field's order-1 jet: f [E, B, n_x] and g [E, B, n_x (direction), n_x]
/// = d f / d x_i, and the adjoints of its inputs.
struct JrFieldJet {
  torch::Tensor f, g;
};
struct JrFieldJetAdjoints {
  torch::Tensor effort, effort_g, o, o_g, u;
};

}  // namespace internal
}  // namespace phnn
