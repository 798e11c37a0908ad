// tests/reference/oscillator.cpp — reference/oscillator.h.
#include "reference/oscillator.h"

#include <cmath>

#include "phnn/common/check.h"
#include "phnn/common/cr_math.h"

namespace phnn {

Oscillator::Oscillator(OscillatorOptions options) : options_(options) {
  options_.validate();
  // docs/METHOD.md §1: rows (x_q, x_p, w, y), columns (grad_q H, grad_p H, z, u).
  if (options_.kind == SystemKind::kSelfSustained) {
    S_ << 0, -1, 1, 0,  //
        1, 0, 0, 0,     //
        -1, 0, 0, -1,   //
        0, 0, 1, 0;
  } else {
    S_ << 0, 1, 0, 0,   //
        -1, 0, -1, -1,  //
        0, 1, 0, 0,     //
        0, 1, 0, 0;
  }
}

double Oscillator::hamiltonian(const Vec2& x) const {
  const double q = x(0), p = x(1);
  double h = 0.5 * p * p / options_.mass + 0.5 * options_.stiffness * q * q;
  if (options_.kind == SystemKind::kDuffing) {
    h += 0.25 * options_.cubic_stiffness * q * q * q * q;
  }
  return h;
}

Vec2 Oscillator::grad_hamiltonian(const Vec2& x) const {
  const double q = x(0), p = x(1);
  double dq = options_.stiffness * q;
  if (options_.kind == SystemKind::kDuffing) {
    dq += options_.cubic_stiffness * q * q * q;
  }
  return Vec2(dq, p / options_.mass);
}

Mat2 Oscillator::hessian(const Vec2& x) const {
  Mat2 hess = Mat2::Zero();
  hess(0, 0) = options_.stiffness;
  if (options_.kind == SystemKind::kDuffing) {
    hess(0, 0) += 3.0 * options_.cubic_stiffness * x(0) * x(0);
  }
  hess(1, 1) = 1.0 / options_.mass;
  return hess;
}

double Oscillator::dissipation(double w) const {
  if (options_.kind != SystemKind::kSelfSustained) return options_.damping * w;
  const auto& a = options_.z_coefficients;
  return w * (a[0] + w * (a[1] + w * a[2]));
}

double Oscillator::dissipation_derivative(double w) const {
  if (options_.kind != SystemKind::kSelfSustained) return options_.damping;
  const auto& a = options_.z_coefficients;
  return a[0] + w * (2.0 * a[1] + 3.0 * w * a[2]);
}

double Oscillator::dissipation_second_derivative(double w) const {
  if (options_.kind != SystemKind::kSelfSustained) return 0.0;
  const auto& a = options_.z_coefficients;
  return 2.0 * a[1] + 6.0 * w * a[2];
}

Eigen::Matrix3d Oscillator::J() const {
  Eigen::Matrix3d j;
  if (options_.kind == SystemKind::kSelfSustained) {
    j << 0, -1, 0,  //
        1, 0, 0,    //
        0, 0, 0;
  } else {
    j << 0, 1, 0,  //
        -1, 0, -1,  //
        0, 1, 0;
  }
  return j;
}

PortFlows Oscillator::flows(const Vec2& effort, double u) const {
  // S_ww = 0: w depends on the effort and u only.
  PortFlows out;
  out.w = S_(2, 0) * effort(0) + S_(2, 1) * effort(1) + S_(2, 3) * u;
  out.z = dissipation(out.w);
  for (int r = 0; r < 2; ++r) {
    out.x_dot(r) = S_(r, 0) * effort(0) + S_(r, 1) * effort(1) +
                   S_(r, 2) * out.z + S_(r, 3) * u;
  }
  out.y = S_(3, 0) * effort(0) + S_(3, 1) * effort(1) + S_(3, 2) * out.z +
          S_(3, 3) * u;
  return out;
}

Vec2 Oscillator::vector_field(const Vec2& x, double u) const {
  return flows(grad_hamiltonian(x), u).x_dot;
}

Vec2 Oscillator::discrete_gradient(const Vec2& x, const Vec2& dx) const {
  const Vec2 mid = x + 0.5 * dx;
  Vec2 g = grad_hamiltonian(mid);
  if (options_.kind == SystemKind::kDuffing) {
    const double n2 = dx.squaredNorm();
    if (n2 > 0.0) {
      const double dq = dx(0);
      // (H(x+dx) - H(x) - gradH(mid)^T dx) / |dx|^2, exact: k3 a dq^3 / 4 / n2.
      const double phi =
          0.25 * options_.cubic_stiffness * mid(0) * dq * (dq * dq / n2);
      g += phi * dx;
    }
  }
  return g;
}

Mat2 Oscillator::discrete_gradient_jacobian(const Vec2& x,
                                            const Vec2& dx) const {
  const Vec2 mid = x + 0.5 * dx;
  Mat2 jac = 0.5 * hessian(mid);
  if (options_.kind == SystemKind::kDuffing) {
    const double n2 = dx.squaredNorm();
    if (n2 > 0.0) {
      const double k3 = options_.cubic_stiffness;
      const double a = mid(0), dq = dx(0), dp = dx(1);
      const double num = 0.25 * k3 * a * dq * dq * dq;  // k3 a dq^3 / 4
      const double phi = num / n2;
      // d num / d dq = k3/4 (dq^3 / 2 + 3 a dq^2); d num / d dp = 0.
      const double dnum_dq = 0.25 * k3 * (0.5 * dq * dq * dq + 3.0 * a * dq * dq);
      Vec2 grad_phi;
      grad_phi(0) = dnum_dq / n2 - num * 2.0 * dq / (n2 * n2);
      grad_phi(1) = -num * 2.0 * dp / (n2 * n2);
      jac += phi * Mat2::Identity() + dx * grad_phi.transpose();
    }
  }
  return jac;
}

Vec2 Oscillator::average_vector_field_gradient(const Vec2& x,
                                               const Vec2& dx) const {
  const Vec2 mid = x + 0.5 * dx;
  Vec2 g = grad_hamiltonian(mid);
  if (options_.kind == SystemKind::kDuffing) {
    // int_0^1 k3 (a + (s - 1/2) dq)^3 ds = k3 (a^3 + a dq^2 / 4).
    g(0) += 0.25 * options_.cubic_stiffness * mid(0) * dx(0) * dx(0);
  }
  return g;
}

Mat2 Oscillator::average_vector_field_jacobian(const Vec2& x,
                                               const Vec2& dx) const {
  Mat2 jac = 0.5 * hessian(x + 0.5 * dx);
  if (options_.kind == SystemKind::kDuffing) {
    // d/d dq of k3 a dq^2 / 4 with a = q + dq/2: k3 (dq^2 / 8 + a dq / 2).
    const double a = x(0) + 0.5 * dx(0), dq = dx(0);
    jac(0, 0) += options_.cubic_stiffness * (dq * dq / 8.0 + 0.5 * a * dq);
  }
  return jac;
}

std::array<double, 2> Oscillator::self_oscillation_interval() const {
  PHNN_REQUIRE(options_.kind == SystemKind::kSelfSustained,
               "self_oscillation_interval: only defined for the "
               "self-sustained oscillator, got "
                   << to_string(options_.kind));
  return phnn::self_oscillation_interval(options_.z_coefficients);
}

Vec2 Oscillator::equilibrium(double u) const {
  if (options_.kind == SystemKind::kSelfSustained) {
    return Vec2(0.0, options_.mass * dissipation(-u));
  }
  const double k = options_.stiffness;
  if (options_.kind == SystemKind::kHarmonic) return Vec2(-u / k, 0.0);
  // k q + k3 q^3 = -u: strictly increasing in q, Newton from the linear guess.
  const double k3 = options_.cubic_stiffness;
  double q = cr::cbrt(-u / k3);
  if (std::abs(-u / k) < std::abs(q)) q = -u / k;
  for (int it = 0; it < 100; ++it) {
    const double r = k * q + k3 * q * q * q + u;
    const double step = r / (k + 3.0 * k3 * q * q);
    q -= step;
    if (std::abs(step) <= 1e-16 * (1.0 + std::abs(q))) break;
  }
  return Vec2(q, 0.0);
}

}  // namespace phnn
