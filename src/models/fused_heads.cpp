// src/models/fused_heads.cpp — forward and backward of the closed-form field
// heads (PHNN-JR and its jet, PHNN-S), row by row (a row = one member and one
// batch element). The Hamiltonian heads: fused_heads_hamiltonian.cpp; the
// Gonzalez quotient: the n-state head of general_heads.cpp.
#include "models/fused_heads.h"

#include "models/fused_heads_common.h"

namespace phnn {
namespace internal {
namespace {

using namespace heads;

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

}  // namespace

Tensor jr_field_forward(const Tensor& e_in, const Tensor& o_in, const Tensor& u_in,
                        const std::array<std::array<double, 3>, 3>& J) {
  const Tensor e = dense(e_in), o = dense(o_in), u = dense(u_in);
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
  return f;
}

JrFieldAdjoints jr_field_backward(const Tensor& e_in, const Tensor& o_in, const Tensor& u_in,
                                  const std::array<std::array<double, 3>, 3>& J,
                                  const Tensor& f_bar_in) {
  const Tensor e = dense(e_in), o = dense(o_in), u = dense(u_in), fb = dense(f_bar_in);
  const int64_t rows = e.size(0) * e.size(1);
  JrFieldAdjoints out{torch::empty_like(e), torch::empty_like(o), torch::empty_like(u)};
  const double *pe = e.data_ptr<double>(), *po = o.data_ptr<double>(), *pu = u.data_ptr<double>();
  const double* pfb = fb.data_ptr<double>();
  double *peb = out.effort.data_ptr<double>(), *pob = out.o.data_ptr<double>();
  double* pub = out.u.data_ptr<double>();
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
  return out;
}

namespace {

class JrFieldFunction : public torch::autograd::Function<JrFieldFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& effort_in, const Tensor& o_in,
                        const Tensor& u_in, std::array<std::array<double, 3>, 3> J) {
    const Tensor e = dense(effort_in), o = dense(o_in), u = dense(u_in);
    ctx->save_for_backward({e, o, u});
    save_matrix(ctx, J);
    return jr_field_forward(e, o, u, J);
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const JrFieldAdjoints adj =
        jr_field_backward(saved[0], saved[1], saved[2], load_matrix<3, 3>(ctx), grads[0]);
    return {adj.effort, adj.o, adj.u, Tensor()};
  }
};

}  // namespace

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

JrFieldJet jr_field_jet_forward(const Tensor& e_in, const Tensor& k_in, const Tensor& o_in,
                                const Tensor& og_in, const Tensor& u_in,
                                const std::array<std::array<double, 3>, 3>& J) {
  const Tensor e = dense(e_in), K = dense(k_in), o = dense(o_in), og = dense(og_in),
               u = dense(u_in);
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
    for (int c = 0; c < 2; ++c)
      pf[2 * r + c] = J[c][0] * eps[0] + J[c][1] * eps[1] + J[c][2] * eps[2] - rv[c];
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
  return {f, fg};
}

JrFieldJetAdjoints jr_field_jet_backward(const Tensor& e, const Tensor& K, const Tensor& o,
                                         const Tensor& og, const Tensor& u,
                                         const std::array<std::array<double, 3>, 3>& J,
                                         const Tensor& f_bar, const Tensor& g_bar) {
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  const Tensor fb = f_bar.defined() ? dense(f_bar) : torch::zeros_like(e);
  const Tensor fgb = g_bar.defined() ? dense(g_bar) : torch::zeros({E, B, 2, 2}, e.options());
  Tensor e_bar = torch::empty_like(e), k_bar = torch::empty_like(K), o_bar = torch::empty_like(o);
  Tensor og_bar = torch::empty_like(og), u_bar = torch::empty_like(u);
  const double *pe = e.data_ptr<double>(), *pk = K.data_ptr<double>(), *po = o.data_ptr<double>();
  const double *pog = og.data_ptr<double>(), *pu = u.data_ptr<double>();
  const double *pfb = fb.data_ptr<double>(), *pfgb = fgb.data_ptr<double>();
  double *peb = e_bar.data_ptr<double>(), *pkb = k_bar.data_ptr<double>();
  double *pob = o_bar.data_ptr<double>(), *pogb = og_bar.data_ptr<double>(),
         *pub = u_bar.data_ptr<double>();
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
        pkb[4 * r + 2 * i + a] =
            tmp[a] + J[0][a] * pfgb[4 * r + 2 * i] + J[1][a] * pfgb[4 * r + 2 * i + 1];
      }
    }
  }
  return {e_bar, k_bar, o_bar, og_bar, u_bar};
}

namespace {

class JrJetFunction : public torch::autograd::Function<JrJetFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const Tensor& e_in, const Tensor& k_in,
                               const Tensor& o_in, const Tensor& og_in, const Tensor& u_in,
                               std::array<std::array<double, 3>, 3> J) {
    const Tensor e = dense(e_in), K = dense(k_in), o = dense(o_in), og = dense(og_in), u = dense(u_in);
    const JrFieldJet out = jr_field_jet_forward(e, K, o, og, u, J);
    ctx->save_for_backward({e, K, o, og, u});
    save_matrix(ctx, J);
    return {out.f, out.g};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const auto adj = jr_field_jet_backward(saved[0], saved[1], saved[2], saved[3], saved[4],
                                           load_matrix<3, 3>(ctx), grads[0], grads[1]);
    return {adj.effort, adj.effort_g, adj.o, adj.o_g, adj.u, Tensor()};
  }
};

// ---------------------------------------------------------------- PHNN-S
// Per row: w = S_w0 e0 + S_w1 e1 + S_w3 u (S_ww = 0), and from w and the L_z
// output l: f_i = S_i0 e0 + S_i1 e1 + S_i2 l^2 w + S_i3 u (i = 0, 1).
// Backward: e~_j += sum_i f~_i S_ij, u~ += sum_i f~_i S_i3,
//   l~ = 2 l w sum_i f~_i S_i2, w~ = l^2 sum_i f~_i S_i2 (and w's own rule).
using StructureRows = std::array<std::array<double, 4>, 4>;

}  // namespace

Tensor phnn_s_w_forward(const Tensor& e_in, const Tensor& u_in, const std::array<double, 3>& s) {
  const Tensor e = dense(e_in), u = dense(u_in);
  const int64_t rows = e.size(0) * e.size(1);
  Tensor w = torch::empty({e.size(0), e.size(1), 1}, e.options());
  const double *pe = e.data_ptr<double>(), *pu = u.data_ptr<double>();
  double* pw = w.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) pw[r] = s[0] * pe[2 * r] + s[1] * pe[2 * r + 1] + s[2] * pu[r];
  return w;
}

PhnnSWAdjoints phnn_s_w_backward(const std::array<double, 3>& s, const Tensor& w_bar) {
  const Tensor wb = dense(w_bar);
  const int64_t E = wb.size(0), B = wb.size(1), rows = E * B;
  PhnnSWAdjoints out{torch::empty({E, B, 2}, wb.options()), torch::empty({E, B, 1}, wb.options())};
  const double* pwb = wb.data_ptr<double>();
  double *peb = out.effort.data_ptr<double>(), *pub = out.u.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    peb[2 * r] = s[0] * pwb[r], peb[2 * r + 1] = s[1] * pwb[r], pub[r] = s[2] * pwb[r];
  }
  return out;
}

Tensor phnn_s_field_forward(const Tensor& e_in, const Tensor& u_in, const Tensor& l_in,
                            const Tensor& w_in, const StructureRows& S) {
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
  return f;
}

PhnnSFieldAdjoints phnn_s_field_backward(const Tensor& l_in, const Tensor& w_in,
                                         const StructureRows& S, const Tensor& f_bar) {
  const Tensor l = dense(l_in), w = dense(w_in), fb = dense(f_bar);
  const int64_t E = l.size(0), B = l.size(1), rows = E * B;
  PhnnSFieldAdjoints out{torch::empty({E, B, 2}, l.options()), torch::empty_like(l),
                         torch::empty_like(l), torch::empty_like(w)};
  const double *pl = l.data_ptr<double>(), *pw = w.data_ptr<double>(), *pfb = fb.data_ptr<double>();
  double *peb = out.effort.data_ptr<double>(), *pub = out.u.data_ptr<double>();
  double *plb = out.l.data_ptr<double>(), *pwb = out.w.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    const double f0 = pfb[2 * r], f1 = pfb[2 * r + 1];
    peb[2 * r] = f0 * S[0][0] + f1 * S[1][0];
    peb[2 * r + 1] = f0 * S[0][1] + f1 * S[1][1];
    pub[r] = f0 * S[0][3] + f1 * S[1][3];
    const double zb = f0 * S[0][2] + f1 * S[1][2];
    plb[r] = 2.0 * pl[r] * pw[r] * zb;
    pwb[r] = pl[r] * pl[r] * zb;
  }
  return out;
}

namespace {

class PhnnSWFunction : public torch::autograd::Function<PhnnSWFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& e_in, const Tensor& u_in,
                        std::array<double, 3> s) {
    ctx->saved_data["s"] = std::vector<double>(s.begin(), s.end());
    return phnn_s_w_forward(e_in, u_in, s);
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const std::vector<double> s = ctx->saved_data["s"].toDoubleVector();
    const PhnnSWAdjoints adj = phnn_s_w_backward({s[0], s[1], s[2]}, grads[0]);
    return {adj.effort, adj.u, Tensor()};
  }
};

class PhnnSFieldFunction : public torch::autograd::Function<PhnnSFieldFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& e_in, const Tensor& u_in,
                        const Tensor& l_in, const Tensor& w_in, StructureRows S) {
    const Tensor l = dense(l_in), w = dense(w_in);
    ctx->save_for_backward({l, w});
    save_matrix(ctx, S);
    return phnn_s_field_forward(e_in, u_in, l, w, S);
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const PhnnSFieldAdjoints adj =
        phnn_s_field_backward(saved[0], saved[1], load_matrix<4, 4>(ctx), grads[0]);
    return {adj.effort, adj.u, adj.l, adj.w, Tensor()};
  }
};

}  // namespace

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

}  // namespace internal
}  // namespace phnn
