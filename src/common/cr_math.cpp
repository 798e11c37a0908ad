// src/common/cr_math.cpp — correctly rounded elementary functions
// (include/phnn/common/cr_math.h): GNU MPFR for every function
// (common/mpfr_binary64.h), and a fast path in double-double arithmetic
// (common/double_double.h) with a rounding test (Ziv's strategy) for sin,
// cos, exp, log, sinh, cosh and tanh, the ones data generation and system
// files call per step.
// Size: one table of constants and the fast paths that share it (sin/cos,
// exp, log, sinh/cosh/tanh); apart, they would need a header of internals.
//
// The fast paths: reduce the argument (x = k c + r, c = pi/2 or ln 2 held as
// three doubles), then sin/cos from a table of sin(i/64), cos(i/64) and short
// series in the remainder, exp and log from their series with the leading
// terms in double-double, sinh, cosh and tanh from e^x - 1 in double-double;
// return round(y) when both ends of [y - eps |y|, y + eps |y|] round to the
// same double (eps = 2^-63, at least twice the paths' error, ~2^-65, from the
// terms summed in double). MPFR
// decides the rest (~0.15 % of calls). tests/common/cr_math_test.cpp compares
// both builds (FMA and baseline) with MPFR on ~10^6 arguments. Every
// operation is an IEEE add, multiply or divide in a fixed order (the build
// pins -ffp-contract=off), so even the rounding test gives the same answer on
// every CPU.
#include "phnn/common/cr_math.h"

#ifdef __FAST_MATH__
#error "cr_math.cpp needs IEEE arithmetic in the order written: no -ffast-math"
#endif

#include <mpfr.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "common/double_double.h"
#include "common/mpfr_binary64.h"

namespace phnn {
namespace cr {
namespace {

using internal::dd_add;
using internal::dd_div;
using internal::dd_mul;
using internal::dd_mul_d;
using internal::dd_neg;
using internal::Dd;
using internal::fast_two_sum;
using internal::two_prod;
using internal::two_sum;

thread_local long fallbacks = 0;

double fallback(internal::MpfrUnary f, double x) {
  ++fallbacks;
  return internal::by_mpfr(f, x);
}

// ---- constants, from MPFR at 256 bits ----------------------------------

constexpr int kLead = 6;   // series terms summed in double-double (at most)
constexpr int kTerms = 18; // series terms in all (at most)

struct Series {
  Dd lead[kLead];
  double tail[kTerms];
  int n_lead, n_terms;
};

// sum_j c_j t^j: the terms j >= n_lead by Horner in double on t.hi, the
// first n_lead in double-double.
template <bool kFma>
[[gnu::always_inline]] inline Dd sum_series(const Series& c, Dd t) {
  double tail = c.tail[c.n_terms - 1];
  for (int j = c.n_terms - 2; j >= c.n_lead; --j) tail = tail * t.hi + c.tail[j];
  Dd acc{tail, 0.0};
  for (int j = c.n_lead - 1; j >= 0; --j) acc = dd_add(dd_mul<kFma>(acc, t), c.lead[j]);
  return acc;
}

constexpr int kTableSize = 52;  // |r| <= pi/4 + a hair < 52.5 / 64

struct Constants {
  double pio2[3], two_over_pi;  // pi/2 = pio2[0] + pio2[1] + pio2[2] (+ 2^-160 or so)
  double ln2[3], inv_ln2;
  Dd sin_a[kTableSize + 1], cos_a[kTableSize + 1];  // sin(i/64), cos(i/64), i = 0..52
  double sin_t[4], cos_t[4];  // (-1)^(j+1) / (2j+3)!, (-1)^(j+1) / (2j+2)!, j = 0..3
  Series exp_r;   // e^r = sum r^j / j!
  Series expm1_r; // (e^r - 1) / r = sum r^j / (j+1)!
  Series atanh_f; // atanh f / f = sum s^j / (2j+1), s = f^2
};

// v as d[0] + d[1] + ... + d[n-1], each the double nearest to what remains.
void split_constant(mpfr_t v, double* d, int n) {
  mpfr_t rest;
  mpfr_init2(rest, 256);
  mpfr_set(rest, v, MPFR_RNDN);
  for (int i = 0; i < n; ++i) {
    d[i] = mpfr_get_d(rest, MPFR_RNDN);
    mpfr_sub_d(rest, rest, d[i], MPFR_RNDN);
  }
  mpfr_clear(rest);
}

// c_j = sign^j / (denominator of term j), as lead double-doubles and tail doubles.
template <typename Denominator>
Series make_series(int n_lead, int n_terms, int sign, Denominator denominator) {
  Series s{};
  if (n_lead > kLead || n_terms > kTerms || n_lead > n_terms) {
    std::fputs("cr_math: a series longer than kLead / kTerms\n", stderr);
    std::abort();
  }
  s.n_lead = n_lead;
  s.n_terms = n_terms;
  mpfr_t c;
  mpfr_init2(c, 256);
  for (int j = 0; j < n_terms; ++j) {
    mpfr_set_ui(c, 1, MPFR_RNDN);
    mpfr_div(c, c, denominator(j), MPFR_RNDN);
    if (sign < 0 && j % 2 == 1) mpfr_neg(c, c, MPFR_RNDN);
    double parts[2];
    split_constant(c, parts, 2);
    if (j < n_lead) s.lead[j] = Dd{parts[0], parts[1]};
    s.tail[j] = parts[0];
  }
  mpfr_clear(c);
  return s;
}

// n! as an MPFR number (exact at 256 bits for the n used here).
class Factorial {
 public:
  Factorial() { mpfr_init2(v_, 256); }
  ~Factorial() { mpfr_clear(v_); }
  Factorial(const Factorial&) = delete;
  Factorial& operator=(const Factorial&) = delete;
  mpfr_ptr of(unsigned long n) {
    mpfr_fac_ui(v_, n, MPFR_RNDN);
    return v_;
  }
  mpfr_ptr integer(unsigned long n) {
    mpfr_set_ui(v_, n, MPFR_RNDN);
    return v_;
  }

 private:
  mpfr_t v_;
};

Constants make_constants() {
  Constants k{};
  mpfr_t v;
  mpfr_init2(v, 256);
  mpfr_const_pi(v, MPFR_RNDN);
  mpfr_div_ui(v, v, 2, MPFR_RNDN);
  split_constant(v, k.pio2, 3);
  mpfr_ui_div(v, 1, v, MPFR_RNDN);
  k.two_over_pi = mpfr_get_d(v, MPFR_RNDN);
  mpfr_const_log2(v, MPFR_RNDN);
  split_constant(v, k.ln2, 3);
  mpfr_ui_div(v, 1, v, MPFR_RNDN);
  k.inv_ln2 = mpfr_get_d(v, MPFR_RNDN);
  mpfr_clear(v);
  Factorial f;
  const auto odd_factorial = [&f](int j) { return f.of(2 * j + 1); };
  const auto even_factorial = [&f](int j) { return f.of(2 * j); };
  const auto factorial = [&f](int j) { return f.of(j); };
  const auto odd = [&f](int j) { return f.integer(2 * j + 1); };
  mpfr_t a, t;
  mpfr_inits2(256, a, t, static_cast<mpfr_ptr>(nullptr));
  for (int i = 0; i <= kTableSize; ++i) {
    mpfr_set_si(a, i, MPFR_RNDN);
    mpfr_div_ui(a, a, 64, MPFR_RNDN);
    double parts[2];
    mpfr_sin(t, a, MPFR_RNDN);
    split_constant(t, parts, 2);
    k.sin_a[i] = Dd{parts[0], parts[1]};
    mpfr_cos(t, a, MPFR_RNDN);
    split_constant(t, parts, 2);
    k.cos_a[i] = Dd{parts[0], parts[1]};
  }
  mpfr_clears(a, t, static_cast<mpfr_ptr>(nullptr));
  for (int j = 0; j < 4; ++j) {
    const double sign = j % 2 == 0 ? -1.0 : 1.0;
    k.sin_t[j] = sign / mpfr_get_d(odd_factorial(j + 1), MPFR_RNDN);
    k.cos_t[j] = sign / mpfr_get_d(even_factorial(j + 1), MPFR_RNDN);
  }
  k.exp_r = make_series(5, 17, +1, factorial);
  const auto next_factorial = [&f](int j) { return f.of(j + 1); };
  k.expm1_r = make_series(6, 17, +1, next_factorial);
  k.atanh_f = make_series(3, 14, +1, odd);
  return k;
}

const Constants& constants() {
  static const Constants k = make_constants();
  return k;
}

// ---- the fast paths -----------------------------------------------------

constexpr double kEps = 0x1p-63;  // relative error bound of every fast path

// The double nearest to v, if |v - (y.hi + y.lo)| <= kEps |y.hi| decides it.
inline bool decided(Dd y, double* out) {
  const double e = kEps * std::fabs(y.hi);
  const double up = y.hi + (y.lo + e);
  const double down = y.hi + (y.lo - e);
  if (up != down) return false;
  *out = up;
  return true;
}

// x - k (c[0] + c[1] + c[2]) as a double-double. x - k c[0] rounded is exact:
// with k = round(x / c) != 0 it is at most half of |x| and |k c[0]|' binade
// (Sterbenz), and with k = 0 it is x.
template <bool kFma>
[[gnu::always_inline]] inline Dd reduce(double x, double k, const double* c) {
  const Dd p = two_prod<kFma>(k, c[0]);
  Dd r = two_sum(x - p.hi, -p.lo);
  r = dd_add(r, dd_neg(two_prod<kFma>(k, c[1])));
  return dd_add(r, Dd{-(k * c[2]), 0.0});
}

constexpr double kTrigLimit = 0x1p20;  // |x| reduced in double-double below this

// sin or cos of x = k pi/2 + r, |r| <= pi/4: quadrant q = k mod 4 picks
// +-sin r or +-cos r. Then r = a + t with a = i/64 from a table of sin a
// and cos a (double-doubles) and |t| <= 1/128:
//   sin r = S + S Q + C t + C t P,   cos r = C + C Q - S t - S t P,
//   P = sin t / t - 1 = -t^2/6 + ..., Q = cos t - 1 = -t^2/2 + ...,
// S t and C t as exact products, everything below 2^-14 |result| in double
// (P and Q to t^8: their first omitted terms are ~2^-95 and ~2^-92).
template <bool kFma>
[[gnu::always_inline]] inline bool trig_fast(double x, bool cosine, double* out) {
  const Constants& c = constants();
  const double k = std::nearbyint(x * c.two_over_pi);
  const Dd r = k == 0.0 ? Dd{x, 0.0} : reduce<kFma>(x, k, c.pio2);
  const double i = std::nearbyint(r.hi * 64.0);
  const int n = static_cast<int>(std::fabs(i));
  // r.hi - i/64 is exact: r.hi and i/64 are within a factor 2 of each other (Sterbenz), or i = 0.
  const Dd t = two_sum(r.hi - i / 64.0, r.lo);
  const double sign = i < 0.0 ? -1.0 : 1.0;
  const Dd sa{sign * c.sin_a[n].hi, sign * c.sin_a[n].lo}, ca = c.cos_a[n];
  const double s = t.hi * t.hi;
  const double p = s * (c.sin_t[0] + s * (c.sin_t[1] + s * (c.sin_t[2] + s * c.sin_t[3])));
  const double q = s * (c.cos_t[0] + s * (c.cos_t[1] + s * (c.cos_t[2] + s * c.cos_t[3])));
  const long quadrant = (static_cast<long>(k) + (cosine ? 1 : 0)) & 3;
  Dd y;
  if (quadrant % 2 == 0) {  // sin r
    const Dd ct = two_prod<kFma>(ca.hi, t.hi);
    y = two_sum(sa.hi, ct.hi);
    y.lo += (((ct.lo + sa.lo) + sa.hi * q) + (ca.hi * t.lo + ca.lo * t.hi)) + ct.hi * p;
  } else {  // cos r
    const Dd st = two_prod<kFma>(sa.hi, t.hi);
    y = two_sum(ca.hi, -st.hi);
    y.lo += (((ca.lo - st.lo) + ca.hi * q) - (sa.hi * t.lo + sa.lo * t.hi)) - st.hi * p;
  }
  y = fast_two_sum(y.hi, y.lo);
  if (quadrant >= 2) y = dd_neg(y);
  return decided(y, out);
}

// x = k ln 2 + r, |r| <= ln 2 / 2 with k = round(x / ln 2): e^r.
template <bool kFma>
[[gnu::always_inline]] inline Dd exp_of_remainder(double x, double k) {
  const Constants& c = constants();
  return sum_series<kFma>(c.exp_r, reduce<kFma>(x, k, c.ln2));
}

// e^x = 2^k e^r (2^k applied by the caller).
template <bool kFma>
[[gnu::always_inline]] inline bool exp_fast(double x, double* out, int* k_out) {
  const double k = std::nearbyint(x * constants().inv_ln2);
  *k_out = static_cast<int>(k);
  return decided(exp_of_remainder<kFma>(x, k), out);
}

// x = 2^e m, m in [sqrt(1/2), sqrt(2)): log x = e ln 2 + 2 atanh f with
// f = (m - 1) / (m + 1), |f| <= 0.172 (m - 1 is exact: Sterbenz).
template <bool kFma>
[[gnu::always_inline]] inline bool log_fast(double x, double* out) {
  const Constants& c = constants();
  int e = 0;
  double m = std::frexp(x, &e);
  if (m < 0.70710678118654752440) {  // sqrt(1/2): any nearby threshold works
    m *= 2.0;
    e -= 1;
  }
  const Dd f = dd_div<kFma>(Dd{m - 1.0, 0.0}, two_sum(m, 1.0));
  const Dd series = sum_series<kFma>(c.atanh_f, dd_mul<kFma>(f, f));
  const Dd log_m = dd_mul_d<kFma>(dd_mul<kFma>(f, series), 2.0);
  const double de = static_cast<double>(e);
  const Dd e_ln2 = dd_add(two_prod<kFma>(de, c.ln2[0]), Dd{de * c.ln2[1], 0.0});
  return decided(dd_add(e_ln2, log_m), out);
}

// e^x - 1 as a double-double, |x| <= 700: the series of (e^r - 1) / r when
// k = 0 (no cancellation near 0), else 2^k e^r - 1 (at least 0.41 then).
template <bool kFma>
[[gnu::always_inline]] inline Dd expm1_dd(double x) {
  const Constants& c = constants();
  const double k = std::nearbyint(x * c.inv_ln2);
  if (k == 0.0) return dd_mul_d<kFma>(sum_series<kFma>(c.expm1_r, Dd{x, 0.0}), x);
  const Dd e = exp_of_remainder<kFma>(x, k);
  const int n = static_cast<int>(k);
  return dd_add(Dd{std::ldexp(e.hi, n), std::ldexp(e.lo, n)}, Dd{-1.0, 0.0});
}

enum class Hyperbolic { kSinh, kCosh, kTanh };

// x > 0 (the callers use the symmetries), x <= 700. With m = e^x - 1:
// sinh x = m (m + 2) / (2 (m + 1)) below 1 (no cancellation), (e^x - e^-x) / 2
// above (no overflow of m^2; the difference loses < 1 bit), cosh x =
// (e^x + e^-x) / 2, tanh x = m' / (m' + 2) with m' = e^(2x) - 1 (2x <= 40).
template <bool kFma>
[[gnu::always_inline]] inline bool hyperbolic_fast(double x, Hyperbolic f, double* out) {
  if (f == Hyperbolic::kTanh) {
    const Dd m = expm1_dd<kFma>(2.0 * x);
    return decided(dd_div<kFma>(m, dd_add(m, Dd{2.0, 0.0})), out);
  }
  const Dd m = expm1_dd<kFma>(x);
  const Dd e = dd_add(m, Dd{1.0, 0.0});
  if (f == Hyperbolic::kSinh && x < 1.0) {
    return decided(dd_div<kFma>(dd_mul<kFma>(m, dd_add(m, Dd{2.0, 0.0})), dd_mul_d<kFma>(e, 2.0)),
                   out);
  }
  const Dd inverse = dd_div<kFma>(Dd{1.0, 0.0}, e);
  return decided(dd_mul_d<kFma>(dd_add(e, f == Hyperbolic::kSinh ? dd_neg(inverse) : inverse), 0.5),
                 out);
}

// Two builds of each fast path: with the FMA instruction (two_prod in one
// fused multiply-add) and without (Dekker's split). Same bits: the FMA is
// used only where it computes an exact product error.
struct FastPaths {
  bool (*trig)(double, bool, double*);
  bool (*exp)(double, double*, int*);
  bool (*log)(double, double*);
  bool (*hyperbolic)(double, Hyperbolic, double*);
};

[[gnu::target("fma")]] bool trig_fma(double x, bool cosine, double* out) {
  return trig_fast<true>(x, cosine, out);
}
[[gnu::target("fma")]] bool exp_fma(double x, double* out, int* k) {
  return exp_fast<true>(x, out, k);
}
[[gnu::target("fma")]] bool log_fma(double x, double* out) { return log_fast<true>(x, out); }
[[gnu::target("fma")]] bool hyperbolic_fma(double x, Hyperbolic f, double* out) {
  return hyperbolic_fast<true>(x, f, out);
}
bool trig_base(double x, bool cosine, double* out) { return trig_fast<false>(x, cosine, out); }
bool exp_base(double x, double* out, int* k) { return exp_fast<false>(x, out, k); }
bool log_base(double x, double* out) { return log_fast<false>(x, out); }
bool hyperbolic_base(double x, Hyperbolic f, double* out) {
  return hyperbolic_fast<false>(x, f, out);
}

bool baseline_only = false;  // set by tests (internal::use_baseline_fast_paths)

const FastPaths& fast_paths() {
  static const FastPaths base{trig_base, exp_base, log_base, hyperbolic_base};
  static const FastPaths detected =
      __builtin_cpu_supports("fma") ? FastPaths{trig_fma, exp_fma, log_fma, hyperbolic_fma} : base;
  return baseline_only ? base : detected;
}

}  // namespace

long fallback_count() { return fallbacks; }

namespace internal {
void use_baseline_fast_paths(bool on) { baseline_only = on; }
}  // namespace internal

// |x| < 2^-26: sin x = x (1 - x^2/6 + ...) is within 2^-54.5 |x| of x, under
// half an ulp even below a power of two.
double sin(double x) {
  if (std::fabs(x) < 0x1p-26) return x;
  double y;
  if (std::fabs(x) < kTrigLimit && fast_paths().trig(x, false, &y)) return y;
  return fallback(mpfr_sin, x);
}

// |x| < 2^-27: cos x = 1 - x^2/2 + ... is within 2^-55 of 1, under half an
// ulp below 1 (2^-54).
double cos(double x) {
  if (std::fabs(x) < 0x1p-27) return 1.0;
  double y;
  if (std::fabs(x) < kTrigLimit && fast_paths().trig(x, true, &y)) return y;
  return fallback(mpfr_cos, x);
}

// The scaling by 2^k is exact while the result is normal (|x| <= 700).
// |x| < 2^-60: 1 + x + ... rounds to 1.
double exp(double x) {
  if (std::fabs(x) < 0x1p-60) return 1.0;
  double y;
  int k = 0;
  if (std::fabs(x) <= 700.0 && fast_paths().exp(x, &y, &k)) return std::ldexp(y, k);
  return fallback(mpfr_exp, x);
}

double log(double x) {
  if (x == 1.0) return 0.0;
  double y;
  if (x >= DBL_MIN && x <= DBL_MAX && fast_paths().log(x, &y)) return y;
  return fallback(mpfr_log, x);
}

// |x| < 2^-26: sinh x = x (1 + x^2/6 + ...) rounds to x (as sin x does).
double sinh(double x) {
  const double a = std::fabs(x);
  if (a < 0x1p-26) return x;
  double y;
  if (a <= 700.0 && fast_paths().hyperbolic(a, Hyperbolic::kSinh, &y)) return x < 0 ? -y : y;
  return fallback(mpfr_sinh, x);
}

// |x| < 2^-27: cosh x = 1 + x^2/2 + ... is within 2^-55 of 1: rounds to 1.
double cosh(double x) {
  const double a = std::fabs(x);
  if (a < 0x1p-27) return 1.0;
  double y;
  if (a <= 700.0 && fast_paths().hyperbolic(a, Hyperbolic::kCosh, &y)) return y;
  return fallback(mpfr_cosh, x);
}

// |x| < 2^-27: tanh x = x (1 - x^2/3 + ...) rounds to x. |x| > 20:
// 1 - tanh |x| < 2 e^-40 < 2^-54, half an ulp below 1: rounds to +-1.
double tanh(double x) {
  const double a = std::fabs(x);
  if (a < 0x1p-27 || a != a) return x;
  if (a > 20.0) return x < 0 ? -1.0 : 1.0;
  double y;
  if (fast_paths().hyperbolic(a, Hyperbolic::kTanh, &y)) return x < 0 ? -y : y;
  return fallback(mpfr_tanh, x);
}

// MPFR only.
double tan(double x) { return internal::by_mpfr(mpfr_tan, x); }
double asin(double x) { return internal::by_mpfr(mpfr_asin, x); }
double acos(double x) { return internal::by_mpfr(mpfr_acos, x); }
double atan(double x) { return internal::by_mpfr(mpfr_atan, x); }
double asinh(double x) { return internal::by_mpfr(mpfr_asinh, x); }
double acosh(double x) { return internal::by_mpfr(mpfr_acosh, x); }
double atanh(double x) { return internal::by_mpfr(mpfr_atanh, x); }
double cbrt(double x) { return internal::by_mpfr(mpfr_cbrt, x); }

double pow(double x, double y) { return internal::by_mpfr(mpfr_pow, x, y); }

}  // namespace cr
}  // namespace phnn
