// src/models/dg4_correction.cpp — DG4's field from the order-2 jet of phi
// and its backward (dg4_jet_heads.h; docs/METHOD.md "DG4: a fourth-order
// discrete gradient"), row by row in one fixed order, no autograd node. The
// reference is port_hamiltonian.cpp's discrete_gradient4_field. Private to
// src/models.
#include <vector>

#include "models/dg4_jet_heads.h"
#include "models/fused_heads_common.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {

using heads::dense;
using heads::rows_of;

namespace {

FieldJet2 dense_jet(const torch::Tensor& v, const torch::Tensor& g, const torch::Tensor& h) {
  return {dense(v), dense(g), dense(h)};
}

}  // namespace

// Per row (n = d, A_ia = g[a][i], t = h^2 f4~):
//   Av = A v,  AAv = A Av,  q_i = sum_a sum_b h[a][b][i] (v_a v_b),
//   f4 = v + h^2 (q / 24 - AAv / 12).
// Backward: q~ = t / 24, AAv~ = -(t / 12),
//   h~[a][b][i] = q~_i (v_a v_b),  v~_a = f4~_a + sum_b sum_i q~_i (h[a][b][i] + h[b][a][i]) v_b,
//   g~[a][i] = AAv~_i Av_a,  Av~_a = sum_i g[a][i] AAv~_i,
//   g~[a][i] += Av~_i v_a,  v~_a += sum_i g[a][i] Av~_i.
torch::Tensor dg4_correction_forward(const FieldJet2& phi_in, double h) {
  const FieldJet2 phi = dense_jet(phi_in.f, phi_in.g, phi_in.h);
  const int n = static_cast<int>(phi.f.size(-1)), d = static_cast<int>(phi.g.size(-2));
  PHNN_CHECK(d == n, "dg4_correction_forward: expected n_x directions, got " << d);
  const int64_t rows = rows_of(phi.f);
  torch::Tensor out = torch::empty_like(phi.f);
  const double *pv = phi.f.data_ptr<double>(), *pg = phi.g.data_ptr<double>();
  const double* ph = phi.h.data_ptr<double>();
  double* po = out.data_ptr<double>();
  std::vector<double> av(n);
  const double h2 = h * h;
  for (int64_t r = 0; r < rows; ++r) {
    const double *v = pv + n * r, *g = pg + n * n * r, *hh = ph + n * n * n * r;
    for (int i = 0; i < n; ++i) {
      double s = 0.0;
      for (int a = 0; a < n; ++a) s += g[a * n + i] * v[a];
      av[i] = s;
    }
    for (int i = 0; i < n; ++i) {
      double aav = 0.0, q = 0.0;
      for (int a = 0; a < n; ++a) aav += g[a * n + i] * av[a];
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) q += hh[(a * n + b) * n + i] * (v[a] * v[b]);
      po[n * r + i] = v[i] + h2 * (q / 24.0 - aav / 12.0);
    }
  }
  return out;
}

FieldJet2 dg4_correction_backward(const FieldJet2& phi_in, double h, const torch::Tensor& f4_bar) {
  const FieldJet2 phi = dense_jet(phi_in.f, phi_in.g, phi_in.h);
  const torch::Tensor fb = dense(f4_bar);
  const int n = static_cast<int>(phi.f.size(-1));
  const int64_t rows = rows_of(phi.f);
  FieldJet2 out{torch::empty_like(phi.f), torch::empty_like(phi.g), torch::empty_like(phi.h)};
  const double *pv = phi.f.data_ptr<double>(), *pg = phi.g.data_ptr<double>();
  const double *ph = phi.h.data_ptr<double>(), *pfb = fb.data_ptr<double>();
  std::vector<double> av(n), qb(n), aavb(n), avb(n);
  const double h2 = h * h;
  for (int64_t r = 0; r < rows; ++r) {
    const double *v = pv + n * r, *g = pg + n * n * r, *hh = ph + n * n * n * r, *f = pfb + n * r;
    double *vb = out.f.data_ptr<double>() + n * r, *gb = out.g.data_ptr<double>() + n * n * r;
    double* hb = out.h.data_ptr<double>() + n * n * n * r;
    for (int i = 0; i < n; ++i) {
      double s = 0.0;
      for (int a = 0; a < n; ++a) s += g[a * n + i] * v[a];
      av[i] = s;
      const double t = h2 * f[i];
      qb[i] = t / 24.0;
      aavb[i] = -(t / 12.0);
    }
    for (int a = 0; a < n; ++a) {
      double s = 0.0, sv = f[a];
      for (int i = 0; i < n; ++i) s += g[a * n + i] * aavb[i];
      avb[a] = s;
      for (int b = 0; b < n; ++b) {
        for (int i = 0; i < n; ++i) {
          hb[(a * n + b) * n + i] = qb[i] * (v[a] * v[b]);
          sv += qb[i] * (hh[(a * n + b) * n + i] + hh[(b * n + a) * n + i]) * v[b];
        }
      }
      vb[a] = sv;
    }
    for (int a = 0; a < n; ++a) {
      double s = 0.0;
      for (int i = 0; i < n; ++i) {
        gb[a * n + i] = aavb[i] * av[a] + avb[i] * v[a];
        s += g[a * n + i] * avb[i];
      }
      vb[a] += s;
    }
  }
  return out;
}

}  // namespace internal
}  // namespace phnn
