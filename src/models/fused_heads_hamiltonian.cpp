// src/models/fused_heads_hamiltonian.cpp — the Hamiltonian head H = |L^T x|^2 / 2
// with its gradient (and, for the regularizers and DG4, its curvature), each
// one autograd node with a hand-written backward, row by row (a row = one
// member and one batch element). The field and DG heads: fused_heads.cpp.
#include "models/fused_heads.h"
#include "models/fused_heads_common.h"

namespace phnn {
namespace internal {
namespace {

using namespace heads;

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
// The forward keeps softplus, sigmoid and softplus' of o0 and o2, column
// by column ([6, rows]: one softplus_sigmoid_array call over both outputs
// of every row), for the backward.
struct HamiltonianRow {
  double q, p, l00, l10, l11, s0, s2, v0, v1;
  HamiltonianRow(const double* o, const double* x, const SoftplusColumns& f, int64_t r)
      : q(x[0]), p(x[1]), l00(f.softplus(0, r)), l10(o[1]), l11(f.softplus(1, r)),
        s0(f.sigmoid(0, r)), s2(f.sigmoid(1, r)), v0(l00 * q), v1(l10 * q + l11 * p) {}
  double c(int k) const { return k == 0 ? v0 * s0 * q : k == 1 ? v1 * q : v1 * s2 * p; }
};

}  // namespace

HamiltonianHead hamiltonian_head_taped(const Tensor& o_in, const Tensor& o_g_in, const Tensor& x_in,
                                       HamiltonianTape* tape) {
  const Tensor o = dense(o_in), x = dense(x_in);
  const bool with_grad = o_g_in.defined();
  const Tensor o_g = with_grad ? dense(o_g_in) : Tensor();
  const int64_t rows = o.size(0) * o.size(1);
  Tensor h = torch::empty({o.size(0), o.size(1), 1}, o.options());
  Tensor grad = with_grad ? torch::empty({o.size(0), o.size(1), 2}, o.options()) : Tensor();
  Tensor aux = torch::empty({SoftplusColumns::size(2, rows)}, o.options());
  const double *po = o.data_ptr<double>(), *px = x.data_ptr<double>();
  const double* pog = with_grad ? o_g.data_ptr<double>() : nullptr;
  double* ph = h.data_ptr<double>();
  double* pg = with_grad ? grad.data_ptr<double>() : nullptr;
  const SoftplusColumns f = SoftplusColumns::compute(po, 3, {0, 2}, rows, aux.data_ptr<double>());
  for (int64_t r = 0; r < rows; ++r) {
    const HamiltonianRow row(po + 3 * r, px + 2 * r, f, r);
    ph[r] = 0.5 * (row.v0 * row.v0 + row.v1 * row.v1);
    if (!with_grad) continue;
    const double* og = pog + 6 * r;
    const double c[3] = {row.c(0), row.c(1), row.c(2)};
    pg[2 * r] = row.l00 * row.v0 + row.l10 * row.v1 + og[0] * c[0] + og[1] * c[1] + og[2] * c[2];
    pg[2 * r + 1] = row.l11 * row.v1 + og[3] * c[0] + og[4] * c[1] + og[5] * c[2];
  }
  *tape = HamiltonianTape{o, o_g, x, aux};
  return {h, grad};
}

HamiltonianAdjoints hamiltonian_head_backward(const HamiltonianTape& tape, const Tensor& h_bar_in,
                                              const Tensor& g_bar_in) {
  const Tensor &o = tape.o, &x = tape.x;
  const bool with_grad = tape.o_g.defined();
  const int64_t rows = o.size(0) * o.size(1);
  const Tensor h_bar = h_bar_in.defined() ? dense(h_bar_in) : torch::zeros_like(o.narrow(-1, 0, 1));
  const Tensor g_bar = with_grad && g_bar_in.defined() ? dense(g_bar_in) : Tensor();
  HamiltonianAdjoints out{torch::empty_like(o), with_grad ? torch::zeros_like(tape.o_g) : Tensor(),
                          torch::empty_like(x)};
  const double *po = o.data_ptr<double>(), *px = x.data_ptr<double>();
  const double* phb = h_bar.data_ptr<double>();
  const SoftplusColumns f = SoftplusColumns::saved(2, rows, tape.aux.data_ptr<double>());
  const double* pog = g_bar.defined() ? tape.o_g.data_ptr<double>() : nullptr;
  const double* pgb = g_bar.defined() ? g_bar.data_ptr<double>() : nullptr;
  double* pogb = g_bar.defined() ? out.o_g.data_ptr<double>() : nullptr;
  double *pob = out.o.data_ptr<double>(), *pxb = out.x.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    const HamiltonianRow row(po + 3 * r, px + 2 * r, f, r);
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
    ob[0] = l00b * f.slope(0, r) + cb[0] * row.v0 * row.q * row.s0 * (1.0 - row.s0);
    ob[1] = l10b;
    ob[2] = l11b * f.slope(1, r) + cb[2] * row.v1 * row.p * row.s2 * (1.0 - row.s2);
    double* xb = pxb + 2 * r;
    xb[0] = cb[0] * row.v0 * row.s0 + cb[1] * row.v1 + v0b * row.l00 + v1b * row.l10;
    xb[1] = cb[2] * row.v1 * row.s2 + v1b * row.l11;
  }
  return out;
}

namespace {

// The autograd node of hamiltonian_head: the taped forward and backward.
class HamiltonianFunction : public torch::autograd::Function<HamiltonianFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const Tensor& o_in,
                               const c10::optional<Tensor>& o_g_in, const Tensor& x_in) {
    HamiltonianTape tape;
    const bool with_grad = o_g_in.has_value();
    const HamiltonianHead head =
        hamiltonian_head_taped(o_in, with_grad ? *o_g_in : Tensor(), x_in, &tape);
    ctx->save_for_backward({tape.o, with_grad ? tape.o_g : tape.o, tape.x, tape.aux});
    ctx->saved_data["with_grad"] = with_grad;
    return with_grad ? variable_list{head.h, head.grad} : variable_list{head.h};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const bool with_grad = ctx->saved_data["with_grad"].toBool();
    const HamiltonianTape tape{saved[0], with_grad ? saved[1] : Tensor(), saved[2], saved[3]};
    const HamiltonianAdjoints adj =
        hamiltonian_head_backward(tape, grads[0], with_grad ? grads[1] : Tensor());
    return {adj.o, adj.o_g, adj.x};
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
// The backward runs these lines in reverse (CurvatureRow::backward); the
// forward saves softplus, sigmoid and softplus' of o0 and o2 for it.
struct CurvatureRow {
  // Forward values.
  double q, p, a, c, d, a1, d1, a2, d2, ai[2], ci[2], di[2], aij[2][2], cij[2][2], dij[2][2];
  double v0, v1, v0i[2], v1i[2], v0ij[2][2], v1ij[2][2];

  double a_slope, d_slope;  // softplus' of o0 and o2

  // f: SoftplusColumns of o's columns 0 and 2; r: this row.
  CurvatureRow(const double* o, const double* og, const double* oh, const double* x,
               const SoftplusColumns& f, int64_t r) {
    q = x[0], p = x[1];
    a = f.softplus(0, r), c = o[1], d = f.softplus(1, r);
    a1 = f.sigmoid(0, r), d1 = f.sigmoid(1, r);
    a_slope = f.slope(0, r), d_slope = f.slope(1, r);
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
  void backward(const double* og, const double* oh, const double* gb,
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
    ob[0] = ab * a_slope + a1b * a2 + a2b * a2 * (1.0 - 2.0 * a1);
    ob[1] = cb;
    ob[2] = db * d_slope + d1b * d2 + d2b * d2 * (1.0 - 2.0 * d1);
    xb[0] = qb, xb[1] = pb;
  }
};

}  // namespace

HamiltonianCurvature hamiltonian_curvature_taped(const Tensor& o_in, const Tensor& og_in,
                                                 const Tensor& oh_in, const Tensor& x_in,
                                                 CurvatureTape* tape) {
  const Tensor o = dense(o_in), og = dense(og_in), oh = dense(oh_in), x = dense(x_in);
  const int64_t E = o.size(0), B = o.size(1), rows = E * B;
  Tensor grad = torch::empty({E, B, 2}, o.options()),
         hess = torch::empty({E, B, 2, 2}, o.options());
  const double *po = o.data_ptr<double>(), *pg = og.data_ptr<double>();
  const double *ph = oh.data_ptr<double>(), *px = x.data_ptr<double>();
  double *pgr = grad.data_ptr<double>(), *phs = hess.data_ptr<double>();
  Tensor aux = torch::empty({SoftplusColumns::size(2, rows)}, o.options());
  const SoftplusColumns f = SoftplusColumns::compute(po, 3, {0, 2}, rows, aux.data_ptr<double>());
  for (int64_t r = 0; r < rows; ++r) {
    const CurvatureRow row(po + 3 * r, pg + 6 * r, ph + 12 * r, px + 2 * r, f, r);
    for (int i = 0; i < 2; ++i) {
      pgr[2 * r + i] = row.grad(i);
      for (int j = 0; j < 2; ++j) phs[4 * r + 2 * i + j] = row.hessian(i, j);
    }
  }
  *tape = CurvatureTape{o, og, oh, x, aux};
  return {grad, hess};
}

CurvatureAdjoints hamiltonian_curvature_backward(const CurvatureTape& tape, const Tensor& grad_bar,
                                                 const Tensor& hessian_bar) {
  const Tensor &o = tape.o, &og = tape.o_g, &oh = tape.o_h, &x = tape.x;
  const int64_t rows = o.size(0) * o.size(1);
  const Tensor gb = grad_bar.defined() ? dense(grad_bar) : torch::zeros_like(x);
  const Tensor kb = hessian_bar.defined() ? dense(hessian_bar)
                                          : torch::zeros({o.size(0), o.size(1), 2, 2}, o.options());
  CurvatureAdjoints out{torch::empty_like(o), torch::empty_like(og), torch::empty_like(oh),
                        torch::empty_like(x)};
  const double *po = o.data_ptr<double>(), *pg = og.data_ptr<double>();
  const double *ph = oh.data_ptr<double>(), *px = x.data_ptr<double>();
  const double *pgb = gb.data_ptr<double>(), *pkb = kb.data_ptr<double>();
  double *pob = out.o.data_ptr<double>(), *pogb = out.o_g.data_ptr<double>();
  double *pohb = out.o_h.data_ptr<double>(), *pxb = out.x.data_ptr<double>();
  const SoftplusColumns f = SoftplusColumns::saved(2, rows, tape.aux.data_ptr<double>());
  for (int64_t r = 0; r < rows; ++r) {
    const CurvatureRow row(po + 3 * r, pg + 6 * r, ph + 12 * r, px + 2 * r, f, r);
    row.backward(pg + 6 * r, ph + 12 * r, pgb + 2 * r, pkb + 4 * r, pob + 3 * r, pogb + 6 * r,
                 pohb + 12 * r, pxb + 2 * r);
  }
  return out;
}

namespace {

class CurvatureFunction : public torch::autograd::Function<CurvatureFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const Tensor& o_in, const Tensor& og_in,
                               const Tensor& oh_in, const Tensor& x_in) {
    CurvatureTape tape;
    const HamiltonianCurvature out = hamiltonian_curvature_taped(o_in, og_in, oh_in, x_in, &tape);
    ctx->save_for_backward({tape.o, tape.o_g, tape.o_h, tape.x, tape.aux});
    return {out.grad, out.hessian};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const CurvatureTape tape{saved[0], saved[1], saved[2], saved[3], saved[4]};
    const CurvatureAdjoints adj = hamiltonian_curvature_backward(tape, grads[0], grads[1]);
    return {adj.o, adj.o_g, adj.o_h, adj.x};
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

}  // namespace internal
}  // namespace phnn
