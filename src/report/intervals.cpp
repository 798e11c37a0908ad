// src/report/intervals.cpp — order-statistic, BCa and score intervals: the
// normal quantile, binomial and Mann-Whitney null distributions, jackknife.
#include "phnn/report/intervals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <tuple>

namespace phnn {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void require_confidence(const char* who, double confidence) {
  if (!(confidence > 0.0 && confidence < 1.0)) {
    throw std::invalid_argument(std::string(who) + ": confidence = " + std::to_string(confidence) +
                                "; violated constraint: 0 < confidence < 1");
  }
}

void require_no_nan(const char* who, const std::vector<double>& values) {
  if (values.empty()) throw std::invalid_argument(std::string(who) + ": no values");
  for (double v : values) {
    if (std::isnan(v)) throw std::invalid_argument(std::string(who) + ": values contain NaN");
  }
}

// P(B <= j), B ~ Binomial(n, 1/2): pmf(i) = C(n, i) 2^-n through lgamma
// (2^-n underflows as a product for n > 1074).
double binomial_half_cdf(int n, int j) {
  double sum = 0.0;
  for (int i = 0; i <= j; ++i) {
    sum += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) -
                    n * std::log(2.0));
  }
  return std::min(sum, 1.0);
}

// The null distribution function of U over m x n (docs: shift_rank_interval).
std::vector<double> mann_whitney_cdf(int m, int n) {
  const std::size_t size = static_cast<std::size_t>(m) * static_cast<std::size_t>(n) + 1;
  std::vector<double> cdf(size);
  if (size > 10001) {
    const double mean = m * static_cast<double>(n) / 2.0;
    const double sd = std::sqrt(m * static_cast<double>(n) * (m + n + 1.0) / 12.0);
    for (std::size_t u = 0; u < size; ++u) {
      cdf[u] = normal_cdf((static_cast<double>(u) + 0.5 - mean) / sd);
    }
    return cdf;
  }
  // p_{i,j}(u): the largest of i + j values is an x (prob i/(i+j)) and beats
  // all j y's, or a y (prob j/(i+j)) and adds nothing.
  std::vector<std::vector<double>> prev(static_cast<std::size_t>(n) + 1, {1.0}), cur = prev;
  for (int i = 1; i <= m; ++i) {
    cur[0] = {1.0};
    for (int j = 1; j <= n; ++j) {
      std::vector<double>& p = cur[static_cast<std::size_t>(j)];
      const std::vector<double>& up = prev[static_cast<std::size_t>(j)];
      const std::vector<double>& left = cur[static_cast<std::size_t>(j - 1)];
      p.assign(static_cast<std::size_t>(i * j) + 1, 0.0);
      const double wx = static_cast<double>(i) / (i + j), wy = 1.0 - wx;
      for (std::size_t u = 0; u < p.size(); ++u) {
        if (u >= static_cast<std::size_t>(j) && u - j < up.size()) p[u] += wx * up[u - j];
        if (u < left.size()) p[u] += wy * left[u];
      }
    }
    std::swap(prev, cur);
  }
  const std::vector<double>& pmf = prev[static_cast<std::size_t>(n)];
  double sum = 0.0;
  for (std::size_t u = 0; u < size; ++u) cdf[u] = std::min(sum += pmf[u], 1.0);
  return cdf;
}

// Largest k <= (count + 1) / 2 with 1 - 2 cdf(k - 1) >= confidence, else 1.
RankInterval widest_symmetric(int count, double confidence, const std::vector<double>& cdf) {
  RankInterval r{1, count, 1.0 - 2.0 * cdf[0]};
  for (int k = 2; k <= (count + 1) / 2; ++k) {
    const double coverage = 1.0 - 2.0 * cdf[static_cast<std::size_t>(k - 1)];
    if (coverage < confidence) break;
    r = RankInterval{k, count + 1 - k, coverage};
  }
  return r;
}

std::vector<double> differences(const std::vector<double>& x, const std::vector<double>& y) {
  require_no_nan("hodges_lehmann", x);
  require_no_nan("hodges_lehmann", y);
  std::vector<double> d;
  d.reserve(x.size() * y.size());
  for (double a : x) {
    for (double b : y) d.push_back(a == b ? 0.0 : a - b);  // inf - inf: a tie
  }
  std::sort(d.begin(), d.end());
  return d;
}

}  // namespace

double normal_cdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

double normal_quantile(double p) {
  if (!(p >= 0.0 && p <= 1.0)) throw std::invalid_argument("normal_quantile: p outside [0, 1]");
  if (p == 0.0) return -kInf;
  if (p == 1.0) return kInf;
  // P. J. Acklam's rational approximation (relative error < 1.2e-9).
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  const double tail = std::min(p, 1.0 - p);
  double x;
  if (tail < 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(tail));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
    if (p > 0.5) x = -x;
  } else {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  // One Halley step on e(x) = Phi(x) - p.
  const double e = normal_cdf(x) - p;
  const double u = e * std::sqrt(2.0 * M_PI) * std::exp(x * x / 2.0);
  return x - u / (1.0 + x * u / 2.0);
}

RankInterval median_rank_interval(int n, double confidence) {
  require_confidence("median_rank_interval", confidence);
  if (n < 1) throw std::invalid_argument("median_rank_interval: n = " + std::to_string(n));
  std::vector<double> cdf(static_cast<std::size_t>(n) + 1);
  for (int j = 0; j <= n; ++j) cdf[static_cast<std::size_t>(j)] = binomial_half_cdf(n, j);
  return widest_symmetric(n, confidence, cdf);
}

Interval order_statistic_median_interval(const std::vector<double>& values, double confidence) {
  require_no_nan("order_statistic_median_interval", values);
  std::vector<double> s = values;
  std::sort(s.begin(), s.end());
  const RankInterval r = median_rank_interval(static_cast<int>(s.size()), confidence);
  return Interval{s[static_cast<std::size_t>(r.lower - 1)],
                  s[static_cast<std::size_t>(r.upper - 1)]};
}

RankInterval shift_rank_interval(int m, int n, double confidence) {
  require_confidence("shift_rank_interval", confidence);
  if (m < 1 || n < 1) {
    throw std::invalid_argument("shift_rank_interval: m = " + std::to_string(m) +
                                ", n = " + std::to_string(n) + "; both must be >= 1");
  }
  // A function of (m, n, confidence) alone whose exact recursion costs
  // O(m^2 n^2): memoized, since a reading of many comparisons (200 seed
  // resamples of a grid's) asks for the same few sizes again and again.
  static std::mutex mutex;
  static std::map<std::tuple<int, int, double>, RankInterval> memo;
  const auto key = std::make_tuple(m, n, confidence);
  {
    const std::lock_guard<std::mutex> lock(mutex);
    const auto hit = memo.find(key);
    if (hit != memo.end()) return hit->second;
  }
  const RankInterval r = widest_symmetric(m * n, confidence, mann_whitney_cdf(m, n));
  const std::lock_guard<std::mutex> lock(mutex);
  return memo.emplace(key, r).first->second;
}

double hodges_lehmann_shift(const std::vector<double>& x, const std::vector<double>& y) {
  return quantile_linear_sorted(differences(x, y), 0.5);
}

Interval hodges_lehmann_interval(const std::vector<double>& x, const std::vector<double>& y,
                                 double confidence) {
  const std::vector<double> d = differences(x, y);
  const RankInterval r =
      shift_rank_interval(static_cast<int>(x.size()), static_cast<int>(y.size()), confidence);
  return Interval{d[static_cast<std::size_t>(r.lower - 1)],
                  d[static_cast<std::size_t>(r.upper - 1)]};
}

Interval bca_median_interval(const std::vector<double>& values, const BootstrapOptions& options) {
  require_no_nan("bca_median_interval", values);
  if (values.size() < 2) throw std::invalid_argument("bca_median_interval: needs n >= 2");
  for (double v : values) {
    if (!std::isfinite(v)) throw std::invalid_argument("bca_median_interval: infinite value");
  }
  std::vector<double> medians = bootstrap_medians(values, options);
  std::sort(medians.begin(), medians.end());
  const double m = quantile_linear(values, 0.5);
  const auto below = std::lower_bound(medians.begin(), medians.end(), m) - medians.begin();
  const auto at_most = std::upper_bound(medians.begin(), medians.end(), m) - medians.begin();
  const double big_b = static_cast<double>(medians.size());
  // Kept inside [1/2B, 1 - 1/2B] so that z0 stays finite (scipy: NaN there).
  const double share = std::clamp((static_cast<double>(below + at_most)) / (2.0 * big_b),
                                  0.5 / big_b, 1.0 - 0.5 / big_b);
  const double z0 = normal_quantile(share);
  // Jackknife acceleration.
  std::vector<double> jack(values.size());
  double mean = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::vector<double> rest = values;
    rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(i));
    jack[i] = quantile_linear(rest, 0.5);
    mean += jack[i] / static_cast<double>(values.size());
  }
  double num = 0.0, den = 0.0;
  for (double j : jack) {
    num += std::pow(mean - j, 3);
    den += std::pow(mean - j, 2);
  }
  const double a = den > 0.0 ? num / (6.0 * std::pow(den, 1.5)) : 0.0;
  const double z = normal_quantile((1.0 - options.confidence) / 2.0);
  const auto adjusted = [&](double zq) {
    return normal_cdf(z0 + (z0 + zq) / (1.0 - a * (z0 + zq)));
  };
  return Interval{quantile_linear_sorted(medians, adjusted(z)),
                  quantile_linear_sorted(medians, adjusted(-z))};
}

Interval wilson_interval(double successes, int trials, double confidence) {
  require_confidence("wilson_interval", confidence);
  if (trials < 1 || successes < 0.0 || successes > trials) {
    throw std::invalid_argument("wilson_interval: successes = " + std::to_string(successes) +
                                " of trials = " + std::to_string(trials));
  }
  const double z = normal_quantile((1.0 + confidence) / 2.0), t = trials, p = successes / t;
  const double scale = 1.0 + z * z / t;
  const double center = (p + z * z / (2.0 * t)) / scale;
  const double half = z * std::sqrt(p * (1.0 - p) / t + z * z / (4.0 * t * t)) / scale;
  // Exact ends at p = 0 and p = 1 (center -+ half there is 0 or 1 up to round-off).
  return Interval{successes == 0.0 ? 0.0 : std::max(0.0, center - half),
                  successes == t ? 1.0 : std::min(1.0, center + half)};
}

Interval newcombe_interval(double theta_hat, int m, int n, double confidence) {
  require_confidence("newcombe_interval", confidence);
  if (m < 1 || n < 1 || !(theta_hat >= 0.0 && theta_hat <= 1.0)) {
    throw std::invalid_argument("newcombe_interval: theta_hat = " + std::to_string(theta_hat) +
                                ", m = " + std::to_string(m) + ", n = " + std::to_string(n));
  }
  const double z = normal_quantile((1.0 + confidence) / 2.0);
  const double big_n = (m + n) / 2.0 - 1.0, mn = static_cast<double>(m) * n;
  // f < 0 inside the interval, f >= 0 at its ends and beyond.
  const auto f = [&](double t) {
    const double v =
        t * (1.0 - t) / mn * (1.0 + big_n * (1.0 - t) / (2.0 - t) + big_n * t / (1.0 + t));
    return (theta_hat - t) * (theta_hat - t) - z * z * v;
  };
  const auto root = [&](double inside, double outside) {
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (inside + outside);
      (f(mid) < 0.0 ? inside : outside) = mid;
    }
    return 0.5 * (inside + outside);
  };
  return Interval{theta_hat <= 0.0 ? 0.0 : root(theta_hat, 0.0),
                  theta_hat >= 1.0 ? 1.0 : root(theta_hat, 1.0)};
}

}  // namespace phnn
