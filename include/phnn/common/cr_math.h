// include/phnn/common/cr_math.h — correctly rounded elementary functions:
// the same bits on every CPU and with every C library.
//
// glibc picks its sin, cos, exp, log, pow, atan, ... at load time by the
// CPU's FMA and AVX2 support (ifunc), and the variants round differently on
// ~0.1 % of arguments (measured: docs/METHOD.md "Deterministic kernels").
// A correctly rounded result is defined by the argument alone, so these
// functions give one answer wherever they run: the double nearest to the
// exact value (ties to even). sin, cos, exp, log, sinh, cosh and tanh take
// a fast path in double-double arithmetic and return its result when an
// error bound proves which double is nearest; otherwise, and for every other
// function, GNU MPFR computes it. Used wherever a result depends on an elementary
// function: data generation (initial states, controls, measurement noise)
// and system-file expressions. The models' activations have their own
// pinned kernels (src/models/pinned_activations.h). Assumes the default
// rounding mode (to nearest), which nothing in phnn changes.
#pragma once

namespace phnn {
namespace cr {

double sin(double x);
double cos(double x);
double tan(double x);
double asin(double x);
double acos(double x);
double atan(double x);
double sinh(double x);
double cosh(double x);
double tanh(double x);
double asinh(double x);
double acosh(double x);
double atanh(double x);
double exp(double x);
double log(double x);
double cbrt(double x);
double pow(double x, double y);

/// How many calls of the fast-path functions (sin, cos, exp, log, sinh,
/// cosh, tanh) in this thread MPFR computed: the rounding test did not
/// decide, or the argument is outside the path's range (|x| >= 2^20 for
/// sin/cos, |x| > 700 for exp/sinh/cosh, 0, subnormal or non-finite for
/// log). For tests and benchmarks.
long fallback_count();

namespace internal {
/// Tests: run the fast paths' baseline build (Dekker products) even on a
/// CPU with FMA; not thread-safe, set before the calls it affects.
void use_baseline_fast_paths(bool on);
}  // namespace internal

}  // namespace cr
}  // namespace phnn
