// src/systems/system_file_eval.cpp — FileSystem's evaluations beyond the
// compiled ones (the Hessian, z'', the discrete gradient and its Jacobian,
// the limit cycle) and the checks that evaluate H (file_system.h). Touches
// no file.
#include <cmath>
#include <sstream>

#include "systems/file_system.h"

namespace phnn {
namespace internal {

namespace {
const Eigen::IOFormat kRow(Eigen::StreamPrecision, Eigen::DontAlignCols, ", ", ", ");
}  // namespace

std::array<double, 2> FileSystem::self_oscillation_interval() const {
  if (!has_limit_cycle_) return PhSystem::self_oscillation_interval();
  return limit_cycle_;
}

MatX FileSystem::hessian(const VecX& x) const {
  need_energy();
  set_states(x);
  const double* v = hessian_->eval();
  MatX h(n_x(), n_x());
  for (int i = 0, k = 0; i < n_x(); ++i) {
    for (int j = i; j < n_x(); ++j, ++k) h(i, j) = h(j, i) = v[k];
  }
  return h;
}

VecX FileSystem::dissipation_second(const VecX& w, const VecX& s) const {
  need_energy();
  const int nw = n_w();
  VecX out = VecX::Zero(nw);
  if (nw == 0) return out;
  set_ports(w);
  const double* v = dissipation_second_->eval();
  for (int k = 0, idx = 0; k < nw; ++k) {
    for (int l = 0; l < nw; ++l) {
      for (int m = l; m < nw; ++m, ++idx) out(k) += (l == m ? 1.0 : 2.0) * v[idx] * s(l) * s(m);
    }
  }
  return out;
}

VecX FileSystem::discrete_gradient(const VecX& x, const VecX& dx) const {
  need_energy();
  if (!defect_is_zero_ && !gradient_and_defect_) return PhSystem::discrete_gradient(x, dx);
  const int n = n_x();
  const double n2 = dx.squaredNorm();
  if (defect_is_zero_ || n2 == 0.0) return grad_hamiltonian(x + 0.5 * dx);
  set_midpoint_and_increment(x, dx);
  const double* v = gradient_and_defect_->eval();
  VecX g(n);
  for (int i = 0; i < n; ++i) g(i) = v[i] + (v[n] / n2) * dx(i);
  return g;
}

MatX FileSystem::discrete_gradient_jacobian(const VecX& x, const VecX& dx) const {
  need_energy();
  if (!defect_is_zero_ && !hessian_and_defect_) return PhSystem::discrete_gradient_jacobian(x, dx);
  const double n2 = dx.squaredNorm();
  if (defect_is_zero_ || n2 == 0.0) return 0.5 * hessian(x + 0.5 * dx);
  const int n = n_x();
  set_midpoint_and_increment(x, dx);
  const double* v = hessian_and_defect_->eval();
  const int m = n * (n + 1) / 2;
  const double D = v[m];
  MatX jac(n, n);
  for (int i = 0, k = 0; i < n; ++i) {
    for (int j = i; j < n; ++j, ++k) jac(i, j) = jac(j, i) = 0.5 * v[k];
  }
  // + (D/n2) I + dx (dD/n2 - 2 D dx / n2^2)^T
  for (int i = 0; i < n; ++i) {
    jac(i, i) += D / n2;
    for (int j = 0; j < n; ++j) {
      jac(i, j) += dx(i) * (v[m + 1 + j] / n2 - 2.0 * D * dx(j) / (n2 * n2));
    }
  }
  return jac;
}

// Largest s with H(s e) <= e_max along direction e (bisection after
// doubling); < 0 when H stays below e_max up to |s| = 1e6.
double axis_bound(const PhSystem& sys, const VecX& e, double e_max) {
  double hi = 1e-3;
  while (!(sys.hamiltonian(hi * e) > e_max)) {
    hi *= 2.0;
    if (hi > 1e6) return -1.0;
  }
  double lo = 0.0;
  for (int it = 0; it < 200 && lo < hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (sys.hamiltonian(mid * e) > e_max ? hi : lo) = mid;
  }
  return lo;
}

void FileSystem::check_energy_and_box() {
  InitialConditionDesign& d = def_.initial;
  const int nx = n_x();
  check_energy_at({VecX::Zero(nx)});
  if (d.method == InitialConditionDesign::Method::kEnergy && d.box.empty()) {
    for (int i = 0; i < nx; ++i) {
      VecX e = VecX::Zero(nx);
      e(i) = 1.0;
      const double b = std::max(axis_bound(*this, e, d.energy_max), axis_bound(*this, -e, d.energy_max));
      if (!(b > 0.0)) {
        throw SystemFileError(def_.file, def_.line_of("initial"),
                              "cannot bound state \"" + def_.states[static_cast<std::size_t>(i)] +
                                  "\" for initial.method = \"energy\": H along it stays below "
                                  "energy_max = " + std::to_string(d.energy_max) +
                                  " (or is not finite); give initial.box = [[lo, hi], ...]");
      }
      d.box.push_back({-b, b});
    }
  }
  if (d.method == InitialConditionDesign::Method::kAlgorithm1) {
    const MatX h0 = hessian(VecX::Zero(nx));
    if (!(h0(0, 0) > 0.0 && h0(1, 1) > 0.0 && std::isfinite(h0(0, 0)) && std::isfinite(h0(1, 1)))) {
      throw SystemFileError(def_.file, def_.line_of("initial"),
                            "initial.method = \"algorithm1\" needs d2H/dq2 > 0 and d2H/dp2 > 0 at "
                            "x = 0 (an ellipse around the origin); use \"energy\" or \"box\"");
    }
  }
  // H at the box's (up to 2^10) corners.
  std::vector<VecX> points;
  if (!d.box.empty()) {
    const int corners = nx <= 10 ? 1 << nx : 0;
    for (int c = 0; c < corners; ++c) {
      VecX p(nx);
      for (int i = 0; i < nx; ++i) p(i) = d.box[static_cast<std::size_t>(i)][(c >> i) & 1];
      points.push_back(p);
    }
  }
  check_energy_at(points);
}

void FileSystem::check_energy_at(const std::vector<VecX>& points) const {
  for (const VecX& p : points) {
    const double h = hamiltonian(p);
    if (!std::isfinite(h) || h < 0.0) {
      std::ostringstream os;
      os << "H = " << h << " at x = (" << p.transpose().format(kRow) << ")" << (std::isfinite(h) ? " is negative" : " is not finite");
      if (std::isfinite(h)) {
        os << negative_energy_advice(*this, def_.initial.box, h);
      } else {
        os << "; an energy must be finite wherever initial states are drawn: fix H or shrink initial.box";
      }
      throw SystemFileError(def_.file, def_.line_of("H"), os.str());
    }
  }
}

}  // namespace internal
}  // namespace phnn
