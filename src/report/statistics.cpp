// src/report/statistics.cpp — quantiles with exact infinities, the
// interquartile mean; percentile bootstrap of a median or an IQM from a
// self-contained generator.
#include "phnn/report/statistics.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string_view>
#include <unordered_map>

#include "phnn/data/counter_rng.h"

namespace phnn {

namespace {
// The type-7 interpolation between neighbours a = s[lo] and b = s[hi] of a
// sorted sample at weight frac (quantile_linear_sorted's last step).
double interpolate_linear(double a, double b, double frac) {
  // Equal neighbours (two +inf included: inf - inf would be NaN) and an
  // infinite neighbour with a weight > 0 are exact.
  if (frac == 0.0 || a == b) return a;
  if (std::isinf(b) && b > 0) return b;
  if (std::isinf(a) && a < 0) return a;
  return a + frac * (b - a);
}

// numpy 'linear' (Hyndman & Fan type 7): h = (n - 1) q, lo = floor(h),
// hi = min(lo + 1, n - 1), frac = h - lo.
struct LinearPosition {
  std::size_t lo, hi;
  double frac;
};
LinearPosition linear_position(std::size_t n, double q) {
  const double h = static_cast<double>(n - 1) * q;
  const std::size_t lo = static_cast<std::size_t>(std::floor(h));
  return {lo, std::min(lo + 1, n - 1), h - static_cast<double>(lo)};
}

// quantile_linear_sorted(sort(values), q) without the sort: two selections
// (the order statistics s[lo] and s[hi] are values of the multiset, so the
// result is the same double). Reorders `values`.
double quantile_linear_select(std::vector<double>& values, double q) {
  const LinearPosition p = linear_position(values.size(), q);
  const auto lo = values.begin() + static_cast<std::ptrdiff_t>(p.lo);
  std::nth_element(values.begin(), lo, values.end());
  const double a = *lo;
  const double b = p.hi == p.lo ? a : *std::min_element(lo + 1, values.end());
  return interpolate_linear(a, b, p.frac);
}
}  // namespace

double quantile_linear_sorted(const std::vector<double>& sorted, double q) {
  const LinearPosition p = linear_position(sorted.size(), q);
  return interpolate_linear(sorted[p.lo], sorted[p.hi], p.frac);
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

namespace {
// The checks every bootstrap makes, then the values sorted: the draws
// depend on the multiset of values only, not on the order the runs were
// stored in.
std::vector<double> checked_sorted(const std::vector<double>& values,
                                   const BootstrapOptions& options) {
  options.validate();
  if (values.empty()) throw std::invalid_argument("bootstrap: no values");
  for (double v : values) {
    if (std::isnan(v)) throw std::invalid_argument("bootstrap: values contain NaN");
  }
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

// bootstrap_statistics on values already checked and sorted.
std::vector<double> statistics_of_sorted(const std::vector<double>& sorted,
                                         const BootstrapOptions& options,
                                         double (*statistic)(const std::vector<double>& sorted)) {
  const std::uint64_t n = sorted.size();
  CounterRng rng(options.seed);
  // Each resample is sorted by counting how often each index of `sorted` is
  // drawn and writing sorted[j] that many times, in order of j: the same
  // sorted sample as sorting the drawn values, in O(n) (the values only
  // repeat or grow with j; +0 and -0 aside, equal values are equal bits).
  std::vector<double> sample(sorted.size());
  std::vector<std::uint32_t> drawn(sorted.size());
  std::vector<double> draws;
  draws.reserve(static_cast<std::size_t>(options.resamples));
  for (int b = 0; b < options.resamples; ++b) {
    std::fill(drawn.begin(), drawn.end(), 0U);
    for (std::uint64_t i = 0; i < n; ++i) ++drawn[rng.below(n)];
    auto out = sample.begin();
    for (std::size_t j = 0; j < sorted.size(); ++j) out = std::fill_n(out, drawn[j], sorted[j]);
    draws.push_back(statistic(sample));
  }
  return draws;
}
}  // namespace

std::vector<double> bootstrap_statistics(const std::vector<double>& values,
                                         const BootstrapOptions& options,
                                         double (*statistic)(const std::vector<double>& sorted)) {
  return statistics_of_sorted(checked_sorted(values, options), options, statistic);
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
  const double tail = (1.0 - confidence) / 2.0;
  const double low = quantile_linear_select(draws, tail);
  return Interval{low, quantile_linear_select(draws, 1.0 - tail)};
}

namespace {
// A memo of the percentile intervals computed in this process. An interval
// is a function of the sorted values and the options alone (bootstrap_
// statistics), and a reducer that replays adaptive rounds asks for the same
// cell's interval in every round and every table that shows it. Keys hold
// the values' bits, so a hit returns exactly what the computation would.
enum class Statistic : int { kMedian, kIqm };
struct IntervalKey {
  Statistic statistic;
  int resamples;
  std::uint64_t seed;
  double confidence;
  std::vector<double> sorted;
  std::string_view bytes() const {
    return {reinterpret_cast<const char*>(sorted.data()), sorted.size() * sizeof(double)};
  }
  bool operator==(const IntervalKey& o) const {
    return statistic == o.statistic && resamples == o.resamples && seed == o.seed &&
           std::memcmp(&confidence, &o.confidence, sizeof(double)) == 0 && bytes() == o.bytes();
  }
};
struct IntervalKeyHash {
  std::size_t operator()(const IntervalKey& k) const {
    return std::hash<std::string_view>{}(k.bytes()) ^ static_cast<std::size_t>(k.seed) ^
           (static_cast<std::size_t>(k.resamples) << 1) ^ static_cast<std::size_t>(k.statistic);
  }
};

Interval memoized_interval(Statistic statistic, const std::vector<double>& values,
                           const BootstrapOptions& options) {
  constexpr std::size_t kMaxEntries = 1 << 14;  // a coverage study's samples never repeat
  static std::mutex mutex;
  static std::unordered_map<IntervalKey, Interval, IntervalKeyHash> memo;
  IntervalKey key{statistic, options.resamples, options.seed, options.confidence,
                  checked_sorted(values, options)};
  {
    const std::lock_guard<std::mutex> lock(mutex);
    const auto hit = memo.find(key);
    if (hit != memo.end()) return hit->second;
  }
  const Interval interval = percentile_interval(
      statistics_of_sorted(
          key.sorted, options,
          statistic == Statistic::kMedian ? median_sorted : interquartile_mean_sorted),
      options.confidence);
  const std::lock_guard<std::mutex> lock(mutex);
  if (memo.size() >= kMaxEntries) memo.clear();
  memo.emplace(std::move(key), interval);
  return interval;
}
}  // namespace

Interval bootstrap_median_interval(const std::vector<double>& values,
                                   const BootstrapOptions& options) {
  return memoized_interval(Statistic::kMedian, values, options);
}

Interval bootstrap_iqm_interval(const std::vector<double>& values,
                                const BootstrapOptions& options) {
  return memoized_interval(Statistic::kIqm, values, options);
}

}  // namespace phnn
