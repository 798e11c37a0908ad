// src/report/statistics.cpp — quantiles with exact infinities; percentile
// bootstrap of the median from a self-contained generator.
#include "phnn/report/statistics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "phnn/data/counter_rng.h"

namespace phnn {

double quantile_linear_sorted(const std::vector<double>& sorted, double q) {
  // numpy 'linear' (Hyndman & Fan type 7): h = (n - 1) q.
  const double h = static_cast<double>(sorted.size() - 1) * q;
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double frac = h - static_cast<double>(lo);
  const double a = sorted[lo], b = sorted[hi];
  // Equal neighbours (two +inf included: inf - inf would be NaN) and an
  // infinite neighbour with a weight > 0 are exact.
  if (frac == 0.0 || a == b) return a;
  if (std::isinf(b) && b > 0) return b;
  if (std::isinf(a) && a < 0) return a;
  return a + frac * (b - a);
}

double quantile_linear(std::vector<double> values, double q) {
  if (values.empty()) throw std::invalid_argument("quantile_linear: no values");
  if (!(q >= 0.0 && q <= 1.0)) {
    throw std::invalid_argument("quantile_linear: q = " + std::to_string(q) +
                                "; violated constraint: 0 <= q <= 1");
  }
  for (double v : values) {
    if (std::isnan(v)) throw std::invalid_argument("quantile_linear: values contain NaN");
  }
  std::sort(values.begin(), values.end());
  return quantile_linear_sorted(values, q);
}

void BootstrapOptions::validate() const {
  if (resamples < 2000) {
    throw std::invalid_argument("Invalid BootstrapOptions: resamples = " +
                                std::to_string(resamples) +
                                "; violated constraint: resamples >= 2000");
  }
  if (!(confidence > 0.0 && confidence < 1.0)) {
    throw std::invalid_argument("Invalid BootstrapOptions: confidence = " +
                                std::to_string(confidence) +
                                "; violated constraint: 0 < confidence < 1");
  }
}

std::vector<double> bootstrap_medians(const std::vector<double>& values,
                                      const BootstrapOptions& options) {
  options.validate();
  if (values.empty()) throw std::invalid_argument("bootstrap_medians: no values");
  for (double v : values) {
    if (std::isnan(v)) throw std::invalid_argument("bootstrap_medians: values contain NaN");
  }
  // Sorted first, so the medians depend on the multiset of values only, not
  // on the order the runs were stored in.
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const std::uint64_t n = sorted.size();
  CounterRng rng(options.seed);
  std::vector<double> sample(sorted.size());
  std::vector<double> medians;
  medians.reserve(static_cast<std::size_t>(options.resamples));
  for (int b = 0; b < options.resamples; ++b) {
    for (double& x : sample) x = sorted[rng.below(n)];
    std::sort(sample.begin(), sample.end());
    medians.push_back(quantile_linear_sorted(sample, 0.5));
  }
  return medians;
}

Interval bootstrap_median_interval(const std::vector<double>& values,
                                   const BootstrapOptions& options) {
  std::vector<double> medians = bootstrap_medians(values, options);
  std::sort(medians.begin(), medians.end());
  const double tail = (1.0 - options.confidence) / 2.0;
  return Interval{quantile_linear_sorted(medians, tail),
                  quantile_linear_sorted(medians, 1.0 - tail)};
}

}  // namespace phnn
