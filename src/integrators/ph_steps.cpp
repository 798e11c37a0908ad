// src/integrators/ph_steps.cpp — the n-dimensional RK2, RK4, DG and DG4
// steps of include/phnn/integrators/ph_steps.h.
#include "phnn/integrators/ph_steps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "phnn/common/check.h"

namespace phnn {

VecX ph_rk2_step(const PhSystem& system, const VecX& x, const VecX& u, double h) {
  const VecX k1 = system.vector_field(x, u);
  return x + h * system.vector_field(x + 0.5 * h * k1, u);
}

VecX ph_rk4_step(const PhSystem& system, const VecX& x, const VecX& u, double h) {
  const VecX k1 = system.vector_field(x, u);
  const VecX k2 = system.vector_field(x + 0.5 * h * k1, u);
  const VecX k3 = system.vector_field(x + 0.5 * h * k2, u);
  const VecX k4 = system.vector_field(x + h * k3, u);
  return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

namespace {

void require_step(double h, const char* who) {
  PHNN_REQUIRE(std::isfinite(h) && h > 0.0, who << ": h = " << h << "; violated constraint: h > 0.");
}

// Sets status from the residual; true when the iteration must stop.
bool finished(double residual, const VecX& dx, int it, const DiscreteGradientOptions& options,
              PhImplicitStep* out) {
  out->residual = residual;
  out->newton_iterations = it;
  if (!std::isfinite(residual) || !dx.allFinite()) {
    out->status = StepStatus::kNonFinite;
    return true;
  }
  if (residual <= options.newton_tolerance) {
    out->status = StepStatus::kConverged;
    return true;
  }
  if (it >= options.max_newton_iterations) {
    out->status = StepStatus::kMaxIterations;
    return true;
  }
  return false;
}

// LU with partial pivoting (the first largest |pivot|) of a small matrix,
// factored once and solved many times: Eigen's PartialPivLU on dynamic sizes
// takes its blocked path and was a seventh of a system file's DG step.
class SmallLu {
 public:
  void compute(const MatX& m) {
    lu_ = m;
    const int n = static_cast<int>(m.rows());
    perm_.resize(n);
    for (int k = 0; k < n; ++k) {
      int pivot = k;
      for (int i = k + 1; i < n; ++i) {
        if (std::fabs(lu_(i, k)) > std::fabs(lu_(pivot, k))) pivot = i;
      }
      perm_[k] = pivot;
      if (pivot != k) lu_.row(k).swap(lu_.row(pivot));
      for (int i = k + 1; i < n; ++i) {
        lu_(i, k) /= lu_(k, k);
        for (int j = k + 1; j < n; ++j) lu_(i, j) -= lu_(i, k) * lu_(k, j);
      }
    }
  }
  /// x with M x = b (M of compute()).
  VecX solve(VecX b) const {
    const int n = static_cast<int>(lu_.rows());
    for (int k = 0; k < n; ++k) {  // the row swaps in order, then L
      if (perm_[k] != k) std::swap(b(k), b(perm_[k]));
    }
    for (int k = 0; k < n; ++k) {
      for (int i = k + 1; i < n; ++i) b(i) -= lu_(i, k) * b(k);
    }
    for (int i = n - 1; i >= 0; --i) {
      for (int j = i + 1; j < n; ++j) b(i) -= lu_(i, j) * b(j);
      b(i) /= lu_(i, i);
    }
    return b;
  }

 private:
  MatX lu_;
  Eigen::Matrix<int, Eigen::Dynamic, 1, 0, kMaxDimension, 1> perm_;
};

}  // namespace

// Simplified Newton: the matrix I - h dF/de d dg/d dx and its LU are kept
// while the residual shrinks at least 10x per iteration (at h_gen the
// increment barely moves it), and re-evaluated otherwise.
PhImplicitStep ph_discrete_gradient_step(const PhSystem& system, const VecX& x, const VecX& u,
                                         double h, const DiscreteGradientOptions& options) {
  require_step(h, "ph_discrete_gradient_step");
  const int n = system.n_x();
  PhImplicitStep out;
  VecX dx = ph_rk2_step(system, x, u, h) - x;
  SmallLu lu;
  bool have_matrix = false;
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    out.flows = system.flows(system.discrete_gradient(x, dx), u);
    const VecX r = dx - h * out.flows.x_dot;
    const double residual = r.lpNorm<Eigen::Infinity>();
    if (finished(residual, dx, it, options, &out)) break;
    if (!have_matrix || residual > 0.1 * previous) {
      lu.compute(MatX::Identity(n, n) - h * system.flow_jacobian(out.flows.w) *
                                            system.discrete_gradient_jacobian(x, dx));
      have_matrix = true;
    }
    previous = residual;
    dx -= lu.solve(r);
  }
  out.x_next = x + dx;
  return out;
}

// Gauss-Legendre nodes 1/2 -+ sqrt(15)/10, 1/2 with weights 5/18, 4/9, 5/18.
VecX ph_average_vector_field_gradient(const PhSystem& system, const VecX& x, const VecX& dx) {
  const double c = std::sqrt(15.0) / 10.0;
  VecX g = (5.0 / 18.0) * system.grad_hamiltonian(x + (0.5 - c) * dx) +
           (4.0 / 9.0) * system.grad_hamiltonian(x + 0.5 * dx) +
           (5.0 / 18.0) * system.grad_hamiltonian(x + (0.5 + c) * dx);
  const double n2 = dx.squaredNorm();
  if (!(std::sqrt(n2) >= PhSystem::kMinDxNorm)) return system.grad_hamiltonian(x + 0.5 * dx);
  const double defect = system.hamiltonian(x + dx) - system.hamiltonian(x) - g.dot(dx);
  return g + (defect / n2) * dx;
}

namespace {

struct Dg4Terms {
  VecX effort, correction;
  PhFlows flows;
  MatX F_e, A;
};

Dg4Terms dg4_terms(const PhSystem& system, const VecX& x, const VecX& dx, const VecX& u) {
  const int nx = system.n_x(), nw = system.n_w();
  const MatX& S = system.S();
  Dg4Terms t;
  t.effort = ph_average_vector_field_gradient(system, x, dx);
  t.flows = system.flows(t.effort, u);
  t.F_e = system.flow_jacobian(t.flows.w);
  const MatX Q = system.hessian(x + 0.5 * dx);
  t.A = t.F_e * Q;
  const VecX& v = t.flows.x_dot;
  t.correction = -(t.A * (t.A * v)) / 12.0;
  if (nw > 0) {
    const VecX s = S.block(nx, 0, nw, nx) * (Q * v);
    t.correction += S.block(0, nx, nx, nw) * system.dissipation_second(t.flows.w, s) / 24.0;
  }
  return t;
}

VecX dg4_residual(const PhSystem& system, const VecX& x, const VecX& dx, const VecX& u, double h) {
  const Dg4Terms t = dg4_terms(system, x, dx, u);
  return dx - h * t.flows.x_dot - (h * h * h) * t.correction;
}

// Central differences, step 1e-6 max(|d|_inf, 1e-12) (discrete_gradient4.cpp).
MatX dg4_jacobian_by_differences(const PhSystem& system, const VecX& x, const VecX& dx,
                                 const VecX& u, double h) {
  const int n = system.n_x();
  const double eta = 1e-6 * std::max(dx.lpNorm<Eigen::Infinity>(), 1e-12);
  MatX jac(n, n);
  for (int j = 0; j < n; ++j) {
    VecX plus = dx, minus = dx;
    plus(j) += eta;
    minus(j) -= eta;
    jac.col(j) = (dg4_residual(system, x, plus, u, h) - dg4_residual(system, x, minus, u, h)) /
                 (plus(j) - minus(j));
  }
  return jac;
}

PhImplicitStep solve_dg4(const PhSystem& system, const VecX& x, const VecX& u, double h, VecX dx,
                         const DiscreteGradientOptions& options) {
  const int n = system.n_x();
  const MatX I = MatX::Identity(n, n);
  PhImplicitStep out;
  bool full_newton = false;
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    const Dg4Terms t = dg4_terms(system, x, dx, u);
    const VecX r = dx - h * t.flows.x_dot - (h * h * h) * t.correction;
    out.flows = t.flows;
    out.correction_power = t.effort.dot(t.correction);
    const double residual = r.lpNorm<Eigen::Infinity>();
    if (finished(residual, dx, it, options, &out)) break;
    full_newton = full_newton || residual > 0.1 * previous;
    previous = residual;
    const MatX jac = full_newton ? dg4_jacobian_by_differences(system, x, dx, u, h)
                                 : MatX(I - h * (I - (h * h / 12.0) * t.A * t.A) * t.F_e *
                                                (0.5 * system.hessian(x + 0.5 * dx)));
    dx -= jac.partialPivLu().solve(r);
  }
  out.x_next = x + dx;
  return out;
}

}  // namespace

PhImplicitStep ph_discrete_gradient4_step(const PhSystem& system, const VecX& x, const VecX& u,
                                          double h, const DiscreteGradientOptions& options) {
  require_step(h, "ph_discrete_gradient4_step");
  PhImplicitStep out = solve_dg4(system, x, u, h, ph_rk4_step(system, x, u, h) - x, options);
  if (out.status == StepStatus::kConverged) return out;
  const PhImplicitStep dg = ph_discrete_gradient_step(system, x, u, h, options);
  if (dg.status != StepStatus::kConverged) return out;
  const int first = out.newton_iterations;
  out = solve_dg4(system, x, u, h, dg.x_next - x, options);
  out.newton_iterations += first;
  return out;
}

}  // namespace phnn
