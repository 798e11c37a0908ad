// src/common/double_double.h — double-double arithmetic for the fast paths
// of src/common/cr_math.cpp: a value as an unevaluated sum hi + lo of two
// doubles (~106 bits). Error-free transformations (Knuth's TwoSum, Dekker's
// FastTwoSum and product) and the QD library's add, multiply and divide, in
// a fixed order of IEEE operations (the build pins -ffp-contract=off), so
// the same inputs give the same bits on every CPU. kFma selects how a
// product's exact error is found: one fused multiply-add, or Dekker's split;
// the error is unique, so both give the same bits.
#pragma once

namespace phnn {
namespace cr {
namespace internal {

struct Dd {
  double hi, lo;
};

// a + b = s + e exactly.
inline Dd two_sum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}

// The same for |a| >= |b| or a = 0.
inline Dd fast_two_sum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}

// Veltkamp's split a = hi + lo, each with at most 26 significant bits.
inline Dd split(double a) {
  const double c = 134217729.0 * a;  // (2^27 + 1) a
  const double hi = c - (c - a);
  return {hi, a - hi};
}

// a b = p + e exactly (|a|, |b| far from overflow and underflow). The error
// e is unique, so the FMA clone (one fused multiply-add) and Dekker's split
// (baseline x86-64) give the same bits.
template <bool kFma>
[[gnu::always_inline]] inline Dd two_prod(double a, double b) {
  const double p = a * b;
  if (kFma) return {p, __builtin_fma(a, b, -p)};
  const Dd x = split(a), y = split(b);
  return {p, ((x.hi * y.hi - p) + x.hi * y.lo + x.lo * y.hi) + x.lo * y.lo};
}

inline Dd dd_add(Dd a, Dd b) {
  Dd s = two_sum(a.hi, b.hi);
  const Dd t = two_sum(a.lo, b.lo);
  s.lo += t.hi;
  s = fast_two_sum(s.hi, s.lo);
  s.lo += t.lo;
  return fast_two_sum(s.hi, s.lo);
}

template <bool kFma>
[[gnu::always_inline]] inline Dd dd_mul(Dd a, Dd b) {
  Dd p = two_prod<kFma>(a.hi, b.hi);
  p.lo += a.hi * b.lo + a.lo * b.hi;
  return fast_two_sum(p.hi, p.lo);
}

template <bool kFma>
[[gnu::always_inline]] inline Dd dd_mul_d(Dd a, double b) {
  Dd p = two_prod<kFma>(a.hi, b);
  p.lo += a.lo * b;
  return fast_two_sum(p.hi, p.lo);
}

inline Dd dd_neg(Dd a) { return {-a.hi, -a.lo}; }

// a / b with three quotient digits (QD's accurate division).
template <bool kFma>
[[gnu::always_inline]] inline Dd dd_div(Dd a, Dd b) {
  const double q1 = a.hi / b.hi;
  Dd r = dd_add(a, dd_mul_d<kFma>(b, -q1));
  const double q2 = r.hi / b.hi;
  r = dd_add(r, dd_mul_d<kFma>(b, -q2));
  const double q3 = r.hi / b.hi;
  return dd_add(fast_two_sum(q1, q2), Dd{q3, 0.0});
}

}  // namespace internal
}  // namespace cr
}  // namespace phnn
