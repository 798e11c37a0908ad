// src/kernels/vector_math.h — tanh over arrays, written so the compiler
// vectorizes it (AVX-512 / AVX2 / baseline copies, kernel_isa.h), for the fused
// networks. LibTorch's tanh on this build goes through Sleef's 1-ulp AVX2
// kernel at ~5 ns per element, 20 % of a small training step (perf).
#pragma once

#include <cstdint>

namespace phnn {
namespace internal {

/// y[i] = tanh(x[i]) for i < n, within 1.6 ulp of the exact tanh (tested
/// against long double), NaN and +-inf handled like std::tanh. x and y may alias.
///
/// Method (the Cephes library's rational forms, S. L. Moshier, with one
/// division per element): for |x| < 0.625 the odd rational approximation
/// tanh x = x + x^3 P(x^2) / Q(x^2); otherwise tanh |x| = 1 - 2 / (exp(2|x|)
/// + 1) with |x| clamped at 22 (where tanh rounds to 1), exp by the
/// reduction 2|x| = k ln 2 + r, |r| <= ln2/2, exp r = (q + p) / (q - p)
/// (p = r P(r^2), q = Q(r^2): a Pade form) times 2^k built from its bits,
/// so tanh |x| = 1 - 2 (q - p) / (2^k (q + p) + (q - p)). Both branches are
/// computed and blended before their one division, so the loop has no
/// branch and vectorizes.
void tanh_array(const double* x, double* y, int64_t n);

/// exp(x) for x <= 0 (0 below -745.2, NaN stays NaN; x > 0 falls back to
/// std::exp), within 2 ulp of
/// std::exp (tested). Our own, like tanh_array: glibc picks its exp by CPU
/// (an FMA variant), which could change last bits between machines.
double exp_nonpositive(double x);

/// log(1 + z) for 0 <= z <= 1, within 3 ulp of std::log1p (tested); by
/// the series of 2 atanh(z / (2 + z)), for the same reason.
double log1p_unit(double z);

/// softplus(x[i]), sigmoid(x[i]) and softplus'(x[i]) for i < n, bit for bit
/// what heads::SoftplusSigmoid(x[i]) gives (fused_heads_common.h: one
/// exp(-|x|), softplus = x and slope 1 above 20), written without branches
/// so the loop vectorizes (tested against the scalar form, NaN and +-inf
/// included). The fused heads call it once per tensor instead of per row.
void softplus_sigmoid_array(const double* x, int64_t n, double* softplus, double* sigmoid,
                            double* slope);

}  // namespace internal
}  // namespace phnn
