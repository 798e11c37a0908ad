// src/common/mpfr_binary64.h — GNU MPFR evaluated as binary64 arithmetic:
// the exact value of a function at doubles, rounded once to the nearest
// double (ties to even), subnormals and overflow as IEEE 754 has them. The
// slow path and the reference of src/common/cr_math.cpp.
#pragma once

#include <mpfr.h>

namespace phnn {
namespace cr {
namespace internal {

using MpfrUnary = int (*)(mpfr_ptr, mpfr_srcptr, mpfr_rnd_t);
using MpfrBinary = int (*)(mpfr_ptr, mpfr_srcptr, mpfr_srcptr, mpfr_rnd_t);

/// f(x) correctly rounded to a double (f: mpfr_sin, mpfr_exp, ...).
double by_mpfr(MpfrUnary f, double x);
/// f(x, y) correctly rounded to a double (f: mpfr_pow, ...).
double by_mpfr(MpfrBinary f, double x, double y);

}  // namespace internal
}  // namespace cr
}  // namespace phnn
