// src/models/general_field_heads.cpp — the field heads of src/models/general_heads.h
// for n states: PHNN-S from the port variables and the L_z outputs, PHNN-JR
// from the effort and the L_R outputs. Plain loops per row; the backward
// formulas are written above each class.
#include "models/fused_heads_common.h"
#include "models/general_heads.h"
#include "models/head_sizes.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {
namespace {

using namespace heads;

// ---------------------------------------------------------------- PHNN-S
// Per row, L = L_z (raw outputs), K strictly lower (the outputs after L's),
// A = K - K^T, W = n_x + n_w + n_u:
//   y = L w,  z = L^T y + A w,  f_i = sum_j S_ij [e; z; u]_j  (i < n_x).
// Backward with f~:  [e~; z~; u~]_j = sum_i f~_i S_ij,
//   y~ = L z~,  L~_ra = y_r z~_a + y~_r w_a,  w~ = L^T y~ + A^T z~,
//   K~_ab = z~_a w_b - z~_b w_a  (a > b).
struct PortRow {
  const double* o;  // L's triangle, then K's
  int nw;
  double a(int r, int c) const { return skew_entry(o, nw, r, c); }  // (K - K^T)_rc
};

// The PHNN-S head's rows for n_x = NX, n_w = NW (head_sizes.h).
template <int NX, int NW>
void s_rows_forward(const double* pe, const double* pu, const double* po, const double* pw,
                    const double* S, int64_t rows, int nx_rt, int nw_rt, int nu, double* pf) {
  const int nx = size_of<NX>(nx_rt), n = count_of<NW>(nw_rt), T = n * n, W = nx + n + nu;
  std::vector<double> heap(NW >= 0 ? 0 : 2 * n);
  double fixed[NW > 0 ? 2 * NW : 1];
  double* y = NW >= 0 ? fixed : heap.data();
  double* z = y + n;
  for (int64_t r = 0; r < rows; ++r) {
    const PortRow port{po + T * r, n};
    const double* wr = pw + n * r;
    lower_times<NW>(port.o, wr, n, y);
    lower_transpose_times<NW>(port.o, y, n, z);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) z[a] += port.a(a, b) * wr[b];
    for (int i = 0; i < nx; ++i) {
      const double* s = S + i * W;
      double acc = 0.0;
      for (int j = 0; j < nx; ++j) acc += s[j] * pe[nx * r + j];
      for (int a = 0; a < n; ++a) acc += s[nx + a] * z[a];
      for (int b = 0; b < nu; ++b) acc += s[nx + n + b] * pu[nu * r + b];
      pf[nx * r + i] = acc;
    }
  }
}

template <int NX, int NW>
void s_rows_backward(const double* po, const double* pw, const double* S, const double* pfb,
                     int64_t rows, int nx_rt, int nw_rt, int nu, double* peb, double* pub,
                     double* pob, double* pwb) {
  const int nx = size_of<NX>(nx_rt), n = count_of<NW>(nw_rt), T = n * n, W = nx + n + nu;
  std::vector<double> adj(W);
  std::vector<double> heap(NW >= 0 ? 0 : 2 * n);
  double fixed[NW > 0 ? 2 * NW : 1];
  double* y = NW >= 0 ? fixed : heap.data();
  double* yb = y + n;
  for (int64_t r = 0; r < rows; ++r) {
    const double* f = pfb + nx * r;
    for (int j = 0; j < W; ++j) {
      double s = 0.0;
      for (int i = 0; i < nx; ++i) s += f[i] * S[i * W + j];
      adj[j] = s;
    }
    for (int j = 0; j < nx; ++j) peb[nx * r + j] = adj[j];
    for (int b = 0; b < nu; ++b) pub[nu * r + b] = adj[nx + n + b];
    const double* zb = adj.data() + nx;
    const PortRow port{po + T * r, n};
    const double* wr = pw + n * r;
    lower_times<NW>(port.o, wr, n, y);
    lower_times<NW>(port.o, zb, n, yb);
    double* ob = pob + T * r;
    for (int i = 0; i < n; ++i)
      for (int a = 0; a <= i; ++a) ob[tri(i, a)] = y[i] * zb[a] + yb[i] * wr[a];
    for (int a = 1; a < n; ++a)
      for (int b = 0; b < a; ++b)
        ob[n * (n + 1) / 2 + a * (a - 1) / 2 + b] = zb[a] * wr[b] - zb[b] * wr[a];
    double* wb = pwb + n * r;
    lower_transpose_times<NW>(port.o, yb, n, wb);
    for (int c = 0; c < n; ++c)
      for (int a = 0; a < n; ++a) wb[c] += port.a(a, c) * zb[a];
  }
}

}  // namespace

Tensor general_s_field_forward(const Tensor& e_in, const Tensor& u_in, const Tensor& o_in,
                               const Tensor& w_in, const std::vector<double>& S, int nw) {
  const Tensor e = dense(e_in), u = rows_like(u_in, e_in), o = dense(o_in), w = dense(w_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1));
  const int n = nw, T = static_cast<int>(o.size(-1)), W = nx + n + nu;
  PHNN_CHECK(static_cast<int>(S.size()) >= nx * W && T == n * n,
             "general_s_field_head: structure or output sizes");
  const int64_t rows = rows_of(e);
  Tensor f = torch::empty_like(e);
  const double *pe = e.data_ptr<double>(), *pu = u.data_ptr<double>();
  const double *po = o.data_ptr<double>(), *pw = w.data_ptr<double>();
  double* pf = f.data_ptr<double>();
  with_size(nx, [&](auto x_size) {
    with_count(n, [&](auto w_count) {
      s_rows_forward<decltype(x_size)::value, decltype(w_count)::value>(pe, pu, po, pw, S.data(),
                                                                        rows, nx, n, nu, pf);
    });
  });
  return f;
}

SFieldAdjoints general_s_field_backward(const Tensor& o_in, const Tensor& w_in,
                                        const std::vector<double>& S, int nx, int n, int nu,
                                        const Tensor& f_bar) {
  const Tensor o = dense(o_in), w = dense(w_in);
  PHNN_CHECK(
      o.size(-1) == static_cast<int64_t>(n) * n && static_cast<int>(S.size()) >= nx * (nx + n + nu),
      "general_s_field_head: structure or output sizes");
  const Tensor fb = dense(f_bar);
  const int64_t E = o.size(0), B = o.size(1), rows = rows_of(o);
  SFieldAdjoints out{torch::empty({E, B, nx}, o.options()), torch::empty({E, B, nu}, o.options()),
                     torch::empty_like(o), torch::empty_like(w)};
  const double *po = o.data_ptr<double>(), *pw = w.data_ptr<double>(), *pfb = fb.data_ptr<double>();
  double *peb = out.e.data_ptr<double>(), *pub = out.u.data_ptr<double>();
  double *pob = out.o.data_ptr<double>(), *pwb = out.w.data_ptr<double>();
  with_size(nx, [&](auto x_size) {
    with_count(n, [&](auto w_count) {
      s_rows_backward<decltype(x_size)::value, decltype(w_count)::value>(
          po, pw, S.data(), pfb, rows, nx, n, nu, peb, pub, pob, pwb);
    });
  });
  return out;
}

namespace {

class SFieldFunction : public torch::autograd::Function<SFieldFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& e, const Tensor& u, const Tensor& o,
                        const Tensor& w, std::vector<double> S, int64_t nw) {
    const Tensor f = general_s_field_forward(e, u, o, w, S, static_cast<int>(nw));
    ctx->save_for_backward({dense(o), dense(w)});
    ctx->saved_data["S"] = S;
    ctx->saved_data["dims"] = std::vector<int64_t>{e.size(-1), nw, u.size(-1)};
    return f;
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const auto dims = ctx->saved_data["dims"].toIntVector();
    const auto adj = general_s_field_backward(
        saved[0], saved[1], ctx->saved_data["S"].toDoubleVector(), static_cast<int>(dims[0]),
        static_cast<int>(dims[1]), static_cast<int>(dims[2]), grads[0]);
    return {adj.e, adj.u, adj.o, adj.w, Tensor(), Tensor()};
  }
};

// --------------------------------------------------------------- PHNN-JR
// Per row, p = [e; u] (m = n_x + n_u), L = L_R:
//   y = L p,  f_i = sum_j J_ij p_j - (L^T y)_i  (i < n_x).
// Backward with f~ (zero beyond n_x), r~ = -f~:
//   y~ = L r~,  L~_rc = r~_c y_r + y~_r p_c,  p~ = J^T f~ + L^T y~.
// The JR head's rows for n_x = NX, n_u = NU (head_sizes.h; m = n_x + n_u).
template <int NX, int NU>
void jr_rows_forward(const double* pe, const double* pu, const double* po, const double* J,
                     int64_t rows, int nx_rt, int nu_rt, double* pf) {
  constexpr int MX = NX > 0 && NU >= 0 ? NX + NU : 0;
  const int nx = size_of<NX>(nx_rt), nu = count_of<NU>(nu_rt), m = nx + nu;
  const int K = m * (m + 1) / 2;
  std::vector<double> heap(MX > 0 ? 0 : 3 * m);
  double fixed[MX > 0 ? 3 * MX : 1];
  double* p = MX > 0 ? fixed : heap.data();
  double *y = p + m, *rr = p + 2 * m;
  for (int64_t r = 0; r < rows; ++r) {
    for (int j = 0; j < nx; ++j) p[j] = pe[nx * r + j];
    for (int b = 0; b < nu; ++b) p[nx + b] = pu[nu * r + b];
    lower_times<MX>(po + K * r, p, m, y);
    lower_transpose_times<MX>(po + K * r, y, m, rr);
    for (int i = 0; i < nx; ++i) {
      double s = 0.0;
      for (int j = 0; j < m; ++j) s += J[i * m + j] * p[j];
      pf[nx * r + i] = s - rr[i];
    }
  }
}

template <int NX, int NU>
void jr_rows_backward(const double* pe, const double* pu, const double* po, const double* J,
                      const double* pfb, int64_t rows, int nx_rt, int nu_rt, double* peb,
                      double* pub, double* pob) {
  constexpr int MX = NX > 0 && NU >= 0 ? NX + NU : 0;
  const int nx = size_of<NX>(nx_rt), nu = count_of<NU>(nu_rt), m = nx + nu;
  const int K = m * (m + 1) / 2;
  std::vector<double> heap(MX > 0 ? 0 : 5 * m);
  double fixed[MX > 0 ? 5 * MX : 1];
  double* p = MX > 0 ? fixed : heap.data();
  double *y = p + m, *rb = p + 2 * m, *yb = p + 3 * m, *pb = p + 4 * m;
  std::fill(rb, rb + m, 0.0);
  for (int64_t r = 0; r < rows; ++r) {
    for (int j = 0; j < nx; ++j) p[j] = pe[nx * r + j], rb[j] = -pfb[nx * r + j];
    for (int b = 0; b < nu; ++b) p[nx + b] = pu[nu * r + b];
    const double* L = po + K * r;
    lower_times<MX>(L, p, m, y);
    lower_times<MX>(L, rb, m, yb);
    double* ob = pob + K * r;
    for (int i = 0; i < m; ++i)
      for (int c = 0; c <= i; ++c) ob[tri(i, c)] = rb[c] * y[i] + yb[i] * p[c];
    lower_transpose_times<MX>(L, yb, m, pb);
    for (int j = 0; j < m; ++j) {
      double s = 0.0;
      for (int i = 0; i < nx; ++i) s += pfb[nx * r + i] * J[i * m + j];
      pb[j] += s;
    }
    for (int j = 0; j < nx; ++j) peb[nx * r + j] = pb[j];
    for (int b = 0; b < nu; ++b) pub[nu * r + b] = pb[nx + b];
  }
}

}  // namespace

Tensor general_jr_field_forward(const Tensor& e_in, const Tensor& u_in, const Tensor& o_in,
                                const std::vector<double>& J) {
  const Tensor e = dense(e_in), u = rows_like(u_in, e_in), o = dense(o_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1)), m = nx + nu;
  PHNN_CHECK(static_cast<int>(J.size()) == m * m && o.size(-1) == m * (m + 1) / 2,
             "general_jr_field_head: structure or output sizes");
  const int64_t rows = rows_of(e);
  Tensor f = torch::empty_like(e);
  const double *pe = e.data_ptr<double>(), *pu = u.data_ptr<double>(), *po = o.data_ptr<double>();
  double* pf = f.data_ptr<double>();
  with_size(nx, [&](auto x_size) {
    with_count(nu, [&](auto u_count) {
      jr_rows_forward<decltype(x_size)::value, decltype(u_count)::value>(pe, pu, po, J.data(), rows,
                                                                         nx, nu, pf);
    });
  });
  return f;
}

JrFieldAdjoints general_jr_field_backward(const Tensor& e_in, const Tensor& u_in,
                                          const Tensor& o_in, const std::vector<double>& J,
                                          const Tensor& f_bar) {
  const Tensor e = dense(e_in), u = rows_like(u_in, e_in), o = dense(o_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1));
  const Tensor fb = dense(f_bar);
  const int64_t rows = rows_of(e);
  JrFieldAdjoints out{torch::empty_like(e), torch::empty_like(o), torch::empty_like(u)};
  const double *pe = e.data_ptr<double>(), *pu = u.data_ptr<double>(), *po = o.data_ptr<double>();
  const double* pfb = fb.data_ptr<double>();
  double *peb = out.effort.data_ptr<double>(), *pub = out.u.data_ptr<double>();
  double* pob = out.o.data_ptr<double>();
  with_size(nx, [&](auto x_size) {
    with_count(nu, [&](auto u_count) {
      jr_rows_backward<decltype(x_size)::value, decltype(u_count)::value>(
          pe, pu, po, J.data(), pfb, rows, nx, nu, peb, pub, pob);
    });
  });
  return out;
}

namespace {

class JrFieldFunction : public torch::autograd::Function<JrFieldFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& e, const Tensor& u, const Tensor& o,
                        std::vector<double> J) {
    const Tensor f = general_jr_field_forward(e, u, o, J);
    ctx->save_for_backward({dense(e), rows_like(u, e), dense(o)});
    ctx->saved_data["J"] = J;
    return f;
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const auto adj = general_jr_field_backward(saved[0], saved[1], saved[2],
                                               ctx->saved_data["J"].toDoubleVector(), grads[0]);
    return {adj.effort, adj.u, adj.o, Tensor()};
  }
};

}  // namespace

Tensor general_s_field_head(const Tensor& e, const Tensor& u, const Tensor& o, const Tensor& w,
                            const std::vector<double>& S, int n_w) {
  return SFieldFunction::apply(e, u, o, w, S, static_cast<int64_t>(n_w));
}

Tensor general_jr_field_head(const Tensor& e, const Tensor& u, const Tensor& o,
                             const std::vector<double>& J) {
  return JrFieldFunction::apply(e, u, o, J);
}

}  // namespace internal
}  // namespace phnn
