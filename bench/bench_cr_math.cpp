// bench/bench_cr_math.cpp — ns per call of the correctly rounded functions
// (include/phnn/common/cr_math.h) against the C library's, and how many
// calls fell back to MPFR (not a test; numbers in docs/BENCHMARKS.md).
//
//   bench_cr_math [repeats]   medians of `repeats` passes over 10^6 arguments
//                             per range (2 10^4 for MPFR-only atan), the C library and phnn::cr alternated
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "phnn/common/cr_math.h"

namespace {

struct Case {
  const char* name;
  double lo, hi;
  double (*libc)(double);
  double (*ours)(double);
  int arguments;  // fewer for the MPFR-only functions (~2 us a call)
};

volatile double sink = 0.0;

// ns per call of f over xs (the sum keeps the calls).
double ns_per_call(double (*f)(double), const std::vector<double>& xs) {
  const auto t0 = std::chrono::steady_clock::now();
  double s = 0.0;
  for (double x : xs) s += f(x);
  sink = sink + s;
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return dt * 1e9 / static_cast<double>(xs.size());
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const Case cases[] = {
      {"sin", -0.7, 0.7, [](double x) { return std::sin(x); }, phnn::cr::sin, 1000000},
      {"sin", -7.0, 7.0, [](double x) { return std::sin(x); }, phnn::cr::sin, 1000000},
      {"cos", -7.0, 7.0, [](double x) { return std::cos(x); }, phnn::cr::cos, 1000000},
      {"exp", -5.0, 5.0, [](double x) { return std::exp(x); }, phnn::cr::exp, 1000000},
      {"log", 1e-3, 1e3, [](double x) { return std::log(x); }, phnn::cr::log, 1000000},
      {"tanh", -3.0, 3.0, [](double x) { return std::tanh(x); }, phnn::cr::tanh, 1000000},
      {"sinh", -3.0, 3.0, [](double x) { return std::sinh(x); }, phnn::cr::sinh, 1000000},
      {"atan", -5.0, 5.0, [](double x) { return std::atan(x); }, phnn::cr::atan, 20000},
  };
  std::printf("function,range,libc_ns,cr_ns,cr_over_libc,mpfr_fallbacks_per_1e6\n");
  for (const Case& c : cases) {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(c.lo, c.hi);
    std::vector<double> xs(static_cast<std::size_t>(c.arguments));
    for (double& x : xs) x = u(rng);
    std::vector<double> libc, ours;
    long fallbacks = 0;
    for (int r = 0; r < repeats; ++r) {
      libc.push_back(ns_per_call(c.libc, xs));
      const long before = phnn::cr::fallback_count();
      ours.push_back(ns_per_call(c.ours, xs));
      fallbacks = phnn::cr::fallback_count() - before;
    }
    const double a = median(libc), b = median(ours);
    std::printf("%s,[%g %g],%.1f,%.1f,%.1f,%.0f\n", c.name, c.lo, c.hi, a, b, b / a,
                1e6 * static_cast<double>(fallbacks) / static_cast<double>(xs.size()));
  }
  return 0;
}
