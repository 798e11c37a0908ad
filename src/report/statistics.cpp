// src/report/statistics.cpp — quantiles with exact infinities, the
// interquartile mean; percentile bootstrap of a median or an IQM from a
// self-contained generator.
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

// IQM = mean of s[g .. n-1-g], g = floor(n / 4) (statistics.h; scipy's
// trim_mean(x, 0.25) cuts int(0.25 n) from each end).
double interquartile_mean_sorted(const std::vector<double>& sorted) {
  const std::size_t g = sorted.size() / 4;
  double sum = 0.0;
  for (std::size_t i = g; i + g < sorted.size(); ++i) sum += sorted[i];
  return sum / static_cast<double>(sorted.size() - 2 * g);
}

double interquartile_mean(std::vector<double> values) {
  if (values.empty()) throw std::invalid_argument("interquartile_mean: no values");
  for (double v : values) {
    if (std::isnan(v)) throw std::invalid_argument("interquartile_mean: values contain NaN");
  }
  std::sort(values.begin(), values.end());
  return interquartile_mean_sorted(values);
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

std::vector<double> bootstrap_statistics(const std::vector<double>& values,
                                         const BootstrapOptions& options,
                                         double (*statistic)(const std::vector<double>& sorted)) {
  options.validate();
  if (values.empty()) throw std::invalid_argument("bootstrap: no values");
  for (double v : values) {
    if (std::isnan(v)) throw std::invalid_argument("bootstrap: values contain NaN");
  }
  // Sorted first, so the draws depend on the multiset of values only, not
  // on the order the runs were stored in.
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  const std::uint64_t n = sorted.size();
  CounterRng rng(options.seed);
  std::vector<double> sample(sorted.size());
  std::vector<double> draws;
  draws.reserve(static_cast<std::size_t>(options.resamples));
  for (int b = 0; b < options.resamples; ++b) {
    for (double& x : sample) x = sorted[rng.below(n)];
    std::sort(sample.begin(), sample.end());
    draws.push_back(statistic(sample));
  }
  return draws;
}

namespace {
double median_sorted(const std::vector<double>& sorted) {
  return quantile_linear_sorted(sorted, 0.5);
}
}  // namespace

std::vector<double> bootstrap_medians(const std::vector<double>& values,
                                      const BootstrapOptions& options) {
  return bootstrap_statistics(values, options, median_sorted);
}

Interval percentile_interval(std::vector<double> draws, double confidence) {
  std::sort(draws.begin(), draws.end());
  const double tail = (1.0 - confidence) / 2.0;
  return Interval{quantile_linear_sorted(draws, tail), quantile_linear_sorted(draws, 1.0 - tail)};
}

Interval bootstrap_median_interval(const std::vector<double>& values,
                                   const BootstrapOptions& options) {
  return percentile_interval(bootstrap_medians(values, options), options.confidence);
}

Interval bootstrap_iqm_interval(const std::vector<double>& values,
                                const BootstrapOptions& options) {
  return percentile_interval(bootstrap_statistics(values, options, interquartile_mean_sorted),
                             options.confidence);
}

}  // namespace phnn
