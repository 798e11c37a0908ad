// src/models/general_field_heads.cpp — the field heads of src/models/general_heads.h
// for n states: PHNN-S from the port variables and the L_z outputs, PHNN-JR
// from the effort and the L_R outputs. Plain loops per row; the backward
// formulas are written above each class.
#include "models/fused_heads_common.h"
#include "models/general_heads.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {
namespace {

using namespace heads;

// y = L x and x~ = L^T y~ for a lower-triangular L stored as its row-major triangle.
void lower_times(const double* L, const double* x, int n, double* y) {
  for (int r = 0; r < n; ++r) {
    double s = 0.0;
    for (int c = 0; c <= r; ++c) s += L[tri(r, c)] * x[c];
    y[r] = s;
  }
}
void lower_transpose_times(const double* L, const double* y, int n, double* x) {
  for (int c = 0; c < n; ++c) {
    double s = 0.0;
    for (int r = c; r < n; ++r) s += L[tri(r, c)] * y[r];
    x[c] = s;
  }
}

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
  double a(int r, int c) const {  // (K - K^T)_rc
    if (r == c) return 0.0;
    const int base = nw * (nw + 1) / 2;
    return r > c ? o[base + r * (r - 1) / 2 + c] : -o[base + c * (c - 1) / 2 + r];
  }
};

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
  std::vector<double> y(n), z(n);
  for (int64_t r = 0; r < rows; ++r) {
    const PortRow port{po + T * r, n};
    const double* wr = pw + n * r;
    lower_times(port.o, wr, n, y.data());
    lower_transpose_times(port.o, y.data(), n, z.data());
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) z[a] += port.a(a, b) * wr[b];
    for (int i = 0; i < nx; ++i) {
      const double* s = S.data() + i * W;
      double acc = 0.0;
      for (int j = 0; j < nx; ++j) acc += s[j] * pe[nx * r + j];
      for (int a = 0; a < n; ++a) acc += s[nx + a] * z[a];
      for (int b = 0; b < nu; ++b) acc += s[nx + n + b] * pu[nu * r + b];
      pf[nx * r + i] = acc;
    }
  }
  return f;
}

SFieldAdjoints general_s_field_backward(const Tensor& o_in, const Tensor& w_in,
                                        const std::vector<double>& S, int nx, int n, int nu,
                                        const Tensor& f_bar) {
  const Tensor o = dense(o_in), w = dense(w_in);
  const int T = static_cast<int>(o.size(-1)), W = nx + n + nu;
  const Tensor fb = dense(f_bar);
  const int64_t E = o.size(0), B = o.size(1), rows = rows_of(o);
  SFieldAdjoints out{torch::empty({E, B, nx}, o.options()), torch::empty({E, B, nu}, o.options()),
                     torch::empty_like(o), torch::empty_like(w)};
  const double *po = o.data_ptr<double>(), *pw = w.data_ptr<double>(), *pfb = fb.data_ptr<double>();
  double *peb = out.e.data_ptr<double>(), *pub = out.u.data_ptr<double>();
  double *pob = out.o.data_ptr<double>(), *pwb = out.w.data_ptr<double>();
  std::vector<double> adj(W), y(n), yb(n);
  for (int64_t r = 0; r < rows; ++r) {
    const double* f = pfb + nx * r;
    for (int j = 0; j < W; ++j) {
      double s = 0.0;
      for (int i = 0; i < nx; ++i) s += f[i] * S[static_cast<std::size_t>(i * W + j)];
      adj[j] = s;
    }
    for (int j = 0; j < nx; ++j) peb[nx * r + j] = adj[j];
    for (int b = 0; b < nu; ++b) pub[nu * r + b] = adj[nx + n + b];
    const double* zb = adj.data() + nx;
    const PortRow port{po + T * r, n};
    const double* wr = pw + n * r;
    lower_times(port.o, wr, n, y.data());
    lower_times(port.o, zb, n, yb.data());
    double* ob = pob + T * r;
    for (int i = 0; i < n; ++i)
      for (int a = 0; a <= i; ++a) ob[tri(i, a)] = y[i] * zb[a] + yb[i] * wr[a];
    for (int a = 1; a < n; ++a)
      for (int b = 0; b < a; ++b)
        ob[n * (n + 1) / 2 + a * (a - 1) / 2 + b] = zb[a] * wr[b] - zb[b] * wr[a];
    double* wb = pwb + n * r;
    lower_transpose_times(port.o, yb.data(), n, wb);
    for (int c = 0; c < n; ++c)
      for (int a = 0; a < n; ++a) wb[c] += port.a(a, c) * zb[a];
  }
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
}  // namespace

Tensor general_jr_field_forward(const Tensor& e_in, const Tensor& u_in, const Tensor& o_in,
                                const std::vector<double>& J) {
  const Tensor e = dense(e_in), u = rows_like(u_in, e_in), o = dense(o_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1)), m = nx + nu;
  PHNN_CHECK(static_cast<int>(J.size()) == m * m && o.size(-1) == m * (m + 1) / 2,
             "general_jr_field_head: structure or output sizes");
  const int K = m * (m + 1) / 2;
  const int64_t rows = rows_of(e);
  Tensor f = torch::empty_like(e);
  const double *pe = e.data_ptr<double>(), *pu = u.data_ptr<double>(), *po = o.data_ptr<double>();
  double* pf = f.data_ptr<double>();
  std::vector<double> p(m), y(m), rr(m);
  for (int64_t r = 0; r < rows; ++r) {
    for (int j = 0; j < nx; ++j) p[j] = pe[nx * r + j];
    for (int b = 0; b < nu; ++b) p[nx + b] = pu[nu * r + b];
    lower_times(po + K * r, p.data(), m, y.data());
    lower_transpose_times(po + K * r, y.data(), m, rr.data());
    for (int i = 0; i < nx; ++i) {
      double s = 0.0;
      for (int j = 0; j < m; ++j) s += J[static_cast<std::size_t>(i * m + j)] * p[j];
      pf[nx * r + i] = s - rr[i];
    }
  }
  return f;
}

JrFieldAdjoints general_jr_field_backward(const Tensor& e_in, const Tensor& u_in,
                                          const Tensor& o_in, const std::vector<double>& J,
                                          const Tensor& f_bar) {
  const Tensor e = dense(e_in), u = rows_like(u_in, e_in), o = dense(o_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1)), m = nx + nu;
  const int K = m * (m + 1) / 2;
  const Tensor fb = dense(f_bar);
  const int64_t rows = rows_of(e);
  JrFieldAdjoints out{torch::empty_like(e), torch::empty_like(o), torch::empty_like(u)};
  const double *pe = e.data_ptr<double>(), *pu = u.data_ptr<double>(), *po = o.data_ptr<double>();
  const double* pfb = fb.data_ptr<double>();
  double *peb = out.effort.data_ptr<double>(), *pub = out.u.data_ptr<double>();
  double* pob = out.o.data_ptr<double>();
  std::vector<double> p(m), y(m), rb(m, 0.0), yb(m), pb(m);
  for (int64_t r = 0; r < rows; ++r) {
    for (int j = 0; j < nx; ++j) p[j] = pe[nx * r + j], rb[j] = -pfb[nx * r + j];
    for (int b = 0; b < nu; ++b) p[nx + b] = pu[nu * r + b];
    const double* L = po + K * r;
    lower_times(L, p.data(), m, y.data());
    lower_times(L, rb.data(), m, yb.data());
    double* ob = pob + K * r;
    for (int i = 0; i < m; ++i)
      for (int c = 0; c <= i; ++c) ob[tri(i, c)] = rb[c] * y[i] + yb[i] * p[c];
    lower_transpose_times(L, yb.data(), m, pb.data());
    for (int j = 0; j < m; ++j) {
      double s = 0.0;
      for (int i = 0; i < nx; ++i) s += pfb[nx * r + i] * J[static_cast<std::size_t>(i * m + j)];
      pb[j] += s;
    }
    for (int j = 0; j < nx; ++j) peb[nx * r + j] = pb[j];
    for (int b = 0; b < nu; ++b) pub[nu * r + b] = pb[nx + b];
  }
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
