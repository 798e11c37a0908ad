// src/models/general_curvature_head.cpp — the curvature of the n-state
// H_theta for the hand-written regularized steps (general_jet_heads.h): gradH
// and the Hessian from L_H's order-2 jet, forward and written-out backward,
// row by row, no autograd node. Private to src/models; the op-by-op
// general_hamiltonian_jet (general_ph.cpp) is the reference.
#include <algorithm>
#include <vector>

#include "models/fused_heads_common.h"
#include "models/general_jet_heads.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {
namespace {

using namespace heads;

// ------------------------------------------------------------- curvature
// Per row, for entry k = (r, c) of L (row-major lower triangle) with value
// l_k and its x-derivatives (directions i, j):
//   off the diagonal:  l = o_k,  l_i = og_ik,  l_ij = oh_ijk;
//   on it (s = sigmoid(o_k), s' = s (1 - s)):
//     l = softplus(o_k),  l_i = s og_ik,  l_ij = s' og_ik og_jk + s oh_ijk.
//   v_r = sum_{c<=r} l_rc x_c
//   v_ri = sum_{c<=r} l_rc,i x_c + [i<=r] l_ri
//   v_rij = sum_{c<=r} l_rc,ij x_c + [j<=r] l_rj,i + [i<=r] l_ri,j
//   G_i = sum_r v_r v_ri,   K_ij = sum_r (v_ri v_rj + v_r v_rij).
// Backward with G~, K~:
//   v~_r = sum_i G~_i v_ri + sum_ij K~_ij v_rij,
//   v~_ri = G~_i v_r + sum_j (K~_ij + K~_ji) v_rj,   v~_rij = K~_ij v_r,
// then each line of v read backwards into l~ and x~, and l~ into o~, og~,
// oh~ (on the diagonal: o~ = l~ softplus' + s~ s' + s'~ s' (1 - 2 s), with
// s~ = sum_i l~_i og_ik + sum_ij l~_ij oh_ijk, s'~ = sum_ij l~_ij og_ik og_jk).
struct CurvatureRow {
  int n, K;
  std::vector<double> l, li, lij, v, vi, vij;  // [K], [n][K], [n][n][K], [n], [n][n], [n][n][n]
  std::vector<double> lb, lib, lijb;           // the backward's adjoints of l, li, lij

  CurvatureRow(int states, int outputs)
      : n(states),
        K(outputs),
        l(K),
        li(n * K),
        lij(n * n * K),
        v(n),
        vi(n * n),
        vij(n * n * n),
        lb(K),
        lib(n * K),
        lijb(n * n * K) {}

  // The L entries' jet of one row (aux: softplus, sigmoid, softplus' per diagonal entry).
  void entries(const double* o, const double* og, const double* oh, const double* aux) {
    for (int k = 0; k < K; ++k) {
      l[k] = o[k];
      for (int i = 0; i < n; ++i) {
        li[i * K + k] = og[i * K + k];
        for (int j = 0; j < n; ++j) lij[(i * n + j) * K + k] = oh[(i * n + j) * K + k];
      }
    }
    for (int r = 0; r < n; ++r) {
      const int k = tri(r, r);
      const double s = aux[3 * r + 1], s1 = s * (1.0 - s);
      l[k] = aux[3 * r];
      for (int i = 0; i < n; ++i) {
        li[i * K + k] = s * og[i * K + k];
        for (int j = 0; j < n; ++j) {
          lij[(i * n + j) * K + k] =
              s1 * og[i * K + k] * og[j * K + k] + s * oh[(i * n + j) * K + k];
        }
      }
    }
  }

  // v, v_i, v_ij from the entries and x.
  void forward(const double* x) {
    for (int r = 0; r < n; ++r) {
      double s = 0.0;
      for (int c = 0; c <= r; ++c) s += l[tri(r, c)] * x[c];
      v[r] = s;
      for (int i = 0; i < n; ++i) {
        double t = i <= r ? l[tri(r, i)] : 0.0;
        for (int c = 0; c <= r; ++c) t += li[i * K + tri(r, c)] * x[c];
        vi[r * n + i] = t;
        for (int j = 0; j < n; ++j) {
          double u = 0.0;
          if (j <= r) u += li[i * K + tri(r, j)];
          if (i <= r) u += li[j * K + tri(r, i)];
          for (int c = 0; c <= r; ++c) u += lij[(i * n + j) * K + tri(r, c)] * x[c];
          vij[(r * n + i) * n + j] = u;
        }
      }
    }
  }
  double grad(int i) const {
    double s = 0.0;
    for (int r = 0; r < n; ++r) s += v[r] * vi[r * n + i];
    return s;
  }
  double hessian(int i, int j) const {
    double s = 0.0;
    for (int r = 0; r < n; ++r)
      s += vi[r * n + i] * vi[r * n + j] + v[r] * vij[(r * n + i) * n + j];
    return s;
  }
};

// The adjoints of one row (file comment): from G~ (gb [n]) and K~ (kb [n][n])
// into ob [K], ogb [n][K], ohb [n][n][K], xb [n].
void curvature_row_backward(CurvatureRow& w, const double* og, const double* oh, const double* aux,
                            const double* x, const double* gb, const double* kb, double* ob,
                            double* ogb, double* ohb, double* xb) {
  const int n = w.n, K = w.K;
  std::vector<double>&lb = w.lb, &lib = w.lib, &lijb = w.lijb;
  std::fill(lb.begin(), lb.end(), 0.0);
  std::fill(lib.begin(), lib.end(), 0.0);
  std::fill(lijb.begin(), lijb.end(), 0.0);
  std::fill(xb, xb + n, 0.0);
  for (int r = 0; r < n; ++r) {
    double vb = 0.0;
    for (int i = 0; i < n; ++i) {
      vb += gb[i] * w.vi[r * n + i];
      for (int j = 0; j < n; ++j) vb += kb[i * n + j] * w.vij[(r * n + i) * n + j];
    }
    for (int i = 0; i < n; ++i) {
      double vib = gb[i] * w.v[r];
      for (int j = 0; j < n; ++j) vib += (kb[i * n + j] + kb[j * n + i]) * w.vi[r * n + j];
      for (int j = 0; j < n; ++j) {  // v_rij
        const double vijb = kb[i * n + j] * w.v[r];
        if (j <= r) lib[i * K + tri(r, j)] += vijb;
        if (i <= r) lib[j * K + tri(r, i)] += vijb;
        for (int c = 0; c <= r; ++c) {
          lijb[(i * n + j) * K + tri(r, c)] += vijb * x[c];
          xb[c] += vijb * w.lij[(i * n + j) * K + tri(r, c)];
        }
      }
      if (i <= r) lb[tri(r, i)] += vib;  // v_ri
      for (int c = 0; c <= r; ++c) {
        lib[i * K + tri(r, c)] += vib * x[c];
        xb[c] += vib * w.li[i * K + tri(r, c)];
      }
    }
    for (int c = 0; c <= r; ++c) {  // v_r
      lb[tri(r, c)] += vb * x[c];
      xb[c] += vb * w.l[tri(r, c)];
    }
  }
  for (int k = 0; k < K; ++k) {
    ob[k] = lb[k];
    for (int i = 0; i < n; ++i) {
      ogb[i * K + k] = lib[i * K + k];
      for (int j = 0; j < n; ++j) ohb[(i * n + j) * K + k] = lijb[(i * n + j) * K + k];
    }
  }
  for (int r = 0; r < n; ++r) {  // the diagonal through softplus and sigmoid
    const int k = tri(r, r);
    const double s = aux[3 * r + 1], s1 = s * (1.0 - s);
    double sb = 0.0, s1b = 0.0;
    for (int i = 0; i < n; ++i) {
      sb += lib[i * K + k] * og[i * K + k];
      ogb[i * K + k] = lib[i * K + k] * s;
    }
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const double b = lijb[(i * n + j) * K + k];
        s1b += b * og[i * K + k] * og[j * K + k];
        ogb[i * K + k] += b * s1 * og[j * K + k];
        ogb[j * K + k] += b * s1 * og[i * K + k];
        sb += b * oh[(i * n + j) * K + k];
        ohb[(i * n + j) * K + k] = b * s;
      }
    }
    ob[k] = lb[k] * aux[3 * r + 2] + sb * s1 + s1b * s1 * (1.0 - 2.0 * s);
  }
}

}  // namespace

HamiltonianCurvature general_curvature_forward(const Tensor& o_in, const Tensor& og_in,
                                               const Tensor& oh_in, const Tensor& x_in,
                                               CurvatureTape* tape) {
  const Tensor o = dense(o_in), og = dense(og_in), oh = dense(oh_in), x = dense(x_in);
  const int n = static_cast<int>(x.size(-1)), K = static_cast<int>(o.size(-1));
  PHNN_CHECK(K == n * (n + 1) / 2 && og.size(-2) == n && oh.size(-2) == n,
             "general_curvature_forward: " << K << " outputs, " << og.size(-2) << " directions for "
                                           << n << " states");
  const int64_t E = o.size(0), B = o.size(1), rows = E * B;
  Tensor grad = torch::empty({E, B, n}, o.options()),
         hess = torch::empty({E, B, n, n}, o.options());
  Tensor aux = torch::empty({rows, 3 * n}, o.options());
  const double *po = o.data_ptr<double>(), *pg = og.data_ptr<double>();
  const double *ph = oh.data_ptr<double>(), *px = x.data_ptr<double>();
  double *pgr = grad.data_ptr<double>(), *phs = hess.data_ptr<double>();
  double* pa = aux.data_ptr<double>();
  std::vector<int> diagonal(n);
  for (int i = 0; i < n; ++i) diagonal[i] = tri(i, i);
  std::vector<double> columns(static_cast<std::size_t>(SoftplusColumns::size(n, rows)));
  const SoftplusColumns f = SoftplusColumns::compute(po, K, diagonal, rows, columns.data());
  CurvatureRow row(n, K);
  for (int64_t r = 0; r < rows; ++r) {
    double* a = pa + 3 * n * r;
    for (int i = 0; i < n; ++i)
      a[3 * i] = f.softplus(i, r), a[3 * i + 1] = f.sigmoid(i, r), a[3 * i + 2] = f.slope(i, r);
    row.entries(po + K * r, pg + n * K * r, ph + n * n * K * r, a);
    row.forward(px + n * r);
    for (int i = 0; i < n; ++i) {
      pgr[n * r + i] = row.grad(i);
      for (int j = 0; j < n; ++j) phs[n * n * r + n * i + j] = row.hessian(i, j);
    }
  }
  *tape = CurvatureTape{o, og, oh, x, aux};
  return {grad, hess};
}

CurvatureAdjoints general_curvature_backward(const CurvatureTape& tape, const Tensor& grad_bar,
                                             const Tensor& hessian_bar) {
  const Tensor &o = tape.o, &og = tape.o_g, &oh = tape.o_h, &x = tape.x;
  const int n = static_cast<int>(x.size(-1)), K = static_cast<int>(o.size(-1));
  const int64_t E = o.size(0), B = o.size(1), rows = E * B;
  const Tensor gb = grad_bar.defined() ? dense(grad_bar) : torch::zeros_like(x);
  const Tensor kb =
      hessian_bar.defined() ? dense(hessian_bar) : torch::zeros({E, B, n, n}, o.options());
  CurvatureAdjoints out{torch::empty_like(o), torch::empty_like(og), torch::empty_like(oh),
                        torch::empty_like(x)};
  const double *po = o.data_ptr<double>(), *pg = og.data_ptr<double>();
  const double *ph = oh.data_ptr<double>(), *px = x.data_ptr<double>();
  const double *pgb = gb.data_ptr<double>(), *pkb = kb.data_ptr<double>();
  const double* pa = tape.aux.data_ptr<double>();
  double *pob = out.o.data_ptr<double>(), *pogb = out.o_g.data_ptr<double>();
  double *pohb = out.o_h.data_ptr<double>(), *pxb = out.x.data_ptr<double>();
  CurvatureRow row(n, K);
  for (int64_t r = 0; r < rows; ++r) {
    const double *a = pa + 3 * n * r, *ogr = pg + n * K * r, *ohr = ph + n * n * K * r;
    row.entries(po + K * r, ogr, ohr, a);
    row.forward(px + n * r);
    curvature_row_backward(row, ogr, ohr, a, px + n * r, pgb + n * r, pkb + n * n * r, pob + K * r,
                           pogb + n * K * r, pohb + n * n * K * r, pxb + n * r);
  }
  return out;
}

}  // namespace internal
}  // namespace phnn
