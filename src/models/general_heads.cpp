// src/models/general_heads.cpp — the n-dimensional fused heads of
// src/models/general_heads.h: the Cholesky-form Hamiltonian with its
// gradient, the Gonzalez DG, the PHNN-S port map and field, the PHNN-JR
// field. Plain loops per row over small n; the backward formulas are written
// above each class.
// Size: the Hamiltonian head's two modes (gradH from L_H's jet, or the
// cotangent of reverse mode) share its row loops and tape.
#include "models/general_heads.h"

#include <algorithm>
#include <vector>

#include "models/fused_heads_common.h"
#include "models/head_sizes.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {
namespace {

using namespace heads;

// ------------------------------------------------------------ Hamiltonian
// Per row, with L_rc = o_k (k = tri(r, c)), softplus(o_k) on the diagonal,
// s_k = sigmoid(o_k) on the diagonal and 1 off it:
//   v = L x,  H = |v|^2 / 2,  c_k = v_r s_k x_c,
//   gradH_i = (L^T v)_i + sum_k o_g[i][k] c_k.
// Backward with adjoints H~, g~ (c~_k = sum_i g~_i o_g[i][k]):
//   o_g~[i][k] = g~_i c_k
//   v~_r = H~ v_r + sum_{c<=r} (g~_c L_rc + c~_k s_k x_c)
//   L~_rc = g~_c v_r + v~_r x_c
//   x~_c = sum_{r>=c} (c~_k v_r s_k + v~_r L_rc)
//   o~_k = L~_rc off the diagonal; L~_rr softplus'(o_k) + c~_k v_r x_r s_k (1 - s_k) on it.
// The forward keeps (softplus, sigmoid, softplus') of every diagonal output.
struct LowerFactor {
  const double* o;
  const double* aux;  // 3 per diagonal entry
  double entry(int r, int c) const { return r == c ? aux[3 * r] : o[tri(r, c)]; }
  double sig(int r, int c) const { return r == c ? aux[3 * r + 1] : 1.0; }
};

template <int N>
void lower_times(const LowerFactor& L, const double* x, int n_rt, double* v) {
  const int n = size_of<N>(n_rt);
  for (int r = 0; r < n; ++r) {
    double s = 0.0;
    for (int c = 0; c <= r; ++c) s += L.entry(r, c) * x[c];
    v[r] = s;
  }
}

// H (and gradH when pog is set) of every row, the diagonal's softplus
// columns f saved into pa (formulas above).
// Reverse mode (pc set, pog null): the cotangent c into pc and L^T v into pg.
template <int N>
void hamiltonian_rows_forward(const double* po, const double* px, const double* pog,
                              const SoftplusColumns& f, int64_t rows, int n_rt, double* pa,
                              double* ph, double* pg, double* pc = nullptr) {
  const int n = size_of<N>(n_rt), K = n * (n + 1) / 2;
  std::vector<double> heap(N > 0 ? 0 : n + K);
  double fixed[N > 0 ? N + N * (N + 1) / 2 : 1];
  double* v = N > 0 ? fixed : heap.data();
  double* c = v + n;
  for (int64_t r = 0; r < rows; ++r) {
    double* a = pa + 3 * n * r;
    for (int i = 0; i < n; ++i)
      a[3 * i] = f.softplus(i, r), a[3 * i + 1] = f.sigmoid(i, r), a[3 * i + 2] = f.slope(i, r);
    const LowerFactor L{po + K * r, a};
    const double* xr = px + n * r;
    lower_times<N>(L, xr, n, v);
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += v[i] * v[i];
    ph[r] = 0.5 * s;
    if (!pog && !pc) continue;
    double* cr = pc ? pc + K * r : c;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j <= i; ++j) cr[tri(i, j)] = v[i] * L.sig(i, j) * xr[j];
    const double* og = pog ? pog + static_cast<int64_t>(n) * K * r : nullptr;
    for (int i = 0; i < n; ++i) {
      double g = 0.0;
      for (int k = i; k < n; ++k) g += L.entry(k, i) * v[k];
      for (int k = 0; og && k < K; ++k) g += og[i * K + k] * cr[k];
      pg[n * r + i] = g;
    }
  }
}

}  // namespace

namespace {

// H, and gradH from o_g (forward mode) or, with `cotangent`, the cotangent c
// [E, B, K] and L^T v in `grad` (reverse mode); what the backward reads in *tape.
struct HamiltonianRows {
  Tensor h, grad, c;
};
HamiltonianRows hamiltonian_forward(const Tensor& o_in, const Tensor& o_g_in, const Tensor& x_in,
                                    bool cotangent, HamiltonianTape* tape) {
  const Tensor o = dense(o_in), x = dense(x_in);
  const bool with_grad = o_g_in.defined();
  const Tensor o_g = with_grad ? dense(o_g_in) : Tensor();
  const int n = static_cast<int>(x.size(-1)), K = static_cast<int>(o.size(-1));
  PHNN_CHECK(K == n * (n + 1) / 2,
             "general_hamiltonian_head: " << K << " outputs for " << n << " states");
  const int64_t rows = rows_of(o);
  HamiltonianRows out{torch::empty({o.size(0), o.size(1), 1}, o.options()),
                      with_grad || cotangent ? torch::empty_like(x) : Tensor(),
                      cotangent ? torch::empty_like(o) : Tensor()};
  Tensor aux = torch::empty({rows, 3 * n}, o.options());
  const double *po = o.data_ptr<double>(), *px = x.data_ptr<double>();
  const double* pog = with_grad ? o_g.data_ptr<double>() : nullptr;
  double *ph = out.h.data_ptr<double>(), *pa = aux.data_ptr<double>();
  double* pg = out.grad.defined() ? out.grad.data_ptr<double>() : nullptr;
  double* pc = cotangent ? out.c.data_ptr<double>() : nullptr;
  std::vector<int> diagonal(n);
  for (int i = 0; i < n; ++i) diagonal[i] = tri(i, i);
  thread_local std::vector<double> columns;
  columns.resize(static_cast<std::size_t>(SoftplusColumns::size(n, rows)));
  const SoftplusColumns f = SoftplusColumns::compute(po, K, diagonal, rows, columns.data());
  with_size(n, [&](auto size) {
    hamiltonian_rows_forward<decltype(size)::value>(po, px, pog, f, rows, n, pa, ph, pg, pc);
  });
  *tape = HamiltonianTape{o, o_g, x, aux};
  return out;
}

}  // namespace

HamiltonianHead general_hamiltonian_forward(const Tensor& o, const Tensor& o_g, const Tensor& x,
                                            HamiltonianTape* tape) {
  const HamiltonianRows r = hamiltonian_forward(o, o_g, x, false, tape);
  return {r.h, r.grad};
}

HamiltonianCotangent general_hamiltonian_cotangent(const Tensor& o, const Tensor& x,
                                                   HamiltonianTape* tape) {
  const HamiltonianRows r = hamiltonian_forward(o, Tensor(), x, true, tape);
  return {r.h, r.c, r.grad};
}

namespace {

// The backward's rows: o_g~, then v~, x~ and o~ of one row (formulas above);
// `work` holds 3 n + K doubles.
// Reverse mode: og null and cbr the given c~ of the row.
template <int N>
void hamiltonian_row_backward(const LowerFactor& L, const double* xr, const double* og,
                              const double* gbr, double hb, int n_rt, double* ogb, double* ob,
                              double* xb, double* work, const double* cbr = nullptr) {
  const int n = size_of<N>(n_rt), K = n * (n + 1) / 2;
  double fixed[N > 0 ? 3 * N + N * (N + 1) / 2 : 1];
  double* w = N > 0 ? fixed : work;
  double *v = w, *gb = w + n, *vb = w + 2 * n, *cb = w + 3 * n;
  std::fill(gb, gb + n, 0.0);
  std::fill(cb, cb + K, 0.0);
  lower_times<N>(L, xr, n, v);
  if (cbr) {
    for (int i = 0; i < n; ++i) gb[i] = gbr[i];
    for (int k = 0; k < K; ++k) cb[k] = cbr[k];
  } else if (gbr) {
    for (int i = 0; i < n; ++i) gb[i] = gbr[i];
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j <= i; ++j) {
        const int k = tri(i, j);
        const double ck = v[i] * L.sig(i, j) * xr[j];
        double s = 0.0;
        for (int d = 0; d < n; ++d) {
          s += gb[d] * og[d * K + k];
          ogb[d * K + k] = gb[d] * ck;
        }
        cb[k] = s;
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    double s = hb * v[i];
    for (int c = 0; c <= i; ++c) s += gb[c] * L.entry(i, c) + cb[tri(i, c)] * L.sig(i, c) * xr[c];
    vb[i] = s;
  }
  for (int c = 0; c < n; ++c) {
    double s = 0.0;
    for (int i = c; i < n; ++i) s += cb[tri(i, c)] * v[i] * L.sig(i, c) + vb[i] * L.entry(i, c);
    xb[c] = s;
  }
  for (int i = 0; i < n; ++i) {
    for (int c = 0; c <= i; ++c) {
      const int k = tri(i, c);
      const double l_bar = gb[c] * v[i] + vb[i] * xr[c];
      if (c < i) {
        ob[k] = l_bar;
      } else {
        const double s = L.aux[3 * i + 1];
        ob[k] = l_bar * L.aux[3 * i + 2] + cb[k] * v[i] * xr[i] * s * (1.0 - s);
      }
    }
  }
}

}  // namespace

HamiltonianAdjoints general_hamiltonian_cotangent_backward(const HamiltonianTape& tape,
                                                           const Tensor& h_bar_in,
                                                           const Tensor& g_bar_in,
                                                           const Tensor& c_bar_in) {
  const Tensor &o = tape.o, &x = tape.x, &aux = tape.aux;
  const bool with_grad = tape.o_g.defined(), reverse = c_bar_in.defined();
  PHNN_CHECK(!reverse || (!with_grad && g_bar_in.defined()),
             "general_hamiltonian_cotangent_backward: c~ goes with a reverse-mode tape and gradH~");
  const Tensor c_bar = reverse ? dense(c_bar_in) : Tensor();
  const int n = static_cast<int>(x.size(-1)), K = static_cast<int>(o.size(-1));
  const int64_t rows = rows_of(o);
  const Tensor h_bar = h_bar_in.defined() ? dense(h_bar_in)
                                          : torch::zeros({o.size(0), o.size(1), 1}, o.options());
  const Tensor g_bar = (with_grad || reverse) && g_bar_in.defined() ? dense(g_bar_in) : Tensor();
  Tensor o_bar = torch::empty_like(o), x_bar = torch::empty_like(x);
  Tensor o_g_bar = with_grad ? torch::zeros_like(tape.o_g) : Tensor();
  const double *po = o.data_ptr<double>(), *px = x.data_ptr<double>();
  const double *phb = h_bar.data_ptr<double>(), *pa = aux.data_ptr<double>();
  const double* pog = g_bar.defined() && with_grad ? tape.o_g.data_ptr<double>() : nullptr;
  const double* pgb = g_bar.defined() ? g_bar.data_ptr<double>() : nullptr;
  double* pogb = g_bar.defined() && with_grad ? o_g_bar.data_ptr<double>() : nullptr;
  const double* pcb = reverse ? c_bar.data_ptr<double>() : nullptr;
  double *pob = o_bar.data_ptr<double>(), *pxb = x_bar.data_ptr<double>();
  const int64_t per_row = static_cast<int64_t>(n) * K;
  std::vector<double> work(static_cast<std::size_t>(3 * n + K));
  with_size(n, [&](auto size) {
    constexpr int N = decltype(size)::value;
    for (int64_t r = 0; r < rows; ++r) {
      hamiltonian_row_backward<N>(LowerFactor{po + K * r, pa + 3 * n * r}, px + n * r,
                                  pog ? pog + per_row * r : nullptr, pgb ? pgb + n * r : nullptr,
                                  phb[r], n, pogb ? pogb + per_row * r : nullptr, pob + K * r,
                                  pxb + n * r, work.data(), pcb ? pcb + K * r : nullptr);
    }
  });
  return {o_bar, o_g_bar, x_bar};
}

HamiltonianAdjoints general_hamiltonian_backward(const HamiltonianTape& tape, const Tensor& h_bar,
                                                 const Tensor& g_bar) {
  return general_hamiltonian_cotangent_backward(tape, h_bar, g_bar, Tensor());
}

namespace {

class GeneralHamiltonianFunction
    : public torch::autograd::Function<GeneralHamiltonianFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const Tensor& o,
                               const c10::optional<Tensor>& o_g, const Tensor& x) {
    HamiltonianTape tape;
    const auto out = general_hamiltonian_forward(o, o_g.has_value() ? *o_g : Tensor(), x, &tape);
    const bool with_grad = tape.o_g.defined();
    ctx->save_for_backward({tape.o, with_grad ? tape.o_g : tape.o, tape.x, tape.aux});
    ctx->saved_data["with_grad"] = with_grad;
    return with_grad ? variable_list{out.h, out.grad} : variable_list{out.h};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const bool with_grad = ctx->saved_data["with_grad"].toBool();
    const HamiltonianTape tape{saved[0], with_grad ? saved[1] : Tensor(), saved[2], saved[3]};
    const auto adj = general_hamiltonian_backward(tape, grads[0],
                                                  with_grad ? grads[1] : Tensor());
    return {adj.o, adj.o_g, adj.x};
  }
};

// --------------------------------------------------------------- Gonzalez
// Per row: n2 = |dx|^2, D = H1 - H0 - g.dx, k = D / n2 (0 if n2 < tau^2),
// dg = g + k dx. Backward with dg~, s = dg~.dx (small rows: g~ = dg~ only):
//   H1~ = s / n2,  H0~ = -s / n2,  g~ = dg~ - (s / n2) dx,
//   dx~ = k dg~ - (s / n2) (g + 2 k dx).
double dot(const double* a, const double* b, int n) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

}  // namespace

Tensor gonzalez_forward(const Tensor& h0_in, const Tensor& h1_in, const Tensor& g_in,
                        const Tensor& dx_in, double min_dx_norm) {
  const Tensor h0 = dense(h0_in), h1 = dense(h1_in), g = dense(g_in), dx = dense(dx_in);
  const int n = static_cast<int>(g.size(-1));
  const int64_t rows = rows_of(g);
  Tensor dg = torch::empty_like(g);
  const double *p0 = h0.data_ptr<double>(), *p1 = h1.data_ptr<double>();
  const double *pg = g.data_ptr<double>(), *pd = dx.data_ptr<double>();
  double* out = dg.data_ptr<double>();
  const double tau2 = min_dx_norm * min_dx_norm;
  for (int64_t r = 0; r < rows; ++r) {
    const double *gr = pg + n * r, *d = pd + n * r;
    const double n2 = dot(d, d, n);
    const double k = n2 < tau2 ? 0.0 : (p1[r] - p0[r] - dot(gr, d, n)) / n2;
    for (int i = 0; i < n; ++i) out[n * r + i] = gr[i] + k * d[i];
  }
  return dg;
}

GonzalezAdjoints gonzalez_backward(const Tensor& h0_in, const Tensor& h1_in, const Tensor& g_in,
                                   const Tensor& dx_in, double min_dx_norm, const Tensor& dg_bar) {
  const Tensor h0 = dense(h0_in), h1 = dense(h1_in), g = dense(g_in), dx = dense(dx_in);
  const double tau2 = min_dx_norm * min_dx_norm;
  const Tensor db = dense(dg_bar);
  const int n = static_cast<int>(g.size(-1));
  const int64_t rows = rows_of(g);
  GonzalezAdjoints out{torch::empty_like(h0), torch::empty_like(h1), torch::empty_like(g),
                       torch::empty_like(dx)};
  const double *p0 = h0.data_ptr<double>(), *p1 = h1.data_ptr<double>();
  const double *pg = g.data_ptr<double>(), *pd = dx.data_ptr<double>(), *pb = db.data_ptr<double>();
  double *ph0b = out.h0.data_ptr<double>(), *ph1b = out.h1.data_ptr<double>();
  double *pgb = out.grad.data_ptr<double>(), *pxb = out.dx.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    const double *gr = pg + n * r, *d = pd + n * r, *b = pb + n * r;
    double *gb = pgb + n * r, *xb = pxb + n * r;
    const double n2 = dot(d, d, n);
    if (n2 < tau2) {
      ph0b[r] = ph1b[r] = 0.0;
      for (int i = 0; i < n; ++i) gb[i] = b[i], xb[i] = 0.0;
      continue;
    }
    const double k = (p1[r] - p0[r] - dot(gr, d, n)) / n2;
    const double s = dot(b, d, n) / n2;
    ph1b[r] = s, ph0b[r] = -s;
    for (int i = 0; i < n; ++i) {
      gb[i] = b[i] - s * d[i];
      xb[i] = k * b[i] - s * (gr[i] + 2.0 * k * d[i]);
    }
  }
  return out;
}

namespace {

class GeneralGonzalezFunction : public torch::autograd::Function<GeneralGonzalezFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& h0_in, const Tensor& h1_in,
                        const Tensor& g_in, const Tensor& dx_in, double min_dx_norm) {
    const Tensor h0 = dense(h0_in), h1 = dense(h1_in), g = dense(g_in), dx = dense(dx_in);
    ctx->save_for_backward({h0, h1, g, dx});
    ctx->saved_data["min_dx_norm"] = min_dx_norm;
    return gonzalez_forward(h0, h1, g, dx, min_dx_norm);
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const auto adj = gonzalez_backward(saved[0], saved[1], saved[2], saved[3],
                                       ctx->saved_data["min_dx_norm"].toDouble(), grads[0]);
    return {adj.h0, adj.h1, adj.grad, adj.dx, Tensor()};
  }
};

}  // namespace

// ----------------------------------------------------------------- linear
// y_i = sum_j M_ij a_j + sum_j M_i(n_a + j) b_j;  a~_j = sum_i y~_i M_ij, b~ likewise.
Tensor general_linear_forward(const Tensor& a_in, const Tensor& b_in, const std::vector<double>& M,
                              int out) {
  const Tensor a = dense(a_in), b = rows_like(b_in, a_in);
  const int na = static_cast<int>(a.size(-1)), nb = static_cast<int>(b.size(-1)), w = na + nb;
  PHNN_CHECK(static_cast<int64_t>(M.size()) == static_cast<int64_t>(out) * w,
             "general_linear_head: matrix size");
  const int64_t rows = rows_of(a);
  Tensor y = torch::empty({a.size(0), a.size(1), out}, a.options());
  const double *pa = a.data_ptr<double>(), *pb = b.data_ptr<double>();
  double* py = y.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    for (int64_t i = 0; i < out; ++i) {
      const double* m = M.data() + i * w;
      double s = 0.0;
      for (int j = 0; j < na; ++j) s += m[j] * pa[na * r + j];
      for (int j = 0; j < nb; ++j) s += m[na + j] * pb[nb * r + j];
      py[out * r + i] = s;
    }
  }
  return y;
}

LinearAdjoints general_linear_backward(const Tensor& y_bar, const std::vector<double>& M, int na,
                                       int nb) {
  const int w = na + nb;
  const Tensor yb = dense(y_bar);
  const int out = static_cast<int>(yb.size(-1));
  const int64_t rows = rows_of(yb);
  Tensor a_bar = torch::empty({yb.size(0), yb.size(1), na}, yb.options());
  Tensor b_bar = torch::empty({yb.size(0), yb.size(1), nb}, yb.options());
  const double* pyb = yb.data_ptr<double>();
  double *pab = a_bar.data_ptr<double>(), *pbb = b_bar.data_ptr<double>();
  for (int64_t r = 0; r < rows; ++r) {
    for (int j = 0; j < w; ++j) {
      double s = 0.0;
      for (int i = 0; i < out; ++i) s += pyb[out * r + i] * M[static_cast<std::size_t>(i * w + j)];
      if (j < na) pab[na * r + j] = s; else pbb[nb * r + j - na] = s;
    }
  }
  return {a_bar, b_bar};
}

namespace {

class LinearFunction : public torch::autograd::Function<LinearFunction> {
 public:
  static Tensor forward(AutogradContext* ctx, const Tensor& a, const Tensor& b,
                        std::vector<double> M, int64_t out) {
    ctx->saved_data["M"] = M;
    ctx->saved_data["na"] = a.size(-1);
    ctx->saved_data["nb"] = b.size(-1);
    return general_linear_forward(a, b, M, static_cast<int>(out));
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto adj = general_linear_backward(
        grads[0], ctx->saved_data["M"].toDoubleVector(),
        static_cast<int>(ctx->saved_data["na"].toInt()),
        static_cast<int>(ctx->saved_data["nb"].toInt()));
    return {adj.a, adj.b, Tensor(), Tensor()};
  }
};

}  // namespace

GeneralHamiltonian general_hamiltonian_head(const Tensor& o, const Tensor& o_g, const Tensor& x) {
  const auto out = GeneralHamiltonianFunction::apply(
      o, o_g.defined() ? c10::optional<Tensor>(o_g) : c10::nullopt, x);
  return {out[0], o_g.defined() ? out[1] : Tensor()};
}

Tensor general_gonzalez_head(const Tensor& h0, const Tensor& h1, const Tensor& grad_mid,
                             const Tensor& dx, double min_dx_norm) {
  return GeneralGonzalezFunction::apply(h0, h1, grad_mid, dx.expand_as(grad_mid), min_dx_norm);
}

Tensor general_linear_head(const Tensor& a, const Tensor& b, const std::vector<double>& M,
                           int rows) {
  return LinearFunction::apply(a, b, M, static_cast<int64_t>(rows));
}

}  // namespace internal
}  // namespace phnn
