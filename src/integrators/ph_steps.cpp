// src/integrators/ph_steps.cpp — the n-dimensional RK2, RK4, DG and DG4
// steps of include/phnn/integrators/ph_steps.h.
#include "phnn/integrators/ph_steps.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "phnn/common/check.h"
#include "phnn/common/small_lu.h"

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

// The Newton matrix's LU (common/small_lu.h), factored once and solved
// many times: Eigen's PartialPivLU on dynamic sizes takes its blocked path
// and was a seventh of a system file's DG step.
class SmallLu {
 public:
  void compute(const MatX& m) {
    n_ = static_cast<int>(m.rows());
    for (int i = 0; i < n_; ++i) {
      for (int j = 0; j < n_; ++j) lu_[i * n_ + j] = m(i, j);
    }
    lu_factor(lu_.data(), perm_.data(), n_);
  }
  /// b <- x with M x = b (M of compute()).
  void solve_in_place(VecX* b) const { lu_solve(lu_.data(), perm_.data(), b->data(), n_); }

 private:
  int n_ = 0;
  std::array<double, kMaxDimension * kMaxDimension> lu_;  // row-major
  std::array<int, kMaxDimension> perm_;
};

// I - h F G with each entry's sum over k in order (Eigen's coefficient-
// based product gives the same bits up to n = 9, its blocked GEMM above).
// F = dF/de is mostly zeros: skipping F_ik = 0 adds nothing but +-0 to a
// sum that starts at +0 (same bits for a finite G).
MatX newton_matrix(const MatX& F, const MatX& G, double h) {
  const int n = static_cast<int>(F.rows());
  MatX m(n, n);
  for (int i = 0; i < n; ++i) {
    int nonzero[kMaxDimension];
    int count = 0;
    for (int k = 0; k < n; ++k) {
      if (F(i, k) != 0.0) nonzero[count++] = k;
    }
    for (int j = 0; j < n; ++j) {
      double sum = 0.0;
      for (int c = 0; c < count; ++c) sum += F(i, nonzero[c]) * G(nonzero[c], j);
      m(i, j) = (i == j ? 1.0 : 0.0) - h * sum;
    }
  }
  return m;
}

// r = dx - h F; returns max |r_i| (NaN if any r_i is NaN).
double newton_residual(const VecX& dx, const VecX& F, double h, VecX* r) {
  const int n = static_cast<int>(dx.size());
  r->resize(n);
  double norm = 0.0;
  bool nan = false;
  for (int i = 0; i < n; ++i) {
    (*r)(i) = dx(i) - h * F(i);
    const double a = std::fabs((*r)(i));
    nan = nan || std::isnan(a);
    if (a > norm) norm = a;
  }
  return nan ? std::numeric_limits<double>::quiet_NaN() : norm;
}

}  // namespace

// Simplified Newton: the matrix I - h dF/de d dg/d dx and its LU are kept
// while the residual shrinks at least 10x per iteration (at h_gen the
// increment barely moves it), and re-evaluated otherwise.
PhImplicitStep ph_discrete_gradient_step(const PhSystem& system, const VecX& x, const VecX& u,
                                         double h, const DiscreteGradientOptions& options) {
  require_step(h, "ph_discrete_gradient_step");
  const int n = system.n_x();
  PhImplicitStep out;
  VecX dx = ph_rk2_step(system, x, u, h);
  for (int i = 0; i < n; ++i) dx(i) -= x(i);
  VecX r;
  SmallLu lu;
  bool have_matrix = false;
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0;; ++it) {
    system.flows(system.discrete_gradient(x, dx), u, &out.flows);
    const double residual = newton_residual(dx, out.flows.x_dot, h, &r);
    if (finished(residual, dx, it, options, &out)) break;
    if (!have_matrix || residual > 0.1 * previous) {
      lu.compute(newton_matrix(system.flow_jacobian(out.flows.w),
                               system.discrete_gradient_jacobian(x, dx), h));
      have_matrix = true;
    }
    previous = residual;
    lu.solve_in_place(&r);
    for (int i = 0; i < n; ++i) dx(i) -= r(i);
  }
  out.x_next.resize(n);
  for (int i = 0; i < n; ++i) out.x_next(i) = x(i) + dx(i);
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
