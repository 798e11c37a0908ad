// src/kernels/kernel_isa.cpp — see kernel_isa.h.
#include "kernels/kernel_isa.h"

#include <atomic>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace phnn {
namespace internal {
namespace {

KernelIsa cpu_isa() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("x86-64-v4")) return KernelIsa::kAvx512;
  if (__builtin_cpu_supports("x86-64-v3")) return KernelIsa::kAvx2;
  return KernelIsa::kBaseline;
}

// The lower of two sets: a request never raises what the CPU has.
KernelIsa lower(KernelIsa a, KernelIsa b) { return static_cast<int>(a) < static_cast<int>(b) ? a : b; }

KernelIsa decide() {
  const KernelIsa best = cpu_isa();
  const char* env = std::getenv("PHNN_KERNEL_ISA");
  if (env == nullptr || *env == '\0') return best;
  const std::string v(env);
  KernelIsa asked{};
  if (!kKernelIsaNames.find(v, &asked)) {
    throw std::runtime_error("PHNN_KERNEL_ISA=" + v + ": expected " + kKernelIsaNames.list() +
                             " (or unset: the CPU's best)");
  }
  return lower(asked, best);
}

KernelIsa decided() {
  static const KernelIsa isa = decide();
  return isa;
}

std::atomic<int> forced{-1};  // ScopedKernelIsa's choice, or -1

}  // namespace

KernelIsa kernel_isa() {
  const int f = forced.load(std::memory_order_relaxed);
  return f >= 0 ? static_cast<KernelIsa>(f) : decided();
}

ScopedKernelIsa::ScopedKernelIsa(KernelIsa isa) : previous_(forced.load()) {
  forced.store(static_cast<int>(lower(isa, cpu_isa())));
}

ScopedKernelIsa::~ScopedKernelIsa() { forced.store(previous_); }

std::string kernel_description() {
  std::string cpu;  // __builtin_cpu_supports takes literals only
  if (__builtin_cpu_supports("avx512f")) cpu += " avx512f";
  if (__builtin_cpu_supports("avx2")) cpu += " avx2";
  if (__builtin_cpu_supports("fma")) cpu += " fma";
  cpu = cpu.empty() ? "baseline" : cpu.substr(1);
  return "phnn kernels " + std::to_string(kKernelSet) + "; " + kernel_isa_name(kernel_isa()) +
         " of " + kernel_isa_name(cpu_isa()) + " (CPU: " + cpu + ")";
}

}  // namespace internal
}  // namespace phnn
