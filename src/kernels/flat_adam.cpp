// src/kernels/flat_adam.cpp — Adam on one contiguous parameter tensor
// (phnn/kernels/flat_adam.h), one fixed operation order.
#include "phnn/kernels/flat_adam.h"

#include <cmath>
#include <type_traits>

#include "kernels/kernel_isa.h"
#include "phnn/common/check.h"

namespace phnn {

namespace {

// b^t by repeated squaring: the same few correctly rounded products on
// every CPU (std::pow is chosen by glibc per CPU and is not correctly
// rounded, so it could differ between machines).
double integer_power(double b, int64_t t) {
  double result = 1.0;
  for (; t > 0; t >>= 1, b *= b)
    if (t & 1) result *= b;
  return result;
}

struct AdamScalars {
  double b1, b2, step, root_correction2, eps;
};

// One element per iteration, each operation rounded on its own (no
// contraction, no library function but sqrt, which IEEE 754 rounds
// correctly): the same bits on every CPU, vectorized or not. LibTorch's
// add_(g, alpha) fused the multiply-add only in its vectorized AVX2/AVX-512
// kernels, so the old tensor form changed with ATEN_CPU_CAPABILITY.
//   m = b1 m + (1 - b1) g
//   v = b2 v + ((1 - b2) g) g
//   p = p + (-lr / (1 - b1^t)) m / (sqrt(v) / sqrt(1 - b2^t) + eps)
// in T (float32 training: the scalars rounded to float first). Compiled per
// instruction set (kernel_isa.h) and without errno for sqrt (this file's
// -fno-math-errno; v >= 0 or NaN), so the loop vectorizes: it was scalar,
// 2.6 % of a small training step.
template <typename T>
struct AdamArrays {
  T* __restrict__ p;
  T* __restrict__ m;
  T* __restrict__ v;
  const T* __restrict__ g;
  int64_t n;
  T b1, b2, c1, c2, step, root2, eps;
};

template <typename T>
PHNN_KERNEL_INLINE void adam_body(const AdamArrays<T>& a) {
  T* __restrict__ p = a.p;
  T* __restrict__ m = a.m;
  T* __restrict__ v = a.v;
  const T* __restrict__ g = a.g;
  for (int64_t k = 0; k < a.n; ++k) {
    m[k] = a.b1 * m[k] + a.c1 * g[k];
    v[k] = a.b2 * v[k] + a.c2 * g[k] * g[k];
    p[k] = p[k] + a.step * m[k] / (std::sqrt(v[k]) / a.root2 + a.eps);
  }
}

PHNN_KERNEL_VARIANTS(void, adam_double, (const AdamArrays<double>& a), (a), adam_body<double>)
PHNN_KERNEL_VARIANTS(void, adam_float, (const AdamArrays<float>& a), (a), adam_body<float>)

template <typename T>
void adam_update(const torch::Tensor& p_t, const torch::Tensor& g_t, const torch::Tensor& m_t,
                 const torch::Tensor& v_t, const AdamScalars& s) {
  const AdamArrays<T> a{p_t.data_ptr<T>(),           m_t.data_ptr<T>(),
                        v_t.data_ptr<T>(),           g_t.data_ptr<T>(),
                        p_t.numel(),                 static_cast<T>(s.b1),
                        static_cast<T>(s.b2),        static_cast<T>(1 - s.b1),
                        static_cast<T>(1 - s.b2),    static_cast<T>(s.step),
                        static_cast<T>(s.root_correction2), static_cast<T>(s.eps)};
  if constexpr (std::is_same<T, float>::value) {
    adam_float(a);
  } else {
    adam_double(a);
  }
}

}  // namespace

FlatAdam::FlatAdam(torch::Tensor values, torch::Tensor gradients, const TrainerOptions& options)
    : p_(std::move(values)),
      g_(std::move(gradients)),
      lr_(options.learning_rate),
      b1_(options.adam_beta1),
      b2_(options.adam_beta2),
      eps_(options.adam_eps) {
  PHNN_CHECK(p_.is_contiguous() && g_.is_contiguous() && p_.sizes() == g_.sizes(),
             "FlatAdam needs contiguous value and gradient buffers of one shape");
  m_ = torch::zeros_like(p_, torch::MemoryFormat::Preserve);
  v_ = torch::zeros_like(p_, torch::MemoryFormat::Preserve);
}

void FlatAdam::restore(const torch::Tensor& m, const torch::Tensor& v, int64_t steps_taken) {
  torch::NoGradGuard no_grad;
  m_.copy_(m);
  v_.copy_(v);
  t_ = steps_taken;
}

void FlatAdam::zero_grad() { g_.zero_(); }

void FlatAdam::step() {
  ++t_;
  const double bias_correction1 = 1 - integer_power(b1_, t_);
  const double root_correction2 = std::sqrt(1 - integer_power(b2_, t_));
  const double step = -lr_ / bias_correction1;
  if (p_.scalar_type() == torch::kFloat32) {
    adam_update<float>(p_, g_, m_, v_, {b1_, b2_, step, root_correction2, eps_});
  } else {
    adam_update<double>(p_, g_, m_, v_, {b1_, b2_, step, root_correction2, eps_});
  }
}

}  // namespace phnn
