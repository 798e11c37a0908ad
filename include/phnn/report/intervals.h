// include/phnn/report/intervals.h — confidence intervals beyond the percentile
// bootstrap: distribution-free order-statistic intervals (median, sign test,
// Hodges-Lehmann shift), BCa of the median, score intervals of a probability.
// Pure functions of their arguments (docs/METHOD.md "Comparisons").
#pragma once

#include <vector>

#include "phnn/report/statistics.h"

namespace phnn {

/// The standard normal distribution function Phi(z) = erfc(-z / sqrt 2) / 2.
double normal_cdf(double z);
/// Its inverse: Phi(normal_quantile(p)) = p for 0 < p < 1 (Acklam's rational
/// start, one Halley step on erfc: about 1e-15 relative); -inf / +inf at 0 / 1.
double normal_quantile(double p);

/// An interval between two order statistics, [x_(lower), x_(upper)] (1-based
/// ranks of the sorted values), and its exact coverage for a continuous
/// distribution.
struct RankInterval {
  int lower = 1, upper = 1;
  double coverage = 0.0;
};

/// Ranks of the distribution-free interval of the median of n values (the
/// sign-test interval): with B ~ Binomial(n, 1/2),
///
///   [x_(k), x_(n + 1 - k)],  coverage = 1 - 2 P(B <= k - 1),
///
/// k the largest with coverage >= `confidence`. If even [x_(1), x_(n)]
/// covers less (n = 5 at 95 %: 1 - 2/32 = 93.75 %), that interval and its
/// coverage. Throws std::invalid_argument unless n >= 1 and 0 < confidence < 1.
RankInterval median_rank_interval(int n, double confidence);

/// [x_(k), x_(n+1-k)] of median_rank_interval over `values` (+inf allowed,
/// no NaN); e.g. n = 10 at 95 %: [x_(2), x_(9)], exact coverage 97.85 %.
Interval order_statistic_median_interval(const std::vector<double>& values, double confidence);

/// Ranks of the distribution-free interval of the shift of two samples
/// (m and n values; Moses's interval, the Mann-Whitney test inverted): over
/// the m n differences D = x_i - y_j sorted,
///
///   [D_(k), D_(mn + 1 - k)],  coverage = 1 - 2 P(U <= k - 1),
///
/// U the Mann-Whitney statistic under the null (exact recursion
///   p_{i,j}(u) = i/(i+j) p_{i-1,j}(u - j) + j/(i+j) p_{i,j-1}(u)
/// while m n <= 10 000, else the normal approximation with continuity
/// correction), k the largest with coverage >= confidence, or k = 1.
/// Memoized per process (thread-safe).
RankInterval shift_rank_interval(int m, int n, double confidence);

/// The Hodges-Lehmann shift of x against y: median of the differences
/// x_i - y_j (quantile_linear), with +inf - +inf counted 0 (two diverged runs
/// tie). Throws std::invalid_argument for an empty sample or a NaN.
double hodges_lehmann_shift(const std::vector<double>& x, const std::vector<double>& y);
/// [D_(k), D_(mn+1-k)] of shift_rank_interval over the same differences.
Interval hodges_lehmann_interval(const std::vector<double>& x, const std::vector<double>& y,
                                 double confidence);

/// BCa (bias-corrected and accelerated, Efron 1987) bootstrap interval of the
/// median, on the draws of bootstrap_medians(values, options):
///
///   z0 = Phi^-1( (#{m*_b < m} + #{m*_b <= m}) / (2 B) )        m = median
///   a  = sum (mbar - m_(i))^3 / (6 (sum (mbar - m_(i))^2)^(3/2))
///        over the jackknife medians m_(i) (value i left out), mean mbar
///   alpha_1,2 = Phi(z0 + (z0 + z) / (1 - a (z0 + z))),  z = Phi^-1((1 -+ c) / 2)
///   interval  = [Q(alpha_1), Q(alpha_2)] of the B medians (quantile_linear),
///
/// scipy.stats.bootstrap(method="BCa")'s definition. a = 0 when the jackknife
/// medians are all equal; with z0 = a = 0 it is the percentile interval.
/// Needs n >= 2 and finite values (+inf makes a undefined: throws).
Interval bca_median_interval(const std::vector<double>& values,
                             const BootstrapOptions& options = {});

/// Wilson's score interval of a probability from `successes` of `trials`
/// (successes may be a half-integer: a tie counts 1/2):
///   (p + z^2/2t +- z sqrt(p(1-p)/t + z^2/4t^2)) / (1 + z^2/t).
Interval wilson_interval(double successes, int trials, double confidence);

/// Newcombe's score interval (2006, method 5) of the Mann-Whitney probability
/// theta = P(X < Y) + P(X = Y)/2 from its estimate over m x n pairs: the
/// theta solving (theta_hat - theta)^2 = z^2 V(theta) on either side, with
///   V(theta) = theta (1 - theta) / (m n) *
///              (1 + N (1 - theta) / (2 - theta) + N theta / (1 + theta)),
///   N = (m + n) / 2 - 1.
/// Found by bisection; [0, 1]-bounded and of non-zero width at theta_hat = 1.
Interval newcombe_interval(double theta_hat, int m, int n, double confidence);

}  // namespace phnn
