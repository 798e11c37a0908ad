// src/models/general_jet_heads.cpp — the order-1 jets of the n-state PH
// fields for the hand-written regularized steps (general_jet_heads.h): the
// PHNN-JR field jet and the PHNN-S field jet around L_z's input-jet call
// (the curvature of H: general_curvature_head.cpp). Plain loops per row (a
// row = one member and one batch element), no autograd node; the backward
// formulas are written above each function. Private to src/models; the
// op-by-op jets of general_ph.cpp are the reference.
// Size: the two fields' jets and backwards share the per-row accessors.
#include "models/general_jet_heads.h"

#include <algorithm>
#include <vector>

#include "models/fused_heads_common.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {

using namespace heads;

// ---------------------------------------------------------- PHNN-JR jet
// Per row, p = [e; u] (m = n_x + n_u), p_d = [e_d; 0], L = L_R (o), L_d (o_g[d]):
//   y = L p,  y_d = L_d p + L p_d,
//   f = [J p - L^T y]_{1:n_x},  f_d = [J p_d - L_d^T y - L^T y_d]_{1:n_x}.
// Backward with f~, f~_d (zero beyond n_x), r~ = -f~, r~_d = -f~_d:
//   p~ = J^T f~,  p~_d = J^T f~_d,
//   L~ += y r~^T (as (L^T y)_c = sum_r L_rc y_r: L~_rc += r~_c y_r),  y~ = L r~,
//   L_d~ += y r~_d^T,  y~ += L_d r~_d,  L~ += y_d r~_d^T,  y~_d = L r~_d,
//   L_d~ += y~_d p^T,  p~ += L_d^T y~_d,  L~ += y~_d p_d^T,  p~_d += L^T y~_d,
//   L~ += y~ p^T,  p~ += L^T y~.
namespace {

struct JrJetRow {
  int nx, nu, m, K, d;
  std::vector<double> p, pd, y, yd;  // [m], [d][m], [m], [d][m]
  JrJetRow(int states, int inputs, int directions)
      : nx(states),
        nu(inputs),
        m(states + inputs),
        K(m * (m + 1) / 2),
        d(directions),
        p(m),
        pd(d * m, 0.0),
        y(m),
        yd(d * m) {}
  void forward(const double* e, const double* eg, const double* u, const double* o,
               const double* og) {
    for (int j = 0; j < nx; ++j) p[j] = e[j];
    for (int b = 0; b < nu; ++b) p[nx + b] = u[b];
    for (int a = 0; a < d; ++a)
      for (int j = 0; j < nx; ++j) pd[a * m + j] = eg[a * nx + j];
    for (int r = 0; r < m; ++r) {
      double s = 0.0;
      for (int c = 0; c <= r; ++c) s += o[tri(r, c)] * p[c];
      y[r] = s;
      for (int a = 0; a < d; ++a) {
        double t = 0.0;
        for (int c = 0; c <= r; ++c)
          t += og[a * K + tri(r, c)] * p[c] + o[tri(r, c)] * pd[a * m + c];
        yd[a * m + r] = t;
      }
    }
  }
  // y~ = L r~ + sum_d L_d r~_d, y~_d = L r~_d, and the adjoints of L (ob)
  // and of each L_d (ogb) from r~, r~_d, y~, y~_d (file comment).
  void lower_adjoints(const double* L, const double* Lg, const double* rb, const double* rdb,
                      double* yb, double* ydb, double* ob, double* ogb) const {
    for (int q = 0; q < m; ++q) {  // y~ = L r~ + sum_a L_a r~_a, y~_a = L r~_a
      double s = 0.0;
      for (int c = 0; c <= q; ++c) s += L[tri(q, c)] * rb[c];
      for (int a = 0; a < d; ++a) {
        double t = 0.0;
        for (int c = 0; c <= q; ++c) {
          s += Lg[a * K + tri(q, c)] * rdb[a * m + c];
          t += L[tri(q, c)] * rdb[a * m + c];
        }
        ydb[a * m + q] = t;
      }
      yb[q] = s;
    }
    for (int q = 0; q < m; ++q) {
      for (int c = 0; c <= q; ++c) {
        const int k = tri(q, c);
        double lb = rb[c] * y[q] + yb[q] * p[c];
        for (int a = 0; a < d; ++a) {
          lb += rdb[a * m + c] * yd[a * m + q] + ydb[a * m + q] * pd[a * m + c];
          ogb[a * K + k] = rdb[a * m + c] * y[q] + ydb[a * m + q] * p[c];
        }
        ob[k] = lb;
      }
    }
  }
};

}  // namespace

JrFieldJet general_jr_field_jet_forward(const Tensor& e_in, const Tensor& eg_in, const Tensor& o_in,
                                        const Tensor& og_in, const Tensor& u_in,
                                        const std::vector<double>& J) {
  const Tensor e = dense(e_in), eg = dense(eg_in), o = dense(o_in), og = dense(og_in);
  const Tensor u = rows_like(u_in, e_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1)), m = nx + nu;
  const int d = static_cast<int>(eg.size(-2)), K = m * (m + 1) / 2;
  PHNN_CHECK(static_cast<int>(J.size()) == m * m && o.size(-1) == K && og.size(-2) == d,
             "general_jr_field_jet_forward: structure or output sizes");
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  JrFieldJet out{torch::empty_like(e), torch::empty({E, B, d, nx}, e.options())};
  const double *pe = e.data_ptr<double>(), *peg = eg.data_ptr<double>();
  const double *po = o.data_ptr<double>(), *pog = og.data_ptr<double>(), *pu = u.data_ptr<double>();
  double *pf = out.f.data_ptr<double>(), *pfg = out.g.data_ptr<double>();
  JrJetRow row(nx, nu, d);
  for (int64_t r = 0; r < rows; ++r) {
    const double* L = po + K * r;
    row.forward(pe + nx * r, peg + d * nx * r, pu + nu * r, L, pog + d * K * r);
    for (int i = 0; i < nx; ++i) {
      double s = 0.0, lty = 0.0;
      for (int j = 0; j < m; ++j) s += J[i * m + j] * row.p[j];
      for (int q = i; q < m; ++q) lty += L[tri(q, i)] * row.y[q];
      pf[nx * r + i] = s - lty;
      for (int a = 0; a < d; ++a) {
        const double* Ld = pog + d * K * r + a * K;
        double sd = 0.0, t = 0.0;
        for (int j = 0; j < m; ++j) sd += J[i * m + j] * row.pd[a * m + j];
        for (int q = i; q < m; ++q)
          t += Ld[tri(q, i)] * row.y[q] + L[tri(q, i)] * row.yd[a * m + q];
        pfg[(d * r + a) * nx + i] = sd - t;
      }
    }
  }
  return out;
}

JrFieldJetAdjoints general_jr_field_jet_backward(const Tensor& e_in, const Tensor& eg_in,
                                                 const Tensor& o_in, const Tensor& og_in,
                                                 const Tensor& u_in, const std::vector<double>& J,
                                                 const Tensor& f_bar, const Tensor& g_bar) {
  const Tensor e = dense(e_in), eg = dense(eg_in), o = dense(o_in), og = dense(og_in);
  const Tensor u = rows_like(u_in, e_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1)), m = nx + nu;
  const int d = static_cast<int>(eg.size(-2)), K = m * (m + 1) / 2;
  const int64_t rows = e.size(0) * e.size(1);
  const Tensor fb = f_bar.defined() ? dense(f_bar) : torch::zeros_like(e);
  const Tensor gb = g_bar.defined() ? dense(g_bar) : torch::zeros_like(eg);
  JrFieldJetAdjoints out{torch::empty_like(e), torch::empty_like(eg), torch::empty_like(o),
                         torch::empty_like(og), torch::empty_like(u)};
  const double *pe = e.data_ptr<double>(), *peg = eg.data_ptr<double>();
  const double *po = o.data_ptr<double>(), *pog = og.data_ptr<double>(), *pu = u.data_ptr<double>();
  const double *pfb = fb.data_ptr<double>(), *pgb = gb.data_ptr<double>();
  double *peb = out.effort.data_ptr<double>(), *pegb = out.effort_g.data_ptr<double>();
  double *pob = out.o.data_ptr<double>(), *pogb = out.o_g.data_ptr<double>();
  double* pub = out.u.data_ptr<double>();
  JrJetRow row(nx, nu, d);
  std::vector<double> rb(m, 0.0), rdb(d * m, 0.0), yb(m), ydb(d * m), pb(m), pdb(d * m);
  for (int64_t r = 0; r < rows; ++r) {
    const double *L = po + K * r, *Lg = pog + d * K * r;
    row.forward(pe + nx * r, peg + d * nx * r, pu + nu * r, L, Lg);
    const double *f = pfb + nx * r, *g = pgb + d * nx * r;
    for (int j = 0; j < nx; ++j) rb[j] = -f[j];
    for (int a = 0; a < d; ++a)
      for (int j = 0; j < nx; ++j) rdb[a * m + j] = -g[a * nx + j];
    for (int j = 0; j < m; ++j) {  // p~ = J^T f~, p~_d = J^T f~_d
      double s = 0.0;
      for (int i = 0; i < nx; ++i) s += f[i] * J[i * m + j];
      pb[j] = s;
      for (int a = 0; a < d; ++a) {
        double t = 0.0;
        for (int i = 0; i < nx; ++i) t += g[a * nx + i] * J[i * m + j];
        pdb[a * m + j] = t;
      }
    }
    row.lower_adjoints(L, Lg, rb.data(), rdb.data(), yb.data(), ydb.data(), pob + K * r,
                       pogb + d * K * r);
    for (int c = 0; c < m; ++c) {  // p~ += L^T y~ + L_a^T y~_a,  p~_a += L^T y~_a
      double s = 0.0;
      for (int q = c; q < m; ++q) {
        s += L[tri(q, c)] * yb[q];
        for (int a = 0; a < d; ++a) s += Lg[a * K + tri(q, c)] * ydb[a * m + q];
      }
      pb[c] += s;
      for (int a = 0; a < d; ++a) {
        double t = 0.0;
        for (int q = c; q < m; ++q) t += L[tri(q, c)] * ydb[a * m + q];
        pdb[a * m + c] += t;
      }
    }
    for (int j = 0; j < nx; ++j) peb[nx * r + j] = pb[j];
    for (int b = 0; b < nu; ++b) pub[nu * r + b] = pb[nx + b];
    for (int a = 0; a < d; ++a)
      for (int j = 0; j < nx; ++j) pegb[(d * r + a) * nx + j] = pdb[a * m + j];
  }
  return out;
}

// -------------------------------------------------------------- PHNN-S jet
// The ports: w = M [e; u], w_d = M_x e_d (M = [S_wx S_wu], n_w rows).
PortJet general_port_jet(const Tensor& e_in, const Tensor& eg_in, const Tensor& u_in,
                         const std::vector<double>& M, int nw) {
  const Tensor e = dense(e_in), eg = dense(eg_in), u = rows_like(u_in, e_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1)), W = nx + nu;
  const int d = static_cast<int>(eg.size(-2));
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  PortJet out{torch::empty({E, B, nw}, e.options()), torch::empty({E, B, d, nw}, e.options())};
  const double *pe = e.data_ptr<double>(), *peg = eg.data_ptr<double>(), *pu = u.data_ptr<double>();
  double *pw = out.w.data_ptr<double>(), *pwg = out.w_g.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    for (int k = 0; k < nw; ++k) {
      const double* m = M.data() + k * W;
      double s = 0.0;
      for (int j = 0; j < nx; ++j) s += m[j] * pe[nx * r + j];
      for (int b = 0; b < nu; ++b) s += m[nx + b] * pu[nu * r + b];
      pw[nw * r + k] = s;
      for (int a = 0; a < d; ++a) {
        double t = 0.0;
        for (int j = 0; j < nx; ++j) t += m[j] * peg[(d * r + a) * nx + j];
        pwg[(d * r + a) * nw + k] = t;
      }
    }
  }
  return out;
}

// e~ = M_x^T w~,  e~_d = M_x^T w~_d.
EffortJetAdjoints general_port_jet_backward(const Tensor& w_bar, const Tensor& wg_bar,
                                            const std::vector<double>& M, int nx, int nu) {
  const Tensor wb = dense(w_bar), wgb = dense(wg_bar);
  const int nw = static_cast<int>(wb.size(-1)), d = static_cast<int>(wgb.size(-2)), W = nx + nu;
  const int64_t E = wb.size(0), B = wb.size(1), rows = E * B;
  EffortJetAdjoints out{torch::empty({E, B, nx}, wb.options()),
                        torch::empty({E, B, d, nx}, wb.options())};
  const double *pwb = wb.data_ptr<double>(), *pwgb = wgb.data_ptr<double>();
  double *peb = out.e.data_ptr<double>(), *pegb = out.e_g.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    for (int j = 0; j < nx; ++j) {
      double s = 0.0;
      for (int k = 0; k < nw; ++k) s += pwb[nw * r + k] * M[k * W + j];
      peb[nx * r + j] = s;
      for (int a = 0; a < d; ++a) {
        double t = 0.0;
        for (int k = 0; k < nw; ++k) t += pwgb[(d * r + a) * nw + k] * M[k * W + j];
        pegb[(d * r + a) * nx + j] = t;
      }
    }
  }
  return out;
}

// Per row, L = L_z (the first n_w (n_w + 1) / 2 outputs), K strictly lower
// (the rest), A = K - K^T, and their tangents L_d, A_d from o_g[d]:
//   y = L w,  y_d = L_d w + L w_d,
//   z = L^T y + A w,  z_d = L_d^T y + L^T y_d + A_d w + A w_d,
//   f = S_x [e; z; u],  f_d = S_x [e_d; z_d; 0].
// Backward with f~, f~_d: [e~; z~; .] = S_x^T f~, [e~_d; z~_d; .] = S_x^T f~_d,
//   L~ += y z~^T,  y~ = L z~,  A~ += z~ w^T,  w~ = A^T z~,
//   L_d~ += y z~_d^T,  y~ += L_d z~_d,  L~ += y_d z~_d^T,  y~_d = L z~_d,
//   A_d~ += z~_d w^T,  w~ += A_d^T z~_d,  A~ += z~_d w_d^T,  w~_d = A^T z~_d,
//   L_d~ += y~_d w^T,  w~ += L_d^T y~_d,  L~ += y~_d w_d^T,  w~_d += L^T y~_d,
//   L~ += y~ w^T,  w~ += L^T y~;   K~_ab = A~_ab - A~_ba (a > b).
// (Here "L~ += y z~^T" means L~_qc += z~_c y_q, the adjoint of (L^T y)_c.)
namespace {

struct PortMatrices {
  int n, T;
  // (K - K^T)_ab from outputs o (L's triangle first).
  double skew(const double* o, int a, int b) const { return skew_entry(o, n, a, b); }
  // y = L w (L = the triangle of o).
  void lower(const double* o, const double* w, double* y) const { lower_times(o, w, n, y); }
  // z = L^T y + A w (A from o; accumulated into z).
  void upper_plus_skew(const double* o, const double* y, const double* w, double* z) const {
    for (int c = 0; c < n; ++c) {
      double s = 0.0;
      for (int q = c; q < n; ++q) s += o[tri(q, c)] * y[q];
      for (int b = 0; b < n; ++b) s += skew(o, c, b) * w[b];
      z[c] += s;
    }
  }
  // o~ += the adjoints of L and A for (L^T y + A w) with z~, and of (L w) with y~.
  void adjoint(const double* y, const double* zb, const double* w, const double* yb,
               const double* wl, double* ob) const {
    for (int q = 0; q < n; ++q)
      for (int c = 0; c <= q; ++c) ob[tri(q, c)] += zb[c] * y[q] + yb[q] * wl[c];
    const int base = n * (n + 1) / 2;
    for (int a = 1; a < n; ++a)
      for (int b = 0; b < a; ++b) ob[base + a * (a - 1) / 2 + b] += zb[a] * w[b] - zb[b] * w[a];
  }
  // w~ = L^T y~ + A^T z~ + sum_d (L_d^T y~_d + A_d^T z~_d) into wb [n], and
  // w~_d = L^T y~_d + A^T z~_d into wgb [d][n] (o_g: the d tangents' outputs).
  void port_adjoints(const double* o, const double* o_g, int d, const double* yb, const double* zb,
                     const double* ydb, const double* zdb, double* wb, double* wgb) const {
    for (int c = 0; c < n; ++c) {
      double s = 0.0;
      for (int q = c; q < n; ++q) s += o[tri(q, c)] * yb[q];
      for (int a = 0; a < n; ++a) s += skew(o, a, c) * zb[a];
      for (int b = 0; b < d; ++b) {
        const double* Lb = o_g + b * T;
        double t = 0.0;
        for (int q = c; q < n; ++q) {
          s += Lb[tri(q, c)] * ydb[b * n + q];
          t += o[tri(q, c)] * ydb[b * n + q];
        }
        for (int a = 0; a < n; ++a) {
          s += skew(Lb, a, c) * zdb[b * n + a];
          t += skew(o, a, c) * zdb[b * n + a];
        }
        wgb[b * n + c] = t;
      }
      wb[c] = s;
    }
  }
};

}  // namespace

JrFieldJet general_s_field_jet_forward(const Tensor& e_in, const Tensor& eg_in, const Tensor& u_in,
                                       const Tensor& o_in, const Tensor& og_in, const PortJet& w,
                                       const std::vector<double>& S, int nw) {
  const Tensor e = dense(e_in), eg = dense(eg_in), u = rows_like(u_in, e_in);
  const Tensor o = dense(o_in), og = dense(og_in), wv = dense(w.w), wg = dense(w.w_g);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1));
  const int d = static_cast<int>(eg.size(-2)), T = nw * nw, W = nx + nw + nu;
  PHNN_CHECK(o.size(-1) == T && static_cast<int>(S.size()) >= nx * W,
             "general_s_field_jet_forward: structure or output sizes");
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  JrFieldJet out{torch::empty_like(e), torch::empty({E, B, d, nx}, e.options())};
  const double *pe = e.data_ptr<double>(), *peg = eg.data_ptr<double>(), *pu = u.data_ptr<double>();
  const double *po = o.data_ptr<double>(), *pog = og.data_ptr<double>();
  const double *pw = wv.data_ptr<double>(), *pwg = wg.data_ptr<double>();
  double *pf = out.f.data_ptr<double>(), *pfg = out.g.data_ptr<double>();
  const PortMatrices P{nw, T};
  std::vector<double> y(nw), z(nw), yd(nw), zd(nw), tmp(nw);
  for (int64_t r = 0; r < rows; ++r) {
    const double *L = po + T * r, *wr = pw + nw * r;
    P.lower(L, wr, y.data());
    std::fill(z.begin(), z.end(), 0.0);
    P.upper_plus_skew(L, y.data(), wr, z.data());
    for (int i = 0; i < nx; ++i) {
      const double* s = S.data() + i * W;
      double acc = 0.0;
      for (int j = 0; j < nx; ++j) acc += s[j] * pe[nx * r + j];
      for (int k = 0; k < nw; ++k) acc += s[nx + k] * z[k];
      for (int b = 0; b < nu; ++b) acc += s[nx + nw + b] * pu[nu * r + b];
      pf[nx * r + i] = acc;
    }
    for (int a = 0; a < d; ++a) {
      const double *La = pog + (d * r + a) * T, *wa = pwg + (d * r + a) * nw;
      P.lower(La, wr, yd.data());  // y_d = L_d w + L w_d
      P.lower(L, wa, tmp.data());
      for (int k = 0; k < nw; ++k) yd[k] += tmp[k];
      std::fill(zd.begin(), zd.end(), 0.0);  // z_d = L_d^T y + A_d w + L^T y_d + A w_d
      P.upper_plus_skew(La, y.data(), wr, zd.data());
      P.upper_plus_skew(L, yd.data(), wa, zd.data());
      for (int i = 0; i < nx; ++i) {
        const double* s = S.data() + i * W;
        double acc = 0.0;
        for (int j = 0; j < nx; ++j) acc += s[j] * peg[(d * r + a) * nx + j];
        for (int k = 0; k < nw; ++k) acc += s[nx + k] * zd[k];
        pfg[(d * r + a) * nx + i] = acc;
      }
    }
  }
  return out;
}

SFieldJetAdjoints general_s_field_jet_backward(const Tensor& o_in, const Tensor& og_in,
                                               const PortJet& w, const std::vector<double>& S,
                                               int nx, int nw, int nu, const Tensor& f_bar,
                                               const Tensor& g_bar) {
  const Tensor o = dense(o_in), og = dense(og_in), wv = dense(w.w), wg = dense(w.w_g);
  const int d = static_cast<int>(og.size(-2)), T = nw * nw, W = nx + nw + nu;
  const int64_t E = o.size(0), B = o.size(1), rows = E * B;
  const Tensor fb = f_bar.defined() ? dense(f_bar) : torch::zeros({E, B, nx}, o.options());
  const Tensor gb = g_bar.defined() ? dense(g_bar) : torch::zeros({E, B, d, nx}, o.options());
  SFieldJetAdjoints out{torch::empty({E, B, nx}, o.options()),
                        torch::empty({E, B, d, nx}, o.options()),
                        torch::zeros_like(o),
                        torch::zeros_like(og),
                        torch::empty_like(wv),
                        torch::empty_like(wg)};
  const double *po = o.data_ptr<double>(), *pog = og.data_ptr<double>();
  const double *pw = wv.data_ptr<double>(), *pwg = wg.data_ptr<double>();
  const double *pfb = fb.data_ptr<double>(), *pgb = gb.data_ptr<double>();
  double *peb = out.e.data_ptr<double>(), *pegb = out.e_g.data_ptr<double>();
  double *pob = out.o.data_ptr<double>(), *pogb = out.o_g.data_ptr<double>();
  double *pwb = out.w.data_ptr<double>(), *pwgb = out.w_g.data_ptr<double>();
  const PortMatrices P{nw, T};
  std::vector<double> y(nw), yd(d * nw), zb(nw), zdb(d * nw), yb(nw), ydb(d * nw), tmp(nw);
  for (int64_t r = 0; r < rows; ++r) {
    const double *L = po + T * r, *wr = pw + nw * r;
    P.lower(L, wr, y.data());
    for (int a = 0; a < d; ++a) {
      P.lower(pog + (d * r + a) * T, wr, yd.data() + a * nw);
      P.lower(L, pwg + (d * r + a) * nw, tmp.data());
      for (int k = 0; k < nw; ++k) yd[a * nw + k] += tmp[k];
    }
    const double *f = pfb + nx * r, *g = pgb + d * nx * r;
    for (int j = 0; j < nx + nw; ++j) {  // [e~; z~] = S_x^T f~, likewise for each direction
      double s = 0.0;
      for (int i = 0; i < nx; ++i) s += f[i] * S[i * W + j];
      if (j < nx)
        peb[nx * r + j] = s;
      else
        zb[j - nx] = s;
      for (int a = 0; a < d; ++a) {
        double t = 0.0;
        for (int i = 0; i < nx; ++i) t += g[a * nx + i] * S[i * W + j];
        if (j < nx)
          pegb[(d * r + a) * nx + j] = t;
        else
          zdb[a * nw + j - nx] = t;
      }
    }
    // y~ = L z~ + sum_d L_d z~_d,  y~_d = L z~_d.
    P.lower(L, zb.data(), yb.data());
    for (int a = 0; a < d; ++a) {
      P.lower(pog + (d * r + a) * T, zdb.data() + a * nw, tmp.data());
      for (int k = 0; k < nw; ++k) yb[k] += tmp[k];
      P.lower(L, zdb.data() + a * nw, ydb.data() + a * nw);
    }
    double *ob = pob + T * r, *wb = pwb + nw * r;
    // o~ from (z~, y~) at (y, w); o_d~ from (z~_d, y~_d) at (y, w); o~ from (z~_d, y~_d) at (y_d,
    // w_d).
    P.adjoint(y.data(), zb.data(), wr, yb.data(), wr, ob);
    for (int a = 0; a < d; ++a) {
      const double* wa = pwg + (d * r + a) * nw;
      P.adjoint(y.data(), zdb.data() + a * nw, wr, ydb.data() + a * nw, wr, pogb + (d * r + a) * T);
      P.adjoint(yd.data() + a * nw, zdb.data() + a * nw, wa, ydb.data() + a * nw, wa, ob);
    }
    P.port_adjoints(L, pog + d * r * T, d, yb.data(), zb.data(), ydb.data(), zdb.data(), wb,
                    pwgb + d * r * nw);
  }
  return out;
}

}  // namespace internal
}  // namespace phnn
