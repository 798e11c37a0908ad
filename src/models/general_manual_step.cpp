// src/models/general_manual_step.cpp — hand-written training steps of the
// n-dimensional NODE, PHNN-S and PHNN-JR (include/phnn/models/general_ph.h)
// on fused float64 networks: RK2 for the three, DG for the PH models, with
// the mean-L1 loss; NODE also with a Jacobian penalty. Forward, loss and
// backward run without an autograd graph through the n-state heads' taped
// forms (general_heads.h) in the order autograd takes the model's graph, so
// loss and gradients are bitwise those of loss.sum().backward()
// (tests/models/general_manual_step_test.cpp). The composition (RK2, DG,
// the loss) is models/manual_step.h's. Touches only the models' gradient sinks.
//
// Backward of one PH field evaluation f(y) = F(gradH(y), y), as autograd
// orders it (of the nodes ready at once, the one created last runs first):
//   PHNN-JR: F = [(J - L^T L) [e; u]]_{1:n_x}, L from L_R([y, u]):
//     the JR head (e~, o~) -> L_R (y~ c) -> the H head (y~ b) -> L_H (y~ a);
//     y~ = (c + b) + a.
//   PHNN-S: w = [S_wx S_wu] [e; u], F = S_x [e; z(w); u], z from L_z(w):
//     the S head (e~ A, w~ B) -> L_z (w~ C) -> the w head from w~ = B + C
//     (e~ D); e~ = A + D. No ports: F = [S_xx S_xu] [e; u], one linear head.
// A PH model's regularized steps (order-2 jets of H) stay on autograd.
#include <array>
#include <memory>

#include "models/fused_heads_common.h"
#include "models/general_heads.h"
#include "models/manual_step.h"
#include "phnn/models/general_ph.h"

namespace phnn {
namespace {

using internal::heads::rows_like;
using namespace internal::manual;
using torch::Tensor;

const HamiltonianOps kGeneralHead{internal::general_hamiltonian_forward,
                                  internal::general_hamiltonian_backward};

// PHNN-JR: F(e, y) = JR(e, L_R(y, u), u).
EffortFieldRecorder jr_effort_field(const StackedMlp& l_r, const Tensor& u,
                                    const std::vector<double>& J) {
  return [&l_r, u, &J](const Tensor& effort, const Tensor& y) {
    auto net_r = std::make_shared<TapedNet>(TapedNet{l_r, nullptr});
    const Tensor o_r = net_r->forward(cat_rows(y, u), 0, 0).v;
    TapedEffortField t{internal::general_jr_field_forward(effort, u, o_r, J), {}};
    const int64_t n_x = y.size(-1);
    t.backward = [=, &J](const Tensor& f_bar, bool input) {
      const auto jr = internal::general_jr_field_backward(effort, u, o_r, J, f_bar);
      const Tensor c = net_r->backward({jr.o}, input);
      return std::make_pair(jr.effort, input ? c.narrow(-1, 0, n_x) : Tensor());
    };
    return t;
  };
}

// PHNN-S without ports: F = [S_xx S_xu] [e; u].
EffortFieldRecorder linear_effort_field(const Tensor& u, const std::vector<double>& s_x_rows) {
  return [u, &s_x_rows](const Tensor& effort, const Tensor& /*y*/) {
    const int64_t n_x = effort.size(-1), n_u = u.size(-1);
    TapedEffortField t{internal::general_linear_forward(effort, u, s_x_rows, static_cast<int>(n_x)),
                       {}};
    t.backward = [=, &s_x_rows](const Tensor& f_bar, bool /*input*/) {
      const auto adj = internal::general_linear_backward(f_bar, s_x_rows, static_cast<int>(n_x),
                                                         static_cast<int>(n_u));
      return std::make_pair(adj.a, Tensor());
    };
    return t;
  };
}

// PHNN-S with n_w ports (file comment).
EffortFieldRecorder s_effort_field(const StackedMlp& l_z, const Tensor& u,
                                   const std::vector<double>& s_w_rows,
                                   const std::vector<double>& S, int n_w) {
  return [&l_z, u, &s_w_rows, &S, n_w](const Tensor& effort, const Tensor& /*y*/) {
    auto net_z = std::make_shared<TapedNet>(TapedNet{l_z, nullptr});
    const Tensor w = internal::general_linear_forward(effort, u, s_w_rows, n_w);
    const Tensor o = net_z->forward(w, 0, 0).v;
    TapedEffortField t{internal::general_s_field_forward(effort, u, o, w, S, n_w), {}};
    const int n_x = static_cast<int>(effort.size(-1)), n_u = static_cast<int>(u.size(-1));
    t.backward = [=, &s_w_rows, &S](const Tensor& f_bar, bool /*input*/) {
      const auto field = internal::general_s_field_backward(o, w, S, n_x, n_w, n_u, f_bar);
      const Tensor w_bar = field.w + net_z->backward({field.o}, true);
      const auto head = internal::general_linear_backward(w_bar, s_w_rows, n_x, n_u);
      return std::make_pair(field.e + head.a, Tensor());
    };
    return t;
  };
}

// No hand-written Jacobian field for the PH models (their order-2 jets run
// op by op): the step is taken only without a penalty.
const JacobianFieldRecorder kNoJacobianField;

}  // namespace

Tensor GeneralPhnnJr::rk2_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                                       double h, const JacobianPenalty& penalty) const {
  if (penalty || !has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_rk2_mean_l1(l_h(), kGeneralHead, x, x_next, h,
                        jr_effort_field(*nets_[1], u, structure().J), kNoJacobianField, penalty);
}

Tensor GeneralPhnnJr::dg_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                                      double h, double min_dx_norm,
                                      const JacobianPenalty& penalty) const {
  if (penalty || !has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  return ph_dg_mean_l1(l_h(), kGeneralHead, x, x_next, h, min_dx_norm, dissipation_at_start(),
                       jr_effort_field(*nets_[1], u, structure().J), kNoJacobianField, penalty);
}

Tensor GeneralPhnnS::rk2_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                                      double h, const JacobianPenalty& penalty) const {
  if (penalty || !has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  const ModelStructure& s = structure();
  const EffortFieldRecorder field = s.n_w == 0
                                        ? linear_effort_field(u, s_x_rows_)
                                        : s_effort_field(*nets_[1], u, s_w_rows_, s.S, s.n_w);
  return ph_rk2_mean_l1(l_h(), kGeneralHead, x, x_next, h, field, kNoJacobianField, penalty);
}

Tensor GeneralPhnnS::dg_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                                     double h, double min_dx_norm,
                                     const JacobianPenalty& penalty) const {
  if (penalty || !has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  const Tensor u = rows_like(u_in, x);
  const ModelStructure& s = structure();
  const EffortFieldRecorder field = s.n_w == 0
                                        ? linear_effort_field(u, s_x_rows_)
                                        : s_effort_field(*nets_[1], u, s_w_rows_, s.S, s.n_w);
  return ph_dg_mean_l1(l_h(), kGeneralHead, x, x_next, h, min_dx_norm, false, field,
                       kNoJacobianField, penalty);
}

// NODE: f = MLP([y, u]) (manual_step.h).
Tensor GeneralNode::rk2_mean_l1_step(const Tensor& x, const Tensor& x_next, const Tensor& u_in,
                                     double h, const JacobianPenalty& penalty) const {
  if (!has_manual_step(nets_, options().dtype)) return {};
  torch::NoGradGuard no_grad;
  return node_rk2_mean_l1(*nets_[0], x, x_next, rows_like(u_in, x), h, penalty);
}

}  // namespace phnn
