// src/kernels/vector_math.cpp — tanh over arrays in one fixed operation order,
// compiled once per instruction set (kernels/vector_math.h).
#include "kernels/vector_math.h"

#include <cmath>
#include <cstring>

#include "kernels/kernel_isa.h"
#include "phnn/common/cr_math.h"

namespace phnn {
namespace internal {
namespace {

// The exp reduction x = k ln 2 + r shared by the functions below: ln 2 in two
// parts (k ln2_hi exact), and the shifter whose addition rounds x log2 e to
// an integer (round half to even, as nearbyint in the default rounding mode)
// that the low mantissa bits of the sum then hold.
constexpr double kLog2e = 1.4426950408889634073599;
constexpr double kLn2Hi = 6.93145751953125e-1, kLn2Lo = 1.42860682030941723212e-6;
constexpr double kShifter = 6755399441055744.0;  // 1.5 * 2^52: t - kShifter = round(t)

PHNN_KERNEL_INLINE int64_t bits_of(double v) {
  int64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}
PHNN_KERNEL_INLINE double power_of_two(int64_t k) {  // 2^k, -1022 <= k <= 1023
  const int64_t b = (k + 1023) << 52;
  double v;
  std::memcpy(&v, &b, sizeof v);
  return v;
}

// exp(r) for |r| <= ln2 / 2: Cephes' Pade form
// exp r = (q + p) / (q - p) = 1 + 2 p / (q - p), p = r P(r^2), q = Q(r^2).
struct PadeTerms {
  double p, q;
};
PHNN_KERNEL_INLINE PadeTerms exp_pade_terms(double r) {
  const double rr = r * r;
  const double p = r * ((1.26177193074810590878e-4 * rr + 3.02994407707441961300e-2) * rr +
                        9.99999999999999999910e-1);
  const double q = ((3.00198505138664455042e-6 * rr + 2.52448340349684104192e-3) * rr +
                    2.27265548208155028766e-1) * rr + 2.00000000000000000009e0;
  return {p, q};
}
PHNN_KERNEL_INLINE double exp_pade(double r) {
  const PadeTerms t = exp_pade_terms(r);
  const double e = 1.0 + 2.0 * t.p / (t.q - t.p);
  return e;
}

// tanh with one division (kernel set 2), both branches computed and blended:
//   |x| < 0.625:  x + (x z num(z)) / den(z), z = x^2 (Cephes' rational form);
//   else, a = min(|x|, 22), e^{2a} = 2^k (q + p) / (q - p) (the exp reduction
//   and Pade form below): tanh a = 1 - 2 / (e^{2a} + 1)
//                                = 1 - 2 (q - p) / (2^k (q + p) + (q - p)),
// the sign of x restored. Within 1.6 ulp of the exact tanh (measured: 1.59 at
// worst near |x| = 0.625 over 4e7 random points of [0.3, 3] and a log grid of
// [1e-20, 31.6]; VectorTanhTest), as kernel set 1's two-division form (1.45).
PHNN_KERNEL_INLINE double tanh_one(double x) {
  const double z = x * x;
  const double num = (-9.64399179425052238628e-1 * z - 9.92877231001918586564e1) * z -
                     1.61468768441708447952e3;
  const double den = ((z + 1.12811678491632931402e2) * z + 2.23548839060100448583e3) * z +
                     4.84406305325125486048e3;
  double a = std::fabs(x);
  a = a < 22.0 ? a : 22.0;
  const double two_a = 2.0 * a;
  const double t = two_a * kLog2e + kShifter;
  const double k = t - kShifter;
  const PadeTerms e = exp_pade_terms((two_a - k * kLn2Hi) - k * kLn2Lo);
  const double up = (e.q + e.p) * power_of_two(bits_of(t) - bits_of(kShifter)), down = e.q - e.p;
  const bool small = std::fabs(x) < 0.625;
  const double f = (small ? x * z * num : 2.0 * down) / (small ? den : up + down);
  const double y = small ? x + f : std::copysign(1.0 - f, x);
  return x == x && x != 0.0 ? y : x;  // NaN in, NaN out; -0 stays -0
}

PHNN_KERNEL_INLINE void tanh_body(const double* x, double* y, int64_t n) {
  for (int64_t i = 0; i < n; ++i) y[i] = tanh_one(x[i]);
}

// exp(x) for x <= 0 or NaN without a branch (exp_nonpositive and
// softplus_sigmoid_array): the exp reduction of tanh_one and the Pade form,
// with 2^k applied in two normal halves 2^k1 2^k2 so results down to the
// subnormals (x > -745.2) come out right; the selects at the end give NaN,
// 0 below -745.2 and 1 at 0.
PHNN_KERNEL_INLINE double exp_nonpositive_lane(double x) {
  const double xc = x < -745.2 ? -745.2 : x == x ? x : 0.0;  // the lanes selected away stay finite
  const double t = xc * kLog2e + kShifter;
  const double k = t - kShifter;
  const double r = (xc - k * kLn2Hi) - k * kLn2Lo;
  const double e = exp_pade(r);
  const int64_t ki = bits_of(t) - bits_of(kShifter);
  const int64_t k1 = ki / 2, k2 = ki - k1;
  const double value = e * power_of_two(k1) * power_of_two(k2);
  return x != x ? x : x < -745.2 ? 0.0 : x == 0.0 ? 1.0 : value;
}

// log(1 + z) = 2 atanh(s), s = z / (2 + z) in [0, 1/3] for z in [0, 1]:
// atanh s = s (1 + s^2/3 + s^4/5 + ...), 19 terms (s^38/39 < 2^-60). NaN
// flows through the series (no branch).
PHNN_KERNEL_INLINE double log1p_unit_lane(double z) {
  const double s = z / (2.0 + z), s2 = s * s;
  double sum = 1.0 / 39.0;
  _Pragma("GCC unroll 19") for (int k = 18; k >= 0; --k) sum = sum * s2 + 1.0 / (2 * k + 1);
  return 2.0 * s * sum;
}

PHNN_KERNEL_INLINE void softplus_sigmoid_body(const double* x, int64_t n, double* softplus,
                                              double* sigmoid, double* slope) {
  for (int64_t i = 0; i < n; ++i) {
    const double v = x[i];
    const double z = exp_nonpositive_lane(-std::fabs(v));
    const double s = v >= 0.0 ? 1.0 / (1.0 + z) : z / (1.0 + z);
    const double l = log1p_unit_lane(z);
    softplus[i] = v > 20.0 ? v : (v > 0.0 ? v : 0.0) + l;
    sigmoid[i] = s;
    slope[i] = v > 20.0 ? 1.0 : s;
  }
}

}  // namespace

// The scalar forms of the two loop bodies above (the same operations, so the
// same bits as softplus_sigmoid_array); x > 0 falls back to the correctly
// rounded exp.
double exp_nonpositive(double x) { return x > 0.0 ? cr::exp(x) : exp_nonpositive_lane(x); }

double log1p_unit(double z) { return z != z ? z : log1p_unit_lane(z); }

PHNN_KERNEL_VARIANTS(void, tanh_array, (const double* x, double* y, int64_t n), (x, y, n),
                     tanh_body)

PHNN_KERNEL_VARIANTS(void, softplus_sigmoid_array,
                     (const double* x, int64_t n, double* softplus, double* sigmoid, double* slope),
                     (x, n, softplus, sigmoid, slope), softplus_sigmoid_body)

}  // namespace internal
}  // namespace phnn
