// src/models/dg4_jet_heads.cpp — the order-2 field jets of PHNN-JR and
// PHNN-S with their backwards (dg4_jet_heads.h; the DG4 correction:
// dg4_correction.cpp).
// Plain loops per row (a row = one member and one batch element), no
// autograd node, one fixed order of operations; the formulas are written
// above each function. Private to src/models; the op-by-op jets of
// general_ph.cpp are the reference.
//
// Both fields are products M(o) p of a matrix whose entries are network
// outputs (L lower triangular, L^T, A = K - K^T) with a vector, and
// constant structure maps (J, S_x). The product of two order-2 jets in d
// directions s_a (o_a = d o / d s_a, o_ab = d2 o / d s_a d s_b):
//   y    = M p,
//   y_a  = M_a p + M p_a,
//   y_ab = M_ab p + M_a p_b + M_b p_a + M p_ab,                         (P)
// and its backward, from y~ (value, tangents, second derivatives), per
// entry M_rc = s o_k (s = +-1):
//   o~_k  += s (y~_r p_c + sum_a y~_{a,r} p_{a,c} + sum_ab y~_{ab,r} p_{ab,c}),
//   o~_ak += s (y~_{a,r} p_c + sum_b (y~_{ab,r} + y~_{ba,r}) p_{b,c}),
//   o~_abk += s y~_{ab,r} p_c,
// and p~ likewise with the roles of o and p exchanged.               (PB)
#include "models/dg4_jet_heads.h"

#include <algorithm>
#include <vector>

#include "models/fused_heads_common.h"
#include "phnn/common/check.h"

namespace phnn {
namespace internal {

using namespace heads;

namespace {

// One row's order-2 jet of a vector of size n in d directions, channel by
// channel: channel 0 the value, 1 + a the tangent along s_a, 1 + d + a d + b
// the second derivative along (s_a, s_b).
struct RowJet {
  int n, d;
  std::vector<double> c;
  RowJet(int size, int directions)
      : n(size), d(directions), c(static_cast<std::size_t>((1 + d + d * d) * size), 0.0) {}
  int channels() const { return 1 + d + d * d; }
  double* ch(int k) { return c.data() + k * n; }
  const double* ch(int k) const { return c.data() + k * n; }
  int g(int a) const { return 1 + a; }
  int h(int a, int b) const { return 1 + d + a * d + b; }
  void zero() { std::fill(c.begin(), c.end(), 0.0); }
  // From a row's value [n], tangents [d][n] and second derivatives [d][d][n]
  // (null: 0), or into them.
  void load(const double* v, const double* tg, const double* sd) {
    std::copy(v, v + n, ch(0));
    if (tg) std::copy(tg, tg + d * n, ch(1));
    if (sd) std::copy(sd, sd + d * d * n, ch(1 + d));
  }
  void store(double* v, double* tg, double* sd) const {
    std::copy(ch(0), ch(0) + n, v);
    if (tg) std::copy(ch(1), ch(1) + d * n, tg);
    if (sd) std::copy(ch(1 + d), ch(1 + d) + d * d * n, sd);
  }
};

// M_rc = s o_k.
struct Entry {
  int r, c, k;
  double s;
};

// The entries of L (or L^T) from a row-major lower triangle, and of
// K - K^T from the strictly lower triangle stored after it.
std::vector<Entry> lower_entries(int n, bool transpose) {
  std::vector<Entry> out;
  for (int q = 0; q < n; ++q)
    for (int c = 0; c <= q; ++c) out.push_back(transpose ? Entry{c, q, tri(q, c), 1.0}
                                                         : Entry{q, c, tri(q, c), 1.0});
  return out;
}
std::vector<Entry> skew_entries(int n) {
  std::vector<Entry> out;
  const int base = n * (n + 1) / 2;
  for (int a = 1; a < n; ++a) {
    for (int b = 0; b < a; ++b) {
      out.push_back({a, b, base + a * (a - 1) / 2 + b, 1.0});
      out.push_back({b, a, base + a * (a - 1) / 2 + b, -1.0});
    }
  }
  return out;
}

// y += M(o) p over the jets, (P) in the file comment.
void product_forward(const std::vector<Entry>& M, const RowJet& o, const RowJet& p, RowJet* y) {
  const int d = o.d;
  for (const Entry& m : M) {
    y->ch(0)[m.r] += m.s * (o.ch(0)[m.k] * p.ch(0)[m.c]);
    for (int a = 0; a < d; ++a) {
      y->ch(y->g(a))[m.r] +=
          m.s * (o.ch(o.g(a))[m.k] * p.ch(0)[m.c] + o.ch(0)[m.k] * p.ch(p.g(a))[m.c]);
      for (int b = 0; b < d; ++b) {
        y->ch(y->h(a, b))[m.r] +=
            m.s * (((o.ch(o.h(a, b))[m.k] * p.ch(0)[m.c] + o.ch(o.g(a))[m.k] * p.ch(p.g(b))[m.c]) +
                    o.ch(o.g(b))[m.k] * p.ch(p.g(a))[m.c]) +
                   o.ch(0)[m.k] * p.ch(p.h(a, b))[m.c]);
      }
    }
  }
}

// o~ += and p~ += the adjoints of y = M(o) p from y~, (PB) in the file comment.
void product_backward(const std::vector<Entry>& M, const RowJet& o, const RowJet& p,
                      const RowJet& yb, RowJet* ob, RowJet* pb) {
  const int d = o.d;
  for (const Entry& m : M) {
    const double yv = m.s * yb.ch(0)[m.r];
    ob->ch(0)[m.k] += yv * p.ch(0)[m.c];
    pb->ch(0)[m.c] += yv * o.ch(0)[m.k];
    for (int a = 0; a < d; ++a) {
      const double yg = m.s * yb.ch(yb.g(a))[m.r];
      ob->ch(0)[m.k] += yg * p.ch(p.g(a))[m.c];
      ob->ch(o.g(a))[m.k] += yg * p.ch(0)[m.c];
      pb->ch(0)[m.c] += yg * o.ch(o.g(a))[m.k];
      pb->ch(p.g(a))[m.c] += yg * o.ch(0)[m.k];
    }
    for (int a = 0; a < d; ++a) {
      for (int b = 0; b < d; ++b) {
        const double yh = m.s * yb.ch(yb.h(a, b))[m.r];
        ob->ch(0)[m.k] += yh * p.ch(p.h(a, b))[m.c];
        ob->ch(o.h(a, b))[m.k] += yh * p.ch(0)[m.c];
        ob->ch(o.g(a))[m.k] += yh * p.ch(p.g(b))[m.c];
        ob->ch(o.g(b))[m.k] += yh * p.ch(p.g(a))[m.c];
        pb->ch(0)[m.c] += yh * o.ch(o.h(a, b))[m.k];
        pb->ch(p.h(a, b))[m.c] += yh * o.ch(0)[m.k];
        pb->ch(p.g(a))[m.c] += yh * o.ch(o.g(b))[m.k];
        pb->ch(p.g(b))[m.c] += yh * o.ch(o.g(a))[m.k];
      }
    }
  }
}

// An effort-like jet [x; c] of size n: x's value and tangents (second
// derivative 0) in its first nx entries, the constant c after them.
void load_effort(const double* x, const double* x_g, int nx, const double* c, RowJet* p) {
  p->zero();
  for (int j = 0; j < nx; ++j) p->ch(0)[j] = x[j];
  for (int j = nx; j < p->n; ++j) p->ch(0)[j] = c[j - nx];
  for (int a = 0; a < p->d; ++a)
    for (int j = 0; j < nx; ++j) p->ch(p->g(a))[j] = x_g[a * nx + j];
}

// Output tensors of an order-2 jet of width n.
FieldJet2 empty_jet(int64_t E, int64_t B, int d, int n, const torch::TensorOptions& options) {
  return {torch::empty({E, B, n}, options), torch::empty({E, B, d, n}, options),
          torch::empty({E, B, d, d, n}, options)};
}

// A row of a jet's three tensors into a RowJet (undefined tensors: 0).
void load_row(const FieldJet2& t, int64_t r, RowJet* j) {
  const int n = j->n, d = j->d;
  j->zero();
  j->load(t.f.data_ptr<double>() + n * r,
          t.g.defined() ? t.g.data_ptr<double>() + d * n * r : nullptr,
          t.h.defined() ? t.h.data_ptr<double>() + d * d * n * r : nullptr);
}

FieldJet2 dense_jet(const torch::Tensor& v, const torch::Tensor& g, const torch::Tensor& h) {
  return {dense(v), g.defined() ? dense(g) : g, h.defined() ? dense(h) : h};
}

}  // namespace

// ---------------------------------------------------------- PHNN-JR jet
// Per row, p = [e; u] (p_a = [Q_a; 0], p_ab = 0), L = L_R (o):
//   y = L p,  r = L^T y (both by (P)),  f = [J p - r]_{1:n_x} per channel.
// Backward: r~ = -f~, p~ = J^T f~ (per channel), then (PB) of r = L^T y
// (-> o~, y~) and of y = L p (-> o~, p~); e~, e_g~ are p~'s first n_x.
namespace {

struct JrRow {
  int nx, m, d;
  std::vector<Entry> lower, upper;
  RowJet p, o, y, r;
  JrRow(int states, int inputs, int directions)
      : nx(states),
        m(states + inputs),
        d(directions),
        lower(lower_entries(m, false)),
        upper(lower_entries(m, true)),
        p(m, d),
        o(m * (m + 1) / 2, d),
        y(m, d),
        r(m, d) {}
  void forward(const double* e, const double* eg, const double* u, const FieldJet2& net,
               int64_t row) {
    load_effort(e, eg, nx, u, &p);
    load_row(net, row, &o);
    y.zero();
    product_forward(lower, o, p, &y);
    r.zero();
    product_forward(upper, o, y, &r);
  }
};

}  // namespace

FieldJet2 jr_field_jet2_forward(const torch::Tensor& e_in, const torch::Tensor& eg_in,
                                const torch::Tensor& o_in, const torch::Tensor& og_in,
                                const torch::Tensor& oh_in, const torch::Tensor& u_in,
                                const std::vector<double>& J) {
  const torch::Tensor e = dense(e_in), eg = dense(eg_in), u = rows_like(u_in, e_in);
  const FieldJet2 net = dense_jet(o_in, og_in, oh_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1)), m = nx + nu;
  const int d = static_cast<int>(eg.size(-2));
  PHNN_CHECK(static_cast<int>(J.size()) == m * m && net.f.size(-1) == m * (m + 1) / 2 &&
                 net.h.size(-3) == d,
             "jr_field_jet2_forward: structure or output sizes");
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  FieldJet2 out = empty_jet(E, B, d, nx, e.options());
  const double *pe = e.data_ptr<double>(), *peg = eg.data_ptr<double>(), *pu = u.data_ptr<double>();
  JrRow row(nx, nu, d);
  RowJet f(nx, d);
  for (int64_t r = 0; r < rows; ++r) {
    row.forward(pe + nx * r, peg + d * nx * r, pu + nu * r, net, r);
    for (int k = 0; k < f.channels(); ++k) {
      for (int i = 0; i < nx; ++i) {
        double s = 0.0;
        for (int j = 0; j < m; ++j) s += J[i * m + j] * row.p.ch(k)[j];
        f.ch(k)[i] = s - row.r.ch(k)[i];
      }
    }
    f.store(out.f.data_ptr<double>() + nx * r, out.g.data_ptr<double>() + d * nx * r,
            out.h.data_ptr<double>() + d * d * nx * r);
  }
  return out;
}

FieldJet2Adjoints jr_field_jet2_backward(const torch::Tensor& e_in, const torch::Tensor& eg_in,
                                         const torch::Tensor& o_in, const torch::Tensor& og_in,
                                         const torch::Tensor& oh_in, const torch::Tensor& u_in,
                                         const std::vector<double>& J, const FieldJet2& bar_in) {
  const torch::Tensor e = dense(e_in), eg = dense(eg_in), u = rows_like(u_in, e_in);
  const FieldJet2 net = dense_jet(o_in, og_in, oh_in), bar = dense_jet(bar_in.f, bar_in.g, bar_in.h);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1)), m = nx + nu;
  const int d = static_cast<int>(eg.size(-2)), K = m * (m + 1) / 2;
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  const FieldJet2 ob_t = empty_jet(E, B, d, K, e.options());
  FieldJet2Adjoints out{torch::empty_like(e), torch::empty_like(eg), ob_t.f, ob_t.g, ob_t.h, {}, {}};
  const double *pe = e.data_ptr<double>(), *peg = eg.data_ptr<double>(), *pu = u.data_ptr<double>();
  JrRow row(nx, nu, d);
  RowJet fb(nx, d), rb(m, d), pb(m, d), yb(m, d), ob(K, d);
  for (int64_t r = 0; r < rows; ++r) {
    row.forward(pe + nx * r, peg + d * nx * r, pu + nu * r, net, r);
    load_row(bar, r, &fb);
    rb.zero();
    for (int k = 0; k < fb.channels(); ++k) {
      for (int i = 0; i < nx; ++i) rb.ch(k)[i] = -fb.ch(k)[i];
      for (int j = 0; j < m; ++j) {  // p~ = J^T f~
        double s = 0.0;
        for (int i = 0; i < nx; ++i) s += fb.ch(k)[i] * J[i * m + j];
        pb.ch(k)[j] = s;
      }
    }
    yb.zero();
    ob.zero();
    product_backward(row.upper, row.o, row.y, rb, &ob, &yb);
    product_backward(row.lower, row.o, row.p, yb, &ob, &pb);
    ob.store(out.o.data_ptr<double>() + K * r, out.o_g.data_ptr<double>() + d * K * r,
             out.o_h.data_ptr<double>() + d * d * K * r);
    double *peb = out.e.data_ptr<double>() + nx * r, *pegb = out.e_g.data_ptr<double>() + d * nx * r;
    for (int j = 0; j < nx; ++j) peb[j] = pb.ch(0)[j];
    for (int a = 0; a < d; ++a)
      for (int j = 0; j < nx; ++j) pegb[a * nx + j] = pb.ch(pb.g(a))[j];
  }
  return out;
}

// -------------------------------------------------------------- PHNN-S jet
// Per row, L = L_z's triangle, A = K - K^T, w the ports' jet (w_ab = 0):
//   y = L w,  z = L^T y + A w (by (P)),  f = S_x [e; z; u] per channel
//   (e_ab = 0; u in the value channel only).
// Backward: [e~; z~] = S_x^T f~ per channel, then (PB) of L^T y and of A w
// (-> o~, y~, w~) and of y = L w (-> o~, w~).
namespace {

struct SRow {
  int nw, d;
  std::vector<Entry> lower, upper, skew;
  RowJet w, o, y, z;
  SRow(int ports, int directions)
      : nw(ports),
        d(directions),
        lower(lower_entries(ports, false)),
        upper(lower_entries(ports, true)),
        skew(skew_entries(ports)),
        w(ports, directions),
        o(ports * ports, directions),
        y(ports, directions),
        z(ports, directions) {}
  void forward(const double* wv, const double* wg, const FieldJet2& net, int64_t row) {
    load_effort(wv, wg, nw, nullptr, &w);
    load_row(net, row, &o);
    y.zero();
    product_forward(lower, o, w, &y);
    z.zero();
    product_forward(upper, o, y, &z);
    product_forward(skew, o, w, &z);
  }
};

}  // namespace

FieldJet2 s_field_jet2_forward(const torch::Tensor& e_in, const torch::Tensor& eg_in,
                               const torch::Tensor& u_in, const torch::Tensor& o_in,
                               const torch::Tensor& og_in, const torch::Tensor& oh_in,
                               const PortJet& w_in, const std::vector<double>& S, int nw) {
  const torch::Tensor e = dense(e_in), eg = dense(eg_in), u = rows_like(u_in, e_in);
  const torch::Tensor wv = dense(w_in.w), wg = dense(w_in.w_g);
  const FieldJet2 net = dense_jet(o_in, og_in, oh_in);
  const int nx = static_cast<int>(e.size(-1)), nu = static_cast<int>(u.size(-1));
  const int d = static_cast<int>(eg.size(-2)), W = nx + nw + nu;
  PHNN_CHECK(net.f.size(-1) == nw * nw && static_cast<int>(S.size()) >= nx * W,
             "s_field_jet2_forward: structure or output sizes");
  const int64_t E = e.size(0), B = e.size(1), rows = E * B;
  FieldJet2 out = empty_jet(E, B, d, nx, e.options());
  const double *pe = e.data_ptr<double>(), *peg = eg.data_ptr<double>(), *pu = u.data_ptr<double>();
  SRow row(nw, d);
  RowJet ej(nx, d), f(nx, d);
  for (int64_t r = 0; r < rows; ++r) {
    row.forward(wv.data_ptr<double>() + nw * r, wg.data_ptr<double>() + d * nw * r, net, r);
    load_effort(pe + nx * r, peg + d * nx * r, nx, nullptr, &ej);
    for (int k = 0; k < f.channels(); ++k) {
      for (int i = 0; i < nx; ++i) {
        const double* s = S.data() + i * W;
        double acc = 0.0;
        for (int j = 0; j < nx; ++j) acc += s[j] * ej.ch(k)[j];
        for (int q = 0; q < nw; ++q) acc += s[nx + q] * row.z.ch(k)[q];
        for (int b = 0; b < nu && k == 0; ++b) acc += s[nx + nw + b] * pu[nu * r + b];
        f.ch(k)[i] = acc;
      }
    }
    f.store(out.f.data_ptr<double>() + nx * r, out.g.data_ptr<double>() + d * nx * r,
            out.h.data_ptr<double>() + d * d * nx * r);
  }
  return out;
}

FieldJet2Adjoints s_field_jet2_backward(const torch::Tensor& o_in, const torch::Tensor& og_in,
                                        const torch::Tensor& oh_in, const PortJet& w_in,
                                        const std::vector<double>& S, int nx, int nw, int nu,
                                        const FieldJet2& bar_in) {
  const FieldJet2 net = dense_jet(o_in, og_in, oh_in), bar = dense_jet(bar_in.f, bar_in.g, bar_in.h);
  const torch::Tensor wv = dense(w_in.w), wg = dense(w_in.w_g);
  const int d = static_cast<int>(net.g.size(-2)), T = nw * nw, W = nx + nw + nu;
  const int64_t E = wv.size(0), B = wv.size(1), rows = E * B;
  const auto options = wv.options();
  const FieldJet2 ob_t = empty_jet(E, B, d, T, options);
  FieldJet2Adjoints out{torch::empty({E, B, nx}, options), torch::empty({E, B, d, nx}, options),
                        ob_t.f, ob_t.g, ob_t.h, torch::empty_like(wv), torch::empty_like(wg)};
  SRow row(nw, d);
  RowJet fb(nx, d), eb(nx, d), zb(nw, d), yb(nw, d), wb(nw, d), ob(T, d);
  for (int64_t r = 0; r < rows; ++r) {
    row.forward(wv.data_ptr<double>() + nw * r, wg.data_ptr<double>() + d * nw * r, net, r);
    load_row(bar, r, &fb);
    for (int k = 0; k < fb.channels(); ++k) {  // [e~; z~] = S_x^T f~
      for (int j = 0; j < nx + nw; ++j) {
        double s = 0.0;
        for (int i = 0; i < nx; ++i) s += fb.ch(k)[i] * S[i * W + j];
        (j < nx ? eb.ch(k)[j] : zb.ch(k)[j - nx]) = s;
      }
    }
    yb.zero(), wb.zero(), ob.zero();
    product_backward(row.upper, row.o, row.y, zb, &ob, &yb);
    product_backward(row.skew, row.o, row.w, zb, &ob, &wb);
    product_backward(row.lower, row.o, row.w, yb, &ob, &wb);
    ob.store(out.o.data_ptr<double>() + T * r, out.o_g.data_ptr<double>() + d * T * r,
             out.o_h.data_ptr<double>() + d * d * T * r);
    eb.store(out.e.data_ptr<double>() + nx * r, out.e_g.data_ptr<double>() + d * nx * r, nullptr);
    wb.store(out.w.data_ptr<double>() + nw * r, out.w_g.data_ptr<double>() + d * nw * r, nullptr);
  }
  return out;
}

}  // namespace internal
}  // namespace phnn
