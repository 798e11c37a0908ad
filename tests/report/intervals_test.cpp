// tests/report/intervals_test.cpp — order-statistic, BCa and score intervals
// against scipy 1.10 values (computed once, checked in below) and exact
// binomial / Mann-Whitney enumerations.
#include "phnn/report/intervals.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace phnn {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Closed forms and scipy values: a few ulps of round-off, plus Acklam's
// refined quantile (~1e-15 relative).
constexpr double kTight = 1e-12;

TEST(NormalQuantileTest, MatchesScipyNormPpf) {
  // scipy.stats.norm.ppf(p)
  EXPECT_NEAR(normal_quantile(1e-10), -6.361340902404056, kTight);
  EXPECT_NEAR(normal_quantile(0.001), -3.090232306167813, kTight);
  EXPECT_NEAR(normal_quantile(0.025), -1.9599639845400545, kTight);
  EXPECT_NEAR(normal_quantile(0.3), -0.5244005127080409, kTight);
  EXPECT_EQ(normal_quantile(0.5), 0.0);
  EXPECT_NEAR(normal_quantile(0.9), 1.2815515655446004, kTight);
  EXPECT_NEAR(normal_quantile(0.975), 1.959963984540054, kTight);
  EXPECT_NEAR(normal_quantile(0.999999), 4.753424308817087, 1e-9);
  EXPECT_EQ(normal_quantile(0.0), -kInf);
  EXPECT_EQ(normal_quantile(1.0), kInf);
  EXPECT_NEAR(normal_cdf(normal_quantile(0.123)), 0.123, kTight);
}

TEST(MedianRankIntervalTest, MatchesBinomialCoverage) {
  // 1 - 2 scipy.stats.binom.cdf(k - 1, n, 0.5), k the largest >= 0.95.
  RankInterval r = median_rank_interval(10, 0.95);
  EXPECT_EQ(r.lower, 2);
  EXPECT_EQ(r.upper, 9);
  EXPECT_NEAR(r.coverage, 0.978515625, kTight);
  r = median_rank_interval(20, 0.95);
  EXPECT_EQ(r.lower, 6);
  EXPECT_EQ(r.upper, 15);
  EXPECT_NEAR(r.coverage, 0.9586105346679688, kTight);
  r = median_rank_interval(40, 0.95);
  EXPECT_EQ(r.lower, 14);
  EXPECT_EQ(r.upper, 27);
  EXPECT_NEAR(r.coverage, 0.9615226917157997, kTight);
}

TEST(MedianRankIntervalTest, GivesTheRangeAndItsCoverageWhenNothingReachesTheLevel) {
  const RankInterval r = median_rank_interval(5, 0.95);  // 1 - 2/32
  EXPECT_EQ(r.lower, 1);
  EXPECT_EQ(r.upper, 5);
  EXPECT_NEAR(r.coverage, 0.9375, kTight);
  EXPECT_THROW(median_rank_interval(0, 0.95), std::invalid_argument);
  EXPECT_THROW(median_rank_interval(5, 1.0), std::invalid_argument);
}

TEST(MedianRankIntervalTest, OrderStatisticIntervalPicksThoseRanks) {
  const std::vector<double> v = {9, 3, kInf, 1, 7, 5, 2, 8, 4, 6};
  const Interval i = order_statistic_median_interval(v, 0.95);
  EXPECT_EQ(i.low, 2.0);
  EXPECT_EQ(i.high, 9.0);
  EXPECT_EQ(order_statistic_median_interval({3, 1, 2, 5, 4}, 0.95).high, 5.0);
}

TEST(ShiftRankIntervalTest, MatchesEnumeratedMannWhitneyDistribution) {
  // By enumerating all C(m + n, m) orders (Python itertools), k the largest
  // with 1 - 2 P(U <= k - 1) >= 0.95.
  struct Case {
    int m, n, lower, upper;
    double coverage;
  };
  for (const Case& c :
       {Case{5, 5, 3, 23, 0.9682539682539683}, Case{5, 8, 7, 34, 0.9549339549339549},
        Case{10, 10, 24, 77, 0.9567429474550218}, Case{3, 3, 1, 9, 0.9}}) {
    const RankInterval r = shift_rank_interval(c.m, c.n, 0.95);
    EXPECT_EQ(r.lower, c.lower) << c.m << "x" << c.n;
    EXPECT_EQ(r.upper, c.upper) << c.m << "x" << c.n;
    EXPECT_NEAR(r.coverage, c.coverage, kTight) << c.m << "x" << c.n;
  }
  // The normal approximation beyond m n = 10 000 agrees closely.
  const RankInterval big = shift_rank_interval(101, 100, 0.95);
  EXPECT_NEAR(big.coverage, 0.95, 0.002);
}

// Two samples of log10 MSE, 10 seeds each (used again in comparison_test).
const std::vector<double> kX = {-3.1, -2.7, -2.95, -1.2, -3.4, -2.2, -2.85, -3.05, 0.8, -2.6};
const std::vector<double> kY = {-2.5, -2.1, -2.8, -1.9, -0.4, -2.35, -2.05, 1.1, -2.65, -2.2};

TEST(HodgesLehmannTest, MatchesNumpyOnPairwiseDifferences) {
  // np.median(np.subtract.outer(x, y)); sorted differences 24 and 77.
  EXPECT_NEAR(hodges_lehmann_shift(kX, kY), -0.575, kTight);
  const Interval i = hodges_lehmann_interval(kX, kY, 0.95);
  EXPECT_NEAR(i.low, -1.05, kTight);
  EXPECT_NEAR(i.high, 0.05, kTight);
}

TEST(HodgesLehmannTest, TwoInfinitiesTieAndOneLoses) {
  EXPECT_EQ(hodges_lehmann_shift({kInf}, {kInf}), 0.0);
  EXPECT_EQ(hodges_lehmann_shift({kInf, kInf, kInf}, {1.0}), kInf);
  EXPECT_EQ(hodges_lehmann_shift({1.0}, {kInf, kInf}), -kInf);
  EXPECT_THROW(hodges_lehmann_shift({}, {1.0}), std::invalid_argument);
  EXPECT_THROW(hodges_lehmann_shift({std::nan("")}, {1.0}), std::invalid_argument);
}

TEST(BcaTest, MatchesScipyBootstrapOnASkewedSample) {
  // scipy.stats.bootstrap((s,), np.median, method="BCa", n_resamples=100000)
  // gives [1.919, 5.552] for random_state 0..3 (percentile: [1.32, 5.552]);
  // the ends are order statistics, so agreement is exact.
  const std::vector<double> s = {0.419, 5.559, 5.552, 3.244,  2.577, 4.002, 1.919, 2.535,
                                 0.392, 6.046, 1.32,  11.348, 0.086, 2.331, 3.247};
  const Interval bca = bca_median_interval(s);
  EXPECT_EQ(bca.low, 1.919);
  EXPECT_EQ(bca.high, 5.552);
  const Interval percentile = bootstrap_median_interval(s);
  EXPECT_EQ(percentile.low, 1.32);
  EXPECT_EQ(percentile.high, 5.552);
}

TEST(BcaTest, EqualsThePercentileIntervalOnASymmetricSample) {
  // Jackknife medians symmetric about their mean (a = 0), and the bootstrap
  // medians symmetric about the median (z0 = 0 up to resampling noise).
  const std::vector<double> s = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19};
  const Interval bca = bca_median_interval(s), percentile = bootstrap_median_interval(s);
  EXPECT_NEAR(bca.low, percentile.low, 1.0);
  EXPECT_NEAR(bca.high, percentile.high, 1.0);
  EXPECT_THROW(bca_median_interval({1.0, kInf}), std::invalid_argument);
  EXPECT_THROW(bca_median_interval({1.0}), std::invalid_argument);
}

TEST(WilsonTest, MatchesScipyBinomtestWilson) {
  // scipy.stats.binomtest(k, n).proportion_ci(0.95, method="wilson")
  Interval i = wilson_interval(7, 10, 0.95);
  EXPECT_NEAR(i.low, 0.39677814746114526, kTight);
  EXPECT_NEAR(i.high, 0.892208732593699, kTight);
  i = wilson_interval(10, 10, 0.95);
  EXPECT_NEAR(i.low, 0.7224672001371109, kTight);
  EXPECT_EQ(i.high, 1.0);
  i = wilson_interval(0, 5, 0.95);
  EXPECT_EQ(i.low, 0.0);
  EXPECT_NEAR(i.high, 0.43448246478317476, kTight);
  i = wilson_interval(3, 7, 0.95);
  EXPECT_NEAR(i.low, 0.1582198552514697, kTight);
  EXPECT_NEAR(i.high, 0.7495416354723428, kTight);
  EXPECT_THROW(wilson_interval(11, 10, 0.95), std::invalid_argument);
}

TEST(NewcombeTest, EndsSolveTheScoreEquation) {
  // (theta_hat - t)^2 = z^2 V(t) at both ends, t inside [0, 1].
  const double theta_hat = 0.755, z = 1.959963984540054;
  const int m = 10, n = 10;
  const Interval i = newcombe_interval(theta_hat, m, n, 0.95);
  const double big_n = (m + n) / 2.0 - 1.0;
  for (double t : {i.low, i.high}) {
    const double v = t * (1 - t) / (m * n) * (1 + big_n * (1 - t) / (2 - t) + big_n * t / (1 + t));
    EXPECT_NEAR((theta_hat - t) * (theta_hat - t), z * z * v, 1e-12);
  }
  EXPECT_LT(i.low, theta_hat);
  EXPECT_GT(i.high, theta_hat);
  // Complete separation still has width.
  const Interval one = newcombe_interval(1.0, m, n, 0.95);
  EXPECT_EQ(one.high, 1.0);
  EXPECT_LT(one.low, 0.95);
  EXPECT_GT(one.low, 0.5);
}

}  // namespace
}  // namespace phnn
