// src/models/fused_heads.cpp — forward and backward of the closed-form model
// heads, row by row (a row = one member and one batch element).
#include "models/fused_heads.h"

#include <cmath>
#include <vector>

namespace phnn {
namespace internal {
namespace {

using torch::Tensor;
using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// softplus(x) and sigmoid(x) from one exp(-|x|); above x = 20 softplus is x
// and its slope 1, as in LibTorch's softplus (threshold 20).
struct SoftplusSigmoid {
  double softplus, sigmoid, slope;
  explicit SoftplusSigmoid(double x) {
    const double z = std::exp(-std::fabs(x));
    sigmoid = x >= 0.0 ? 1.0 / (1.0 + z) : z / (1.0 + z);
    softplus = x > 20.0 ? x : std::fmax(x, 0.0) + std::log1p(z);
    slope = x > 20.0 ? 1.0 : sigmoid;
  }
};

Tensor dense(const Tensor& t) { return t.contiguous(); }

// A head's constant structure matrix (J or S), kept for its backward as one
// list entry of the context.
template <std::size_t R, std::size_t C>
void save_matrix(AutogradContext* ctx, const std::array<std::array<double, C>, R>& m) {
  std::vector<double> flat;
  for (const auto& row : m) flat.insert(flat.end(), row.begin(), row.end());
  ctx->saved_data["matrix"] = flat;
}
template <std::size_t R, std::size_t C>
std::array<std::array<double, C>, R> load_matrix(AutogradContext* ctx) {
  const std::vector<double> flat = ctx->saved_data["matrix"].toDoubleVector();
  std::array<std::array<double, C>, R> m;
  for (std::size_t i = 0; i < R; ++i)
    for (std::size_t j = 0; j < C; ++j) m[i][j] = flat[i * C + j];
  return m;
}

// ------------------------------------------------------------ Hamiltonian
// Per row, with l00 = softplus(o0), l10 = o1, l11 = softplus(o2), s_k =
// sigmoid(o_k):  v0 = l00 q, v1 = l10 q + l11 p, H = (v0^2 + v1^2) / 2,
//   m = L^T v = (l00 v0 + l10 v1, l11 v1),  c = (v0 s0 q, v1 q, v1 s2 p),
//   gradH_i = m_i + sum_k o_g[i][k] c_k.
// Backward with adjoints H~, g~ (c~_k = sum_i g~_i o_g[i][k]):
//   o_g~[i][k] = g~_i c_k
//   v0~ = H~ v0 + g~0 l00 + c~0 s0 q
//   v1~ = H~ v1 + g~0 l10 + g~1 l11 + c~1 q + c~2 s2 p
//   l00~ = g~0 v0 + v0~ q,  l10~ = g~0 v1 + v1~ q,  l11~ = g~1 v1 + v1~ p
//   q~ = c~0 v0 s0 + c~1 v1 + v0~ l00 + v1~ l10,  p~ = c~2 v1 s2 + v1~ l11
//   o0~ = l00~ softplus'(o0) + c~0 v0 q s0 (1 - s0),  o1~ = l10~,
//   o2~ = l11~ softplus'(o2) + c~2 v1 p s2 (1 - s2).
// The forward keeps (l00, l11, s0, s2, softplus'(o0), softplus'(o2)) per row
// for the backward.
constexpr int kAux = 6;
struct HamiltonianRow {
  double q, p, l00, l10, l11, s0, s2, v0, v1;
  HamiltonianRow(const double* o, const double* x, const double* aux)
      : q(x[0]), p(x[1]), l00(aux[0]), l10(o[1]), l11(aux[1]), s0(aux[2]), s2(aux[3]),
        v0(l00 * q), v1(l10 * q + l11 * p) {}
  double c(int k) const { return k == 0 ? v0 * s0 * q : k == 1 ? v1 * q : v1 * s2 * p; }
};

class HamiltonianFunction : public torch::autograd::Function<HamiltonianFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const Tensor& o_in,
                               const c10::optional<Tensor>& o_g_in, const Tensor& x_in) {
    const Tensor o = dense(o_in), x = dense(x_in);
    const bool with_grad = o_g_in.has_value();
    const Tensor o_g = with_grad ? dense(*o_g_in) : Tensor();
    const int64_t rows = o.size(0) * o.size(1);
    Tensor h = torch::empty({o.size(0), o.size(1), 1}, o.options());
    Tensor grad = with_grad ? torch::empty({o.size(0), o.size(1), 2}, o.options()) : Tensor();
    Tensor aux = torch::empty({rows, kAux}, o.options());
    const double *po = o.data_ptr<double>(), *px = x.data_ptr<double>();
    const double* pog = with_grad ? o_g.data_ptr<double>() : nullptr;
    double *ph = h.data_ptr<double>(), *pa = aux.data_ptr<double>();
    double* pg = with_grad ? grad.data_ptr<double>() : nullptr;
    for (int64_t r = 0; r < rows; ++r) {
      const SoftplusSigmoid f0(po[3 * r]), f2(po[3 * r + 2]);
      double* a = pa + kAux * r;
      a[0] = f0.softplus, a[1] = f2.softplus, a[2] = f0.sigmoid, a[3] = f2.sigmoid;
      a[4] = f0.slope, a[5] = f2.slope;
      const HamiltonianRow row(po + 3 * r, px + 2 * r, a);
      ph[r] = 0.5 * (row.v0 * row.v0 + row.v1 * row.v1);
      if (!with_grad) continue;
      const double* og = pog + 6 * r;
      const double c[3] = {row.c(0), row.c(1), row.c(2)};
      pg[2 * r] = row.l00 * row.v0 + row.l10 * row.v1 + og[0] * c[0] + og[1] * c[1] + og[2] * c[2];
      pg[2 * r + 1] = row.l11 * row.v1 + og[3] * c[0] + og[4] * c[1] + og[5] * c[2];
    }
    ctx->save_for_backward({o, with_grad ? o_g : o, x, aux});
    ctx->saved_data["with_grad"] = with_grad;
    return with_grad ? variable_list{h, grad} : variable_list{h};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const Tensor &o = saved[0], &x = saved[2], &aux = saved[3];
    const bool with_grad = ctx->saved_data["with_grad"].toBool();
    const int64_t rows = o.size(0) * o.size(1);
    const Tensor h_bar = grads[0].defined() ? dense(grads[0]) : torch::zeros_like(o.narrow(-1, 0, 1));
    const Tensor g_bar = with_grad && grads[1].defined() ? dense(grads[1]) : Tensor();
    Tensor o_bar = torch::empty_like(o), x_bar = torch::empty_like(x);
    Tensor o_g_bar = with_grad ? torch::zeros_like(saved[1]) : Tensor();
    const double *po = o.data_ptr<double>(), *px = x.data_ptr<double>();
    const double *phb = h_bar.data_ptr<double>(), *pa = aux.data_ptr<double>();
    const double* pog = g_bar.defined() ? saved[1].data_ptr<double>() : nullptr;
    const double* pgb = g_bar.defined() ? g_bar.data_ptr<double>() : nullptr;
    double* pogb = g_bar.defined() ? o_g_bar.data_ptr<double>() : nullptr;
    double *pob = o_bar.data_ptr<double>(), *pxb = x_bar.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const double* a = pa + kAux * r;
      const HamiltonianRow row(po + 3 * r, px + 2 * r, a);
      const double hb = phb[r];
      double gb[2] = {0.0, 0.0}, cb[3] = {0.0, 0.0, 0.0};
      if (pgb) {
        const double* og = pog + 6 * r;
        double* ogb = pogb + 6 * r;
        gb[0] = pgb[2 * r];
        gb[1] = pgb[2 * r + 1];
        for (int k = 0; k < 3; ++k) {
          cb[k] = gb[0] * og[k] + gb[1] * og[3 + k];
          ogb[k] = gb[0] * row.c(k);
          ogb[3 + k] = gb[1] * row.c(k);
        }
      }
      const double v0b = hb * row.v0 + gb[0] * row.l00 + cb[0] * row.s0 * row.q;
      const double v1b = hb * row.v1 + gb[0] * row.l10 + gb[1] * row.l11 + cb[1] * row.q +
                         cb[2] * row.s2 * row.p;
      const double l00b = gb[0] * row.v0 + v0b * row.q;
      const double l10b = gb[0] * row.v1 + v1b * row.q;
      const double l11b = gb[1] * row.v1 + v1b * row.p;
      double* ob = pob + 3 * r;
      ob[0] = l00b * a[4] + cb[0] * row.v0 * row.q * row.s0 * (1.0 - row.s0);
      ob[1] = l10b;
      ob[2] = l11b * a[5] + cb[2] * row.v1 * row.p * row.s2 * (1.0 - row.s2);
      double* xb = pxb + 2 * r;
      xb[0] = cb[0] * row.v0 * row.s0 + cb[1] * row.v1 + v0b * row.l00 + v1b * row.l10;
      xb[1] = cb[2] * row.v1 * row.s2 + v1b * row.l11;
    }
    return {o_bar, o_g_bar, x_bar};
  }
};

// ------------------------------------------------------ Hamiltonian, order 2
// Per row, with a = softplus(o0), c = o1, d = softplus(o2) and their
// x-derivatives by the chain rule (s_k = sigmoid(o_k), a' = s0, a'' = s0 (1 - s0)):
//   a_i = a' og_i0,  a_ij = a'' og_i0 og_j0 + a' oh_ij0   (c_i = og_i1, c_ij = oh_ij1; d like a)
//   v0 = a q,  v1 = c q + d p
//   v0_i = a_i q + a [i=0],  v1_i = c_i q + c [i=0] + d_i p + d [i=1]
//   v0_ij = a_ij q + a_i [j=0] + a_j [i=0]
//   v1_ij = c_ij q + c_i [j=0] + c_j [i=0] + d_ij p + d_i [j=1] + d_j [i=1]
//   G_i = v0 v0_i + v1 v1_i,   K_ij = v0_i v0_j + v0 v0_ij + v1_i v1_j + v1 v1_ij.
// The backward runs these lines in reverse (CurvatureRow::backward).
struct CurvatureRow {
  // Forward values.
  double q, p, a, c, d, a1, d1, a2, d2, ai[2], ci[2], di[2], aij[2][2], cij[2][2], dij[2][2];
  double v0, v1, v0i[2], v1i[2], v0ij[2][2], v1ij[2][2];

  CurvatureRow(const double* o, const double* og, const double* oh, const double* x) {
    q = x[0], p = x[1];
    const SoftplusSigmoid f0(o[0]), f2(o[2]);
    a = f0.softplus, c = o[1], d = f2.softplus;
    a1 = f0.sigmoid, d1 = f2.sigmoid;
    a2 = a1 * (1.0 - a1), d2 = d1 * (1.0 - d1);
    for (int i = 0; i < 2; ++i) {
      ai[i] = a1 * og[3 * i], ci[i] = og[3 * i + 1], di[i] = d1 * og[3 * i + 2];
      for (int j = 0; j < 2; ++j) {
        const double* h = oh + 6 * i + 3 * j;
        aij[i][j] = a2 * og[3 * i] * og[3 * j] + a1 * h[0];
        cij[i][j] = h[1];
        dij[i][j] = d2 * og[3 * i + 2] * og[3 * j + 2] + d1 * h[2];
      }
    }
    v0 = a * q, v1 = c * q + d * p;
    for (int i = 0; i < 2; ++i) {
      v0i[i] = ai[i] * q + (i == 0 ? a : 0.0);
      v1i[i] = ci[i] * q + (i == 0 ? c : 0.0) + di[i] * p + (i == 1 ? d : 0.0);
      for (int j = 0; j < 2; ++j) {
        v0ij[i][j] = aij[i][j] * q + (j == 0 ? ai[i] : 0.0) + (i == 0 ? ai[j] : 0.0);
        v1ij[i][j] = cij[i][j] * q + (j == 0 ? ci[i] : 0.0) + (i == 0 ? ci[j] : 0.0) +
                     dij[i][j] * p + (j == 1 ? di[i] : 0.0) + (i == 1 ? di[j] : 0.0);
      }
    }
  }
  double grad(int i) const { return v0 * v0i[i] + v1 * v1i[i]; }
  double hessian(int i, int j) const {
    return v0i[i] * v0i[j] + v0 * v0ij[i][j] + v1i[i] * v1i[j] + v1 * v1ij[i][j];
  }

  // Adjoints of (o, og, oh, x) from those of G (gb[2]) and K (kb[2][2]).
  void backward(const double* o, const double* og, const double* oh, const double* gb,
                const double* kb, double* ob, double* ogb, double* ohb, double* xb) const {
    double v0b = 0, v1b = 0, v0ib[2] = {0, 0}, v1ib[2] = {0, 0}, v0ijb[2][2], v1ijb[2][2];
    for (int i = 0; i < 2; ++i) {
      v0b += gb[i] * v0i[i], v1b += gb[i] * v1i[i];
      v0ib[i] += gb[i] * v0, v1ib[i] += gb[i] * v1;
      for (int j = 0; j < 2; ++j) {
        const double k = kb[2 * i + j], kt = kb[2 * j + i];
        v0ib[i] += (k + kt) * v0i[j], v1ib[i] += (k + kt) * v1i[j];
        v0b += k * v0ij[i][j], v1b += k * v1ij[i][j];
        v0ijb[i][j] = k * v0, v1ijb[i][j] = k * v1;
      }
    }
    double ab = 0, cb = 0, db = 0, qb = 0, pb = 0, aib[2] = {0, 0}, cib[2] = {0, 0}, dib[2] = {0, 0};
    double aijb[2][2], cijb[2][2], dijb[2][2];
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        aijb[i][j] = v0ijb[i][j] * q, cijb[i][j] = v1ijb[i][j] * q, dijb[i][j] = v1ijb[i][j] * p;
        qb += v0ijb[i][j] * aij[i][j] + v1ijb[i][j] * cij[i][j];
        pb += v1ijb[i][j] * dij[i][j];
        if (j == 0) aib[i] += v0ijb[i][j], cib[i] += v1ijb[i][j];
        if (i == 0) aib[j] += v0ijb[i][j], cib[j] += v1ijb[i][j];
        if (j == 1) dib[i] += v1ijb[i][j];
        if (i == 1) dib[j] += v1ijb[i][j];
      }
      aib[i] += v0ib[i] * q, cib[i] += v1ib[i] * q, dib[i] += v1ib[i] * p;
      qb += v0ib[i] * ai[i] + v1ib[i] * ci[i];
      pb += v1ib[i] * di[i];
    }
    ab += v0ib[0], cb += v1ib[0], db += v1ib[1];
    ab += v0b * q, cb += v1b * q, db += v1b * p;
    qb += v0b * a + v1b * c, pb += v1b * d;
    double a1b = 0, a2b = 0, d1b = 0, d2b = 0;
    for (int i = 0; i < 6; ++i) ogb[i] = 0.0;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        const double* h = oh + 6 * i + 3 * j;
        double* hb = ohb + 6 * i + 3 * j;
        a2b += aijb[i][j] * og[3 * i] * og[3 * j];
        ogb[3 * i] += (aijb[i][j] + aijb[j][i]) * a2 * og[3 * j];
        a1b += aijb[i][j] * h[0];
        d2b += dijb[i][j] * og[3 * i + 2] * og[3 * j + 2];
        ogb[3 * i + 2] += (dijb[i][j] + dijb[j][i]) * d2 * og[3 * j + 2];
        d1b += dijb[i][j] * h[2];
        hb[0] = aijb[i][j] * a1, hb[1] = cijb[i][j], hb[2] = dijb[i][j] * d1;
      }
      a1b += aib[i] * og[3 * i], ogb[3 * i] += aib[i] * a1;
      ogb[3 * i + 1] += cib[i];
      d1b += dib[i] * og[3 * i + 2], ogb[3 * i + 2] += dib[i] * d1;
    }
    const SoftplusSigmoid f0(o[0]), f2(o[2]);
    ob[0] = ab * f0.slope + a1b * a2 + a2b * a2 * (1.0 - 2.0 * a1);
    ob[1] = cb;
    ob[2] = db * f2.slope + d1b * d2 + d2b * d2 * (1.0 - 2.0 * d1);
    xb[0] = qb, xb[1] = pb;
  }
};

class CurvatureFunction : public torch::autograd::Function<CurvatureFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const Tensor& o_in, const Tensor& og_in,
                               const Tensor& oh_in, const Tensor& x_in) {
    const Tensor o = dense(o_in), og = dense(og_in), oh = dense(oh_in), x = dense(x_in);
    const int64_t E = o.size(0), B = o.size(1), rows = E * B;
    Tensor grad = torch::empty({E, B, 2}, o.options()), hess = torch::empty({E, B, 2, 2}, o.options());
    const double *po = o.data_ptr<double>(), *pg = og.data_ptr<double>();
    const double *ph = oh.data_ptr<double>(), *px = x.data_ptr<double>();
    double *pgr = grad.data_ptr<double>(), *phs = hess.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const CurvatureRow row(po + 3 * r, pg + 6 * r, ph + 12 * r, px + 2 * r);
      for (int i = 0; i < 2; ++i) {
        pgr[2 * r + i] = row.grad(i);
        for (int j = 0; j < 2; ++j) phs[4 * r + 2 * i + j] = row.hessian(i, j);
      }
    }
    ctx->save_for_backward({o, og, oh, x});
    return {grad, hess};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const Tensor &o = saved[0], &og = saved[1], &oh = saved[2], &x = saved[3];
    const int64_t rows = o.size(0) * o.size(1);
    const Tensor gb = grads[0].defined() ? dense(grads[0]) : torch::zeros_like(x);
    const Tensor kb = grads[1].defined() ? dense(grads[1])
                                         : torch::zeros({o.size(0), o.size(1), 2, 2}, o.options());
    Tensor o_bar = torch::empty_like(o), og_bar = torch::empty_like(og);
    Tensor oh_bar = torch::empty_like(oh), x_bar = torch::empty_like(x);
    const double *po = o.data_ptr<double>(), *pg = og.data_ptr<double>();
    const double *ph = oh.data_ptr<double>(), *px = x.data_ptr<double>();
    const double *pgb = gb.data_ptr<double>(), *pkb = kb.data_ptr<double>();
    double *pob = o_bar.data_ptr<double>(), *pogb = og_bar.data_ptr<double>();
    double *pohb = oh_bar.data_ptr<double>(), *pxb = x_bar.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const CurvatureRow row(po + 3 * r, pg + 6 * r, ph + 12 * r, px + 2 * r);
      row.backward(po + 3 * r, pg + 6 * r, ph + 12 * r, pgb + 2 * r, pkb + 4 * r, pob + 3 * r,
                   pogb + 6 * r, pohb + 12 * r, pxb + 2 * r);
    }
    return {o_bar, og_bar, oh_bar, x_bar};
  }
};

// ---------------------------------------------------------------- PHNN-JR
// Per row, eps = (e0, e1, u), L lower triangular from o (row-major):
//   v = L eps,  f_i = sum_j J_ij eps_j - (L^T v)_i,  i = 0, 1.
// Backward with f~ (f~_2 = 0), w = L f~:
//   eps~ = J^T f~ - L^T w          (R = L^T L is symmetric)
//   L~_ab = -(v_a f~_b + w_a eps_b)  for the lower-triangle entries (a >= b).
constexpr int kRow[6] = {0, 1, 1, 2, 2, 2}, kCol[6] = {0, 0, 1, 0, 1, 2};

// y = L a and z = L^T a for the row-major lower triangle o.
inline void lower_times(const double* o, const double* a, double* y) {
  y[0] = o[0] * a[0];
  y[1] = o[1] * a[0] + o[2] * a[1];
  y[2] = o[3] * a[0] + o[4] * a[1] + o[5] * a[2];
}
inline void lower_transpose_times(const double* o, const double* a, double* z) {
  z[0] = o[0] * a[0] + o[1] * a[1] + o[3] * a[2];
  z[1] = o[2] * a[1] + o[4] * a[2];
  z[2] = o[5] * a[2];
}

class JrFieldFunction : public torch::autograd::Function<JrFieldFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& effort_in, const Tensor& o_in,
                        const Tensor& u_in, std::array<std::array<double, 3>, 3> J) {
    const Tensor e = dense(effort_in), o = dense(o_in), u = dense(u_in);
    const int64_t rows = e.size(0) * e.size(1);
    Tensor f = torch::empty_like(e);
    const double *pe = e.data_ptr<double>(), *po = o.data_ptr<double>(), *pu = u.data_ptr<double>();
    double* pf = f.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const double eps[3] = {pe[2 * r], pe[2 * r + 1], pu[r]};
      double v[3], rv[3];
      lower_times(po + 6 * r, eps, v);
      lower_transpose_times(po + 6 * r, v, rv);
      for (int i = 0; i < 2; ++i) {
        pf[2 * r + i] = J[i][0] * eps[0] + J[i][1] * eps[1] + J[i][2] * eps[2] - rv[i];
      }
    }
    ctx->save_for_backward({e, o, u});
    save_matrix(ctx, J);
    return f;
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const Tensor &e = saved[0], &o = saved[1], &u = saved[2];
    const auto J = load_matrix<3, 3>(ctx);
    const Tensor fb = dense(grads[0]);
    const int64_t rows = e.size(0) * e.size(1);
    Tensor e_bar = torch::empty_like(e), o_bar = torch::empty_like(o), u_bar = torch::empty_like(u);
    const double *pe = e.data_ptr<double>(), *po = o.data_ptr<double>(), *pu = u.data_ptr<double>();
    const double* pfb = fb.data_ptr<double>();
    double *peb = e_bar.data_ptr<double>(), *pob = o_bar.data_ptr<double>();
    double* pub = u_bar.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const double eps[3] = {pe[2 * r], pe[2 * r + 1], pu[r]};
      const double f_bar[3] = {pfb[2 * r], pfb[2 * r + 1], 0.0};
      double v[3], w[3], ltw[3];
      lower_times(po + 6 * r, eps, v);
      lower_times(po + 6 * r, f_bar, w);
      lower_transpose_times(po + 6 * r, w, ltw);
      double eps_bar[3];
      for (int j = 0; j < 3; ++j) eps_bar[j] = J[0][j] * f_bar[0] + J[1][j] * f_bar[1] - ltw[j];
      peb[2 * r] = eps_bar[0];
      peb[2 * r + 1] = eps_bar[1];
      pub[r] = eps_bar[2];
      double* ob = pob + 6 * r;
      for (int k = 0; k < 6; ++k) ob[k] = -(v[kRow[k]] * f_bar[kCol[k]] + w[kRow[k]] * eps[kCol[k]]);
    }
    return {e_bar, o_bar, u_bar, Tensor()};
  }
};

// ------------------------------------------------- PHNN-JR, first-order jet
// The field and its x-tangents (direction i): eps = (e, u), eps_i = (K_i, 0)
// with K_i = d e / d x_i, L_i = the lower triangle of o_g[i]:
//   v = L eps,  v_i = L_i eps + L eps_i,  r = L^T v,  r_i = L_i^T v + L^T v_i,
//   f_c = sum_j J_cj eps_j - r_c,  f_ic = sum_j J_cj eps_ij - r_ic   (c = 0, 1).
// Backward with f~, f~_i (r~ = -f~, r~_i = -f~_i, third components 0):
//   v~ = L r~ + sum_i L_i r~_i,  v~_i = L r~_i,
//   L~ = v r~^T + sum_i v_i r~_i^T + v~ eps^T + sum_i v~_i eps_i^T,
//   L~_i = v r~_i^T + v~_i eps^T,
//   eps~ = J^T f~ + L^T v~ + sum_i L_i^T v~_i,  eps~_i = J^T f~_i + L^T v~_i,
// keeping the lower-triangle entries of L~ and L~_i.
class JrJetFunction : public torch::autograd::Function<JrJetFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const Tensor& e_in, const Tensor& k_in,
                               const Tensor& o_in, const Tensor& og_in, const Tensor& u_in,
                               std::array<std::array<double, 3>, 3> J) {
    const Tensor e = dense(e_in), K = dense(k_in), o = dense(o_in), og = dense(og_in), u = dense(u_in);
    const int64_t E = e.size(0), B = e.size(1), rows = E * B;
    Tensor f = torch::empty({E, B, 2}, e.options()), fg = torch::empty({E, B, 2, 2}, e.options());
    const double *pe = e.data_ptr<double>(), *pk = K.data_ptr<double>(), *po = o.data_ptr<double>();
    const double *pog = og.data_ptr<double>(), *pu = u.data_ptr<double>();
    double *pf = f.data_ptr<double>(), *pfg = fg.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const double eps[3] = {pe[2 * r], pe[2 * r + 1], pu[r]};
      const double* L = po + 6 * r;
      double v[3], rv[3];
      lower_times(L, eps, v);
      lower_transpose_times(L, v, rv);
      for (int c = 0; c < 2; ++c) pf[2 * r + c] = J[c][0] * eps[0] + J[c][1] * eps[1] + J[c][2] * eps[2] - rv[c];
      for (int i = 0; i < 2; ++i) {
        const double eps_i[3] = {pk[4 * r + 2 * i], pk[4 * r + 2 * i + 1], 0.0};
        const double* Li = pog + 12 * r + 6 * i;
        double vi[3], a[3], b[3], ri[3];
        lower_times(Li, eps, vi);
        lower_times(L, eps_i, a);
        for (int k = 0; k < 3; ++k) vi[k] += a[k];
        lower_transpose_times(Li, v, ri);
        lower_transpose_times(L, vi, b);
        for (int c = 0; c < 2; ++c) {
          pfg[4 * r + 2 * i + c] = J[c][0] * eps_i[0] + J[c][1] * eps_i[1] - (ri[c] + b[c]);
        }
      }
    }
    ctx->save_for_backward({e, K, o, og, u});
    save_matrix(ctx, J);
    return {f, fg};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const Tensor &e = saved[0], &K = saved[1], &o = saved[2], &og = saved[3], &u = saved[4];
    const auto J = load_matrix<3, 3>(ctx);
    const int64_t E = e.size(0), B = e.size(1), rows = E * B;
    const Tensor fb = grads[0].defined() ? dense(grads[0]) : torch::zeros_like(e);
    const Tensor fgb = grads[1].defined() ? dense(grads[1]) : torch::zeros({E, B, 2, 2}, e.options());
    Tensor e_bar = torch::empty_like(e), k_bar = torch::empty_like(K), o_bar = torch::empty_like(o);
    Tensor og_bar = torch::empty_like(og), u_bar = torch::empty_like(u);
    const double *pe = e.data_ptr<double>(), *pk = K.data_ptr<double>(), *po = o.data_ptr<double>();
    const double *pog = og.data_ptr<double>(), *pu = u.data_ptr<double>();
    const double *pfb = fb.data_ptr<double>(), *pfgb = fgb.data_ptr<double>();
    double *peb = e_bar.data_ptr<double>(), *pkb = k_bar.data_ptr<double>();
    double *pob = o_bar.data_ptr<double>(), *pogb = og_bar.data_ptr<double>(), *pub = u_bar.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const double eps[3] = {pe[2 * r], pe[2 * r + 1], pu[r]};
      const double* L = po + 6 * r;
      const double* Li[2] = {pog + 12 * r, pog + 12 * r + 6};
      double eps_i[2][3], v[3], vi[2][3];
      lower_times(L, eps, v);
      for (int i = 0; i < 2; ++i) {
        eps_i[i][0] = pk[4 * r + 2 * i], eps_i[i][1] = pk[4 * r + 2 * i + 1], eps_i[i][2] = 0.0;
        double a[3];
        lower_times(Li[i], eps, vi[i]);
        lower_times(L, eps_i[i], a);
        for (int k = 0; k < 3; ++k) vi[i][k] += a[k];
      }
      const double rb[3] = {-pfb[2 * r], -pfb[2 * r + 1], 0.0};
      double rib[2][3], vb[3], vib[2][3], tmp[3];
      lower_times(L, rb, vb);
      for (int i = 0; i < 2; ++i) {
        rib[i][0] = -pfgb[4 * r + 2 * i], rib[i][1] = -pfgb[4 * r + 2 * i + 1], rib[i][2] = 0.0;
        lower_times(Li[i], rib[i], tmp);
        for (int k = 0; k < 3; ++k) vb[k] += tmp[k];
        lower_times(L, rib[i], vib[i]);
      }
      double* ob = pob + 6 * r;
      for (int k = 0; k < 6; ++k) {
        const int a = kRow[k], b = kCol[k];
        double s = v[a] * rb[b] + vb[a] * eps[b];
        for (int i = 0; i < 2; ++i) s += vi[i][a] * rib[i][b] + vib[i][a] * eps_i[i][b];
        ob[k] = s;
        for (int i = 0; i < 2; ++i) pogb[12 * r + 6 * i + k] = v[a] * rib[i][b] + vib[i][a] * eps[b];
      }
      double eb[3];
      lower_transpose_times(L, vb, eb);
      for (int i = 0; i < 2; ++i) {
        lower_transpose_times(Li[i], vib[i], tmp);
        for (int k = 0; k < 3; ++k) eb[k] += tmp[k];
      }
      for (int j = 0; j < 3; ++j) eb[j] += J[0][j] * pfb[2 * r] + J[1][j] * pfb[2 * r + 1];
      peb[2 * r] = eb[0], peb[2 * r + 1] = eb[1], pub[r] = eb[2];
      for (int i = 0; i < 2; ++i) {
        lower_transpose_times(L, vib[i], tmp);
        for (int a = 0; a < 2; ++a) {
          pkb[4 * r + 2 * i + a] = tmp[a] + J[0][a] * pfgb[4 * r + 2 * i] + J[1][a] * pfgb[4 * r + 2 * i + 1];
        }
      }
    }
    return {e_bar, k_bar, o_bar, og_bar, u_bar, Tensor()};
  }
};

// ---------------------------------------------------------------- PHNN-S
// Per row: w = S_w0 e0 + S_w1 e1 + S_w3 u (S_ww = 0), and from w and the L_z
// output l: f_i = S_i0 e0 + S_i1 e1 + S_i2 l^2 w + S_i3 u (i = 0, 1).
// Backward: e~_j += sum_i f~_i S_ij, u~ += sum_i f~_i S_i3,
//   l~ = 2 l w sum_i f~_i S_i2, w~ = l^2 sum_i f~_i S_i2 (and w's own rule).
using StructureRows = std::array<std::array<double, 4>, 4>;

class PhnnSWFunction : public torch::autograd::Function<PhnnSWFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& e_in, const Tensor& u_in,
                        std::array<double, 3> s) {
    const Tensor e = dense(e_in), u = dense(u_in);
    const int64_t rows = e.size(0) * e.size(1);
    Tensor w = torch::empty({e.size(0), e.size(1), 1}, e.options());
    const double *pe = e.data_ptr<double>(), *pu = u.data_ptr<double>();
    double* pw = w.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) pw[r] = s[0] * pe[2 * r] + s[1] * pe[2 * r + 1] + s[2] * pu[r];
    ctx->saved_data["s"] = std::vector<double>(s.begin(), s.end());
    return w;
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const std::vector<double> s = ctx->saved_data["s"].toDoubleVector();
    const double s0 = s[0], s1 = s[1], s2 = s[2];
    const Tensor wb = dense(grads[0]);
    const int64_t E = wb.size(0), B = wb.size(1), rows = E * B;
    Tensor e_bar = torch::empty({E, B, 2}, wb.options()), u_bar = torch::empty({E, B, 1}, wb.options());
    const double* pwb = wb.data_ptr<double>();
    double *peb = e_bar.data_ptr<double>(), *pub = u_bar.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      peb[2 * r] = s0 * pwb[r], peb[2 * r + 1] = s1 * pwb[r], pub[r] = s2 * pwb[r];
    }
    return {e_bar, u_bar, Tensor()};
  }
};

class PhnnSFieldFunction : public torch::autograd::Function<PhnnSFieldFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& e_in, const Tensor& u_in,
                        const Tensor& l_in, const Tensor& w_in, StructureRows S) {
    const Tensor e = dense(e_in), u = dense(u_in), l = dense(l_in), w = dense(w_in);
    const int64_t rows = e.size(0) * e.size(1);
    Tensor f = torch::empty_like(e);
    const double *pe = e.data_ptr<double>(), *pu = u.data_ptr<double>();
    const double *pl = l.data_ptr<double>(), *pw = w.data_ptr<double>();
    double* pf = f.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const double z = pl[r] * pl[r] * pw[r];
      for (int i = 0; i < 2; ++i) {
        pf[2 * r + i] = S[i][0] * pe[2 * r] + S[i][1] * pe[2 * r + 1] + S[i][2] * z + S[i][3] * pu[r];
      }
    }
    ctx->save_for_backward({l, w});
    save_matrix(ctx, S);
    return f;
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const Tensor &l = saved[0], &w = saved[1];
    const auto S = load_matrix<4, 4>(ctx);
    const Tensor fb = dense(grads[0]);
    const int64_t E = l.size(0), B = l.size(1), rows = E * B;
    Tensor e_bar = torch::empty({E, B, 2}, l.options()), u_bar = torch::empty_like(l);
    Tensor l_bar = torch::empty_like(l), w_bar = torch::empty_like(w);
    const double *pl = l.data_ptr<double>(), *pw = w.data_ptr<double>(), *pfb = fb.data_ptr<double>();
    double *peb = e_bar.data_ptr<double>(), *pub = u_bar.data_ptr<double>();
    double *plb = l_bar.data_ptr<double>(), *pwb = w_bar.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const double f0 = pfb[2 * r], f1 = pfb[2 * r + 1];
      peb[2 * r] = f0 * S[0][0] + f1 * S[1][0];
      peb[2 * r + 1] = f0 * S[0][1] + f1 * S[1][1];
      pub[r] = f0 * S[0][3] + f1 * S[1][3];
      const double zb = f0 * S[0][2] + f1 * S[1][2];
      plb[r] = 2.0 * pl[r] * pw[r] * zb;
      pwb[r] = pl[r] * pl[r] * zb;
    }
    return {e_bar, u_bar, l_bar, w_bar, Tensor()};
  }
};

// --------------------------------------------------------------- Gonzalez
// Per row: n2 = |dx|^2, D = H1 - H0 - g.dx, k = D / n2 (0 if n2 < tau^2),
// dg = g + k dx. Backward with dg~, s = dg~.dx (small rows: g~ = dg~ only):
//   H1~ = s / n2,  H0~ = -s / n2,  g~ = dg~ - (s / n2) dx,
//   dx~ = k dg~ - (s / n2) (g + 2 k dx).
class GonzalezFunction : public torch::autograd::Function<GonzalezFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& h0_in, const Tensor& h1_in,
                        const Tensor& g_in, const Tensor& dx_in, double min_dx_norm) {
    const Tensor h0 = dense(h0_in), h1 = dense(h1_in), g = dense(g_in), dx = dense(dx_in);
    const int64_t rows = g.size(0) * g.size(1);
    Tensor dg = torch::empty_like(g);
    const double *p0 = h0.data_ptr<double>(), *p1 = h1.data_ptr<double>();
    const double *pg = g.data_ptr<double>(), *pd = dx.data_ptr<double>();
    double* out = dg.data_ptr<double>();
    const double tau2 = min_dx_norm * min_dx_norm;
    for (int64_t r = 0; r < rows; ++r) {
      const double* gr = pg + 2 * r;
      const double* d = pd + 2 * r;
      const double n2 = d[0] * d[0] + d[1] * d[1];
      const double defect = p1[r] - p0[r] - (gr[0] * d[0] + gr[1] * d[1]);
      const double k = n2 < tau2 ? 0.0 : defect / n2;
      out[2 * r] = gr[0] + k * d[0];
      out[2 * r + 1] = gr[1] + k * d[1];
    }
    ctx->save_for_backward({h0, h1, g, dx});
    ctx->saved_data["tau2"] = tau2;
    return dg;
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const Tensor &h0 = saved[0], &h1 = saved[1], &g = saved[2], &dx = saved[3];
    const double tau2 = ctx->saved_data["tau2"].toDouble();
    const Tensor db = dense(grads[0]);
    const int64_t rows = g.size(0) * g.size(1);
    Tensor h0_bar = torch::empty_like(h0), h1_bar = torch::empty_like(h1);
    Tensor g_bar = torch::empty_like(g), dx_bar = torch::empty_like(dx);
    const double *p0 = h0.data_ptr<double>(), *p1 = h1.data_ptr<double>();
    const double *pg = g.data_ptr<double>(), *pd = dx.data_ptr<double>();
    const double* pb = db.data_ptr<double>();
    double *ph0b = h0_bar.data_ptr<double>(), *ph1b = h1_bar.data_ptr<double>();
    double *pgb = g_bar.data_ptr<double>(), *pxb = dx_bar.data_ptr<double>();
    for (int64_t r = 0; r < rows; ++r) {
      const double* gr = pg + 2 * r;
      const double* d = pd + 2 * r;
      const double* b = pb + 2 * r;
      const double n2 = d[0] * d[0] + d[1] * d[1];
      double* gb = pgb + 2 * r;
      double* xb = pxb + 2 * r;
      if (n2 < tau2) {
        ph0b[r] = ph1b[r] = 0.0;
        gb[0] = b[0], gb[1] = b[1], xb[0] = xb[1] = 0.0;
        continue;
      }
      const double k = (p1[r] - p0[r] - (gr[0] * d[0] + gr[1] * d[1])) / n2;
      const double s_n2 = (b[0] * d[0] + b[1] * d[1]) / n2;
      ph1b[r] = s_n2;
      ph0b[r] = -s_n2;
      for (int i = 0; i < 2; ++i) {
        gb[i] = b[i] - s_n2 * d[i];
        xb[i] = k * b[i] - s_n2 * (gr[i] + 2.0 * k * d[i]);
      }
    }
    return {h0_bar, h1_bar, g_bar, dx_bar, Tensor()};
  }
};

}  // namespace

HamiltonianHead hamiltonian_head(const torch::Tensor& o, const torch::Tensor& o_g,
                                 const torch::Tensor& x) {
  TORCH_CHECK(o.dim() == 3 && o.size(2) == 3 && x.size(2) == 2 &&
                  o.scalar_type() == torch::kFloat64,
              "hamiltonian_head: expected float64 o [E, B, 3] and x [E, B, 2], got ", o.sizes(),
              " and ", x.sizes());
  const auto out = HamiltonianFunction::apply(
      o, o_g.defined() ? c10::optional<torch::Tensor>(o_g) : c10::nullopt, x.expand_as(o.narrow(-1, 0, 2)));
  return {out[0], out.size() > 1 ? out[1] : torch::Tensor()};
}

HamiltonianCurvature hamiltonian_curvature_head(const torch::Tensor& o, const torch::Tensor& o_g,
                                                const torch::Tensor& o_h, const torch::Tensor& x) {
  TORCH_CHECK(o.dim() == 3 && o.size(2) == 3 && o_g.dim() == 4 && o_h.dim() == 5,
              "hamiltonian_curvature_head: expected o [E, B, 3], o_g [E, B, 2, 3], "
              "o_h [E, B, 2, 2, 3], got ", o.sizes(), ", ", o_g.sizes(), ", ", o_h.sizes());
  const auto out = CurvatureFunction::apply(o, o_g, o_h, x.expand_as(o.narrow(-1, 0, 2)));
  return {out[0], out[1]};
}

torch::Tensor jr_field_head(const torch::Tensor& effort, const torch::Tensor& o,
                            const torch::Tensor& u, const std::array<std::array<double, 3>, 3>& J) {
  TORCH_CHECK(effort.dim() == 3 && effort.size(2) == 2 && o.size(2) == 6 && u.size(2) == 1,
              "jr_field_head: expected e [E, B, 2], o [E, B, 6], u [E, B, 1], got ",
              effort.sizes(), ", ", o.sizes(), ", ", u.sizes());
  return JrFieldFunction::apply(effort, o, u.expand({effort.size(0), effort.size(1), 1}), J);
}

JrFieldJet jr_field_jet_head(const torch::Tensor& effort, const torch::Tensor& effort_g,
                             const torch::Tensor& o, const torch::Tensor& o_g, const torch::Tensor& u,
                             const std::array<std::array<double, 3>, 3>& J) {
  TORCH_CHECK(effort_g.dim() == 4 && effort_g.size(2) == 2 && o_g.dim() == 4 && o_g.size(2) == 2,
              "jr_field_jet_head: expected 2 directions, got ", effort_g.sizes(), " and ", o_g.sizes());
  const auto out = JrJetFunction::apply(effort, effort_g, o, o_g,
                                        u.expand({effort.size(0), effort.size(1), 1}), J);
  return {out[0], out[1]};
}

torch::Tensor phnn_s_w_head(const torch::Tensor& effort, const torch::Tensor& u,
                           const std::array<double, 3>& s_w) {
  return PhnnSWFunction::apply(effort, u.expand({effort.size(0), effort.size(1), 1}), s_w);
}

torch::Tensor phnn_s_field_head(const torch::Tensor& effort, const torch::Tensor& u,
                                const torch::Tensor& l, const torch::Tensor& w,
                                const std::array<std::array<double, 4>, 4>& S) {
  return PhnnSFieldFunction::apply(effort, u.expand({effort.size(0), effort.size(1), 1}), l, w, S);
}

torch::Tensor gonzalez_head(const torch::Tensor& h_x, const torch::Tensor& h_x_dx,
                            const torch::Tensor& grad_mid, const torch::Tensor& dx,
                            double min_dx_norm) {
  return GonzalezFunction::apply(h_x, h_x_dx, grad_mid, dx.expand_as(grad_mid), min_dx_norm);
}

}  // namespace internal
}  // namespace phnn
