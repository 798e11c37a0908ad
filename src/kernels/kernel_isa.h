// src/kernels/kernel_isa.h — which instruction set our own kernels run on
// (the member GEMM, tanh, the jet maps, Adam): chosen once per process from
// the CPU, or pinned with PHNN_KERNEL_ISA. Every choice gives the same bits
// (docs/METHOD.md "Deterministic kernels"); the variable exists so a test can
// run all of them on one machine.
#pragma once

#include <string>

#include "phnn/common/enum_names.h"

namespace phnn {
namespace internal {

/// The instruction sets a kernel is compiled for: baseline x86-64 (SSE2),
/// x86-64-v3 (AVX2 + FMA) and x86-64-v4 (AVX-512).
enum class KernelIsa { kBaseline = 0, kAvx2 = 1, kAvx512 = 2 };

/// The set in use: the best the CPU has, lowered (never raised) by
/// PHNN_KERNEL_ISA = baseline | avx2 | avx512. An unknown value throws
/// std::runtime_error naming it. Decided at the first call, then fixed.
KernelIsa kernel_isa();

inline constexpr EnumNames<KernelIsa, 3> kKernelIsaNames{
    "PHNN_KERNEL_ISA",
    {{{KernelIsa::kBaseline, "baseline"}, {KernelIsa::kAvx2, "avx2"}, {KernelIsa::kAvx512, "avx512"}}}};
/// "baseline", "avx2" or "avx512".
inline std::string kernel_isa_name(KernelIsa isa) { return kKernelIsaNames.name(isa); }

/// The version of our kernels' arithmetic: results are bitwise equal across
/// CPUs within one kernel set; it changes when a kernel's operation order
/// does (then the results change by round-off). Set 2: gradH in reverse mode
/// (fused_mlp_gradient.h), tanh with one division (vector_math.h).
constexpr int kKernelSet = 2;

/// For provenance: "phnn kernels 2; avx512 of avx512 (CPU: avx512f avx2 fma)".
std::string kernel_description();

/// For tests: kernel_isa() returns `isa` (capped by the CPU) while this
/// object lives, so one process can compare every instruction set. One
/// process-wide setting: do not overlap scopes on several threads.
class ScopedKernelIsa {
 public:
  explicit ScopedKernelIsa(KernelIsa isa);
  ~ScopedKernelIsa();
  ScopedKernelIsa(const ScopedKernelIsa&) = delete;
  ScopedKernelIsa& operator=(const ScopedKernelIsa&) = delete;

 private:
  int previous_;
};

}  // namespace internal
}  // namespace phnn

/// Inside a function body that must be compiled per instruction set.
#define PHNN_KERNEL_INLINE inline __attribute__((always_inline))

/// Defines `ret name params` to run `body args` compiled for AVX-512, for
/// AVX2 + FMA and for baseline x86-64, picked by kernel_isa(). `body` (and
/// what it calls) must be PHNN_KERNEL_INLINE so each copy is compiled for
/// its instruction set. Example:
///   PHNN_KERNEL_VARIANTS(void, tanh_array, (const double* x, double* y, int64_t n),
///                        (x, y, n), tanh_body)
#define PHNN_KERNEL_VARIANTS(ret, name, params, args, body)                            \
  __attribute__((target("arch=x86-64-v4"))) static ret name##_avx512 params {          \
    return body args;                                                                   \
  }                                                                                     \
  __attribute__((target("arch=x86-64-v3"))) static ret name##_avx2 params {            \
    return body args;                                                                   \
  }                                                                                     \
  static ret name##_baseline params { return body args; }                              \
  ret name params {                                                                     \
    switch (::phnn::internal::kernel_isa()) {                                           \
      case ::phnn::internal::KernelIsa::kAvx512: return name##_avx512 args;             \
      case ::phnn::internal::KernelIsa::kAvx2: return name##_avx2 args;                 \
      case ::phnn::internal::KernelIsa::kBaseline: break;                               \
    }                                                                                   \
    return name##_baseline args;                                                        \
  }

namespace phnn {
namespace internal {

}  // namespace internal
}  // namespace phnn
