// tests/reference/oscillator.h — the paper's three oscillators in closed
// form (H, its gradient and Hessian, the cancellation-free Gonzalez and AVF
// discrete gradients, equilibria): an implementation independent of the
// shipped system files' compiled expressions, which the tests compare them
// with. Test code only.
#pragma once

#include <array>

#include <Eigen/Core>

#include "phnn/systems/oscillators.h"

namespace phnn {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

/// Effort-to-flow map of the PH-DAE (eq:phs_S) for one state:
///   [x_dot; w; y] = S [gradH; z(w); u],   S = -S^T (4 x 4),
/// rows (x_q, x_p, w, y), columns (grad_q H, grad_p H, z, u). For all three
/// systems S_ww = 0, so w = S_wx e + S_wu u is explicit in the effort e.
struct PortFlows {
  Vec2 x_dot = Vec2::Zero();
  double w = 0.0;
  double z = 0.0;
  double y = 0.0;
};

/// One controlled oscillator as a port-Hamiltonian system.
///
///   Oscillator duffing(OscillatorOptions::defaults(SystemKind::kDuffing));
///   const Vec2 f = duffing.vector_field(x, /*u=*/0.3);
class Oscillator {
 public:
  explicit Oscillator(OscillatorOptions options);

  const OscillatorOptions& options() const { return options_; }
  SystemKind kind() const { return options_.kind; }

  /// H(q, p) = p^2 / 2m + k q^2 / 2 (+ k3 q^4 / 4 for Duffing) [J].
  double hamiltonian(const Vec2& x) const;
  Vec2 grad_hamiltonian(const Vec2& x) const;
  Mat2 hessian(const Vec2& x) const;

  /// Dissipation law z(w) and z'(w).
  double dissipation(double w) const;
  double dissipation_derivative(double w) const;
  /// z''(w): 0 for the linear dampers, 6 z3 w + 2 z2 for the cubic law.
  double dissipation_second_derivative(double w) const;

  /// S of eq:phs_S (docs/METHOD.md §1 table).
  const Eigen::Matrix4d& S() const { return S_; }
  /// J of eq:phs_JR, rows (x_q, x_p, y), columns (grad_q H, grad_p H, u).
  Eigen::Matrix3d J() const;

  /// Flows of eq:phs_S for effort e (in place of gradH) and input u.
  PortFlows flows(const Vec2& effort, double u) const;
  /// Continuous vector field f(x, u) = flows(gradH(x), u).x_dot.
  Vec2 vector_field(const Vec2& x, double u) const;

  /// Gonzalez discrete gradient (eq: gonzalez-discrete-gradient) in closed
  /// form, free of cancellation. For H = p^2/2m + k q^2/2 + k3 q^4/4 and
  /// a = q + dq/2 (midpoint):
  ///   H(x + dx) - H(x) - gradH(x + dx/2)^T dx = k3 a dq^3 / 4   (exactly),
  /// so dg = gradH(x + dx/2) + (k3 a dq^3 / 4) / (dx^T dx) dx, and the
  /// quotient is O(|dx|) with no 0/0 (dg(x, 0) = gradH(x) exactly).
  Vec2 discrete_gradient(const Vec2& x, const Vec2& dx) const;

  /// d dg / d dx (2 x 2), used by Newton in the implicit DG step.
  Mat2 discrete_gradient_jacobian(const Vec2& x, const Vec2& dx) const;

  /// Average-vector-field discrete gradient, exact for these polynomial H:
  ///   avf(x, dx) = int_0^1 gradH(x + s dx) ds
  ///             = gradH(a) + (k3 a dq^2 / 4) e_q,   a = x + dx/2 (midpoint),
  /// (the odd moments of s - 1/2 vanish). It is a discrete gradient
  /// (avf^T dx = H(x + dx) - H(x), avf(x, 0) = gradH(x)) and, unlike the
  /// Gonzalez one, matches gradH(a) + H'''(a)[dx, dx] / 24 to O(|dx|^4):
  /// the property the fourth-order scheme of discrete_gradient4.h needs.
  Vec2 average_vector_field_gradient(const Vec2& x, const Vec2& dx) const;
  /// d avf / d dx (2 x 2).
  Mat2 average_vector_field_jacobian(const Vec2& x, const Vec2& dx) const;

  /// I_w = {w : z'(w) < 0} of Algorithm 4 (self-sustained only): the open
  /// interval between the roots of z'(w). Throws if it is empty.
  std::array<double, 2> self_oscillation_interval() const;

  /// Equilibrium state x* for a constant input u (docs/METHOD.md §2, Appendix E):
  /// harmonic/Duffing: (q*, 0) with k q* + k3 q*^3 = -u;
  /// self-sustained: (0, m z(-u)).
  Vec2 equilibrium(double u) const;

 private:
  OscillatorOptions options_;
  Eigen::Matrix4d S_;
};

}  // namespace phnn
