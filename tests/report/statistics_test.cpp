// tests/report/statistics_test.cpp — quantiles with infinities, the
// interquartile mean, and the percentile bootstrap of the median and the IQM,
// on cases with closed-form (or enumerated) answers.
#include "phnn/report/statistics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "phnn/data/counter_rng.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;

// Quantiles of a handful of values: a few ulps of round-off at most.
constexpr double kQuantileTolerance = 1e-12;
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(QuantileTest, MatchesNumpyLinearOnEvenCount) {
  // numpy.quantile([1, 2, 3, 4], [.25, .5, .75]) = [1.75, 2.5, 3.25].
  const std::vector<double> values = {4.0, 1.0, 3.0, 2.0};
  EXPECT_NEAR(quantile_linear(values, 0.25), 1.75, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear(values, 0.5), 2.5, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear(values, 0.75), 3.25, kQuantileTolerance);
  EXPECT_EQ(quantile_linear(values, 0.0), 1.0);
  EXPECT_EQ(quantile_linear(values, 1.0), 4.0);
}

TEST(QuantileTest, MatchesNumpyLinearOnOddCount) {
  // h = 2 q: [5, 1, 3] -> q25 = 1 + 0.5 (3 - 1) = 2, median 3, q75 = 4.
  EXPECT_NEAR(quantile_linear({5.0, 1.0, 3.0}, 0.25), 2.0, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear({5.0, 1.0, 3.0}, 0.5), 3.0, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear({5.0, 1.0, 3.0}, 0.75), 4.0, kQuantileTolerance);
  // h = 4 q lands on elements: [1, 2, 3, 4, 10] -> 2, 3, 4.
  EXPECT_NEAR(quantile_linear({10.0, 1.0, 2.0, 3.0, 4.0}, 0.25), 2.0, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear({10.0, 1.0, 2.0, 3.0, 4.0}, 0.5), 3.0, kQuantileTolerance);
  EXPECT_NEAR(quantile_linear({10.0, 1.0, 2.0, 3.0, 4.0}, 0.75), 4.0, kQuantileTolerance);
  EXPECT_EQ(quantile_linear({7.0}, 0.25), 7.0);
}

TEST(QuantileTest, RejectsEmptyValuesAndQOutsideUnitInterval) {
  EXPECT_THROW(quantile_linear({}, 0.5), std::invalid_argument);
  EXPECT_THROW(quantile_linear({1.0}, 1.5), std::invalid_argument);
  EXPECT_THROW(quantile_linear({1.0}, -0.1), std::invalid_argument);
  EXPECT_THROW(quantile_linear({1.0, std::nan("")}, 0.5), std::invalid_argument);
}

TEST(QuantileTest, TwoInfiniteNeighboursGiveInfinityNotNan) {
  // numpy gives nan here (inf + 0.5 (inf - inf)).
  EXPECT_EQ(quantile_linear({1.0, 2.0, kInf, kInf}, 0.75), kInf);  // h = 2.25
  EXPECT_EQ(quantile_linear({kInf, kInf}, 0.5), kInf);
  EXPECT_EQ(quantile_linear({kInf, kInf, kInf}, 0.25), kInf);
  EXPECT_EQ(quantile_linear({-kInf, -kInf}, 0.5), -kInf);
}

TEST(QuantileTest, BetweenAFiniteValueAndInfinityIsInfinity) {
  EXPECT_EQ(quantile_linear({1.0, kInf}, 0.5), kInf);
  EXPECT_EQ(quantile_linear({1.0, 2.0, kInf, kInf}, 0.5), kInf);       // h = 1.5: 2 .. inf
  EXPECT_NEAR(quantile_linear({1.0, 2.0, kInf, kInf}, 0.25), 1.75, kQuantileTolerance);
  EXPECT_EQ(quantile_linear({-kInf, 1.0}, 0.5), -kInf);
  // A weight of exactly 0 on the infinite neighbour leaves the finite value.
  EXPECT_EQ(quantile_linear({1.0, 2.0, kInf}, 0.5), 2.0);
}

BootstrapOptions options_with(int resamples, double confidence) {
  BootstrapOptions options;
  options.resamples = resamples;
  options.confidence = confidence;
  return options;
}

TEST(BootstrapTest, IntervalOfAConstantSampleIsThatConstant) {
  const Interval i = bootstrap_median_interval({0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.25});
  EXPECT_EQ(i.low, 0.25);
  EXPECT_EQ(i.high, 0.25);
  const Interval one = bootstrap_median_interval({3e-3});
  EXPECT_EQ(one.low, 3e-3);
  EXPECT_EQ(one.high, 3e-3);
}

// n = 3, a < b < c: of the 27 equally likely resamples, 7 have median a
// (at least two a's: 3 * 2 + 1), 7 have c, 13 have b.
TEST(BootstrapTest, MedianFrequenciesOfThreeValuesMatchTheEnumeration) {
  constexpr int kResamples = 27000;
  const std::vector<double> medians =
      bootstrap_medians({30.0, 10.0, 20.0}, options_with(kResamples, 0.95));
  ASSERT_EQ(medians.size(), static_cast<std::size_t>(kResamples));
  const auto frequency = [&](double v) {
    return static_cast<double>(std::count(medians.begin(), medians.end(), v)) / kResamples;
  };
  // Binomial standard deviation sqrt(p (1 - p) / B) ~ 0.0027 (p = 7/27),
  // 0.0030 (p = 13/27): 5 sigma.
  constexpr double kFiveSigma = 0.015;
  EXPECT_NEAR(frequency(10.0), 7.0 / 27.0, kFiveSigma);
  EXPECT_NEAR(frequency(20.0), 13.0 / 27.0, kFiveSigma);
  EXPECT_NEAR(frequency(30.0), 7.0 / 27.0, kFiveSigma);
}

TEST(BootstrapTest, IntervalOfThreeValuesFollowsTheExactDistribution) {
  // 95 %: the 2.5 % and 97.5 % points of {a: 7/27, b: 13/27, c: 7/27}.
  const Interval wide = bootstrap_median_interval({30.0, 10.0, 20.0});
  EXPECT_EQ(wide.low, 10.0);
  EXPECT_EQ(wide.high, 30.0);
  // 40 %: the 30 % and 70 % points; 7/27 = 0.26 < 0.30 and 20/27 = 0.74 > 0.70.
  const Interval narrow = bootstrap_median_interval({30.0, 10.0, 20.0}, options_with(10000, 0.4));
  EXPECT_EQ(narrow.low, 20.0);
  EXPECT_EQ(narrow.high, 20.0);
}

// n = 5 values 1..5: the bootstrap median is the 3rd smallest of 5 draws, so
// P(median <= k) = P(at least 3 of 5 draws <= k) = 0.058, 0.317, 0.683, 0.942
// for k = 1..4. At 90 % the 5 % and 95 % points are 1 and 5; at 80 % the
// 10 % and 90 % points are 2 and 4 (B = 100 000: each margin >= 10 sigma).
TEST(BootstrapTest, IntervalEndsAreTheTwoTailQuantilesOfTheBootstrapMedians) {
  const std::vector<double> values = {4.0, 2.0, 5.0, 1.0, 3.0};
  const Interval ninety = bootstrap_median_interval(values, options_with(100000, 0.9));
  EXPECT_EQ(ninety.low, 1.0);
  EXPECT_EQ(ninety.high, 5.0);
  const Interval eighty = bootstrap_median_interval(values, options_with(100000, 0.8));
  EXPECT_EQ(eighty.low, 2.0);
  EXPECT_EQ(eighty.high, 4.0);
}

TEST(BootstrapTest, IntervalReachesInfinityWithoutNan) {
  // {1, 2, inf}: the median is inf with probability 7/27 > 2.5 %.
  const Interval i = bootstrap_median_interval({1.0, kInf, 2.0});
  EXPECT_EQ(i.low, 1.0);
  EXPECT_EQ(i.high, kInf);
  const Interval all = bootstrap_median_interval({kInf, kInf, kInf});
  EXPECT_EQ(all.low, kInf);
  EXPECT_EQ(all.high, kInf);
  // Two of five finite: P(median = inf) = P(>= 3 of 5 draws inf, p = 3/5) = 0.68.
  const Interval mostly = bootstrap_median_interval({1.0, 2.0, kInf, kInf, kInf});
  EXPECT_EQ(mostly.low, 1.0);
  EXPECT_EQ(mostly.high, kInf);
}

TEST(BootstrapTest, IsReproducibleAndDependsOnTheSeedOnly) {
  const std::vector<double> values = {0.05, 0.07, 12.0, 0.04, 800.0, 0.06, 35.0, 0.05, 2600.0};
  BootstrapOptions other_seed;
  other_seed.seed = 7;
  const std::vector<double> a = bootstrap_medians(values);
  EXPECT_EQ(a, bootstrap_medians(values));
  std::vector<double> shuffled = values;
  std::reverse(shuffled.begin(), shuffled.end());
  EXPECT_EQ(a, bootstrap_medians(shuffled));  // the run order does not matter
  EXPECT_NE(a, bootstrap_medians(values, other_seed));
}

// The resamples as the header defines them, computed the plain way: the n
// draws of each from one CounterRng stream, the drawn values sorted. The
// library sorts by counting the draws per index; the medians must be the
// same doubles, ties, repeats and +inf included.
std::vector<double> plain_bootstrap_medians(std::vector<double> values,
                                            const BootstrapOptions& options) {
  std::sort(values.begin(), values.end());
  CounterRng rng(options.seed);
  std::vector<double> medians, sample(values.size());
  for (int b = 0; b < options.resamples; ++b) {
    for (double& x : sample) x = values[rng.below(values.size())];
    medians.push_back(quantile_linear(sample, 0.5));
  }
  return medians;
}

TEST(BootstrapTest, CountingTheDrawsGivesTheSortedResamplesMedians) {
  const std::vector<std::vector<double>> samples = {
      {0.05, 0.07, 12.0, 0.04, 800.0, 0.06, 35.0, 0.05, 2600.0},
      {3.0, 1.0, 3.0, 2.0, kInf, 1.0, 1e-300, 7.5, 7.5, 0.0},
      {42.0},
  };
  for (const auto& values : samples) {
    const BootstrapOptions options = options_with(3000, 0.95);
    EXPECT_EQ(bootstrap_medians(values, options), plain_bootstrap_medians(values, options));
  }
}

// The intervals are memoized per process: a repeated call, a reordered
// sample, a sample one ulp away and other options must each give what a
// fresh computation gives.
TEST(BootstrapTest, RepeatedIntervalsEqualAFreshComputation) {
  const std::vector<double> values = {0.05, 0.07, 12.0, 0.04, 800.0, 0.06, 35.0, 0.05, 2600.0};
  auto fresh = [](const std::vector<double>& v, const BootstrapOptions& o) {
    return percentile_interval(bootstrap_medians(v, o), o.confidence);
  };
  auto same = [](const Interval& a, const Interval& b) {
    return a.low == b.low && a.high == b.high;
  };
  std::vector<double> reversed(values.rbegin(), values.rend());
  std::vector<double> nudged = values;
  nudged[4] = std::nextafter(800.0, 0.0);
  const BootstrapOptions base = options_with(2000, 0.95);
  for (const auto& options : {base, options_with(2000, 0.5), options_with(4000, 0.95)}) {
    for (const auto& v : {values, reversed, values, nudged}) {
      EXPECT_TRUE(same(bootstrap_median_interval(v, options), fresh(v, options)));
    }
  }
  // A one-ulp change of the value the 50 % interval ends on reaches the
  // interval (B = 2001: the 25 % and 75 % points are draws 500 and 1500
  // exactly, each a median of 9 values, so a value of the sample).
  const Interval half = bootstrap_median_interval(values, options_with(2001, 0.5));
  std::vector<double> moved = values;
  for (double& v : moved) {
    if (v == half.high) v = std::nextafter(v, kInf);
  }
  const Interval half_moved = bootstrap_median_interval(moved, options_with(2001, 0.5));
  EXPECT_EQ(half_moved.high, std::nextafter(half.high, kInf));
  // The IQM's interval is kept apart from the median's.
  EXPECT_TRUE(same(
      bootstrap_iqm_interval(values, base),
      percentile_interval(bootstrap_statistics(values, base, interquartile_mean_sorted), 0.95)));
}

TEST(BootstrapTest, RejectsFewResamplesBadConfidenceAndNan) {
  EXPECT_THAT([] { bootstrap_medians({1.0}, options_with(1999, 0.95)); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("resamples = 1999")));
  EXPECT_THAT([] { bootstrap_medians({1.0}, options_with(2000, 1.0)); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("confidence = 1")));
  EXPECT_THROW(bootstrap_medians({}), std::invalid_argument);
  EXPECT_THROW(bootstrap_median_interval({1.0, std::nan("")}), std::invalid_argument);
}

// Interquartile mean against scipy.stats.trim_mean(x, 0.25) (scipy 1.10.1,
// numpy 1.24.2), printed with repr(): n = 1..10 (divisible by 4 or not),
// ties, a heavy tail, and +inf (a diverged run) dropped or kept.
struct TrimMeanCase {
  std::vector<double> values;
  double scipy;
};

TEST(InterquartileMeanTest, MatchesScipyTrimMeanFixtures) {
  const std::vector<TrimMeanCase> cases = {
      {{3.0}, 3.0},
      {{2.0, 1.0}, 1.5},
      {{1.0, 2.0, 10.0}, 4.333333333333333},  // n < 4: nothing trimmed
      {{4.0, 1.0, 3.0, 2.0}, 2.5},
      {{1.0, 2.0, 3.0, 4.0, 100.0}, 3.0},
      {{5.0, 1.0, 4.0, 2.0, 3.0, 6.0}, 3.5},
      {{1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0}, 4.0},
      {{1e-3, 2e-3, 2e-3, 2e-3, 5e-1, 9e-4, 2e-3, 3e-3}, 0.002},  // ties
      {{0.05, 0.07, 12.0, 0.04, 800.0, 0.06, 35.0, 0.05, 2600.0, 0.05}, 7.871666666666667},
      {{1.0, 2.0, 3.0, kInf}, 2.5},                 // one inf, trimmed
      {{1.0, 2.0, 3.0, 4.0, kInf, kInf}, kInf},     // two infs, one trimmed
      {{1.0, 2.0, kInf, kInf, kInf}, kInf},
  };
  for (const TrimMeanCase& c : cases) {
    const double iqm = interquartile_mean(c.values);
    if (std::isinf(c.scipy)) {
      EXPECT_EQ(iqm, c.scipy);
    } else {
      EXPECT_DOUBLE_EQ(iqm, c.scipy) << "n = " << c.values.size();
    }
  }
}

TEST(InterquartileMeanTest, ClosedFormsAndErrors) {
  // n = 8: g = 2, the mean of the 3rd..6th smallest, (3 + 5 + 6 + 7) / 4; the
  // inf beyond them is dropped.
  EXPECT_DOUBLE_EQ(interquartile_mean({8.0, 1.0, 7.0, 2.0, 6.0, 3.0, 5.0, kInf}), 5.25);
  // n = 9: g = 2, (3 + 4 + 5 + 6 + 7) / 5.
  EXPECT_DOUBLE_EQ(interquartile_mean({9.0, 1.0, 8.0, 2.0, 7.0, 3.0, 6.0, 4.0, 5.0}), 5.0);
  EXPECT_EQ(interquartile_mean({kInf, kInf}), kInf);
  EXPECT_THAT([] { interquartile_mean({}); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("no values")));
  EXPECT_THAT([] { interquartile_mean({1.0, std::nan("")}); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("NaN")));
}

// The exact bootstrap distribution of the IQM, by enumerating all n^n
// equally likely index tuples; its p-quantile as the smallest value v with
// P(IQM <= v) >= p, and the distance of that probability from p.
struct ExactQuantile {
  double value;
  double margin;  // min |P(IQM <= v) - p|, |P(IQM < v) - p|
};

ExactQuantile exact_iqm_quantile(const std::vector<double>& values, double p) {
  const std::size_t n = values.size();
  std::size_t total = 1;
  for (std::size_t i = 0; i < n; ++i) total *= n;
  std::vector<double> iqms;
  std::vector<double> sample(n);
  for (std::size_t code = 0; code < total; ++code) {
    std::size_t rest = code;
    for (std::size_t i = 0; i < n; ++i, rest /= n) sample[i] = values[rest % n];
    std::sort(sample.begin(), sample.end());
    const std::size_t g = n / 4;
    double sum = 0.0;
    for (std::size_t i = g; i < n - g; ++i) sum += sample[i];
    iqms.push_back(sum / static_cast<double>(n - 2 * g));
  }
  std::sort(iqms.begin(), iqms.end());
  const auto k = static_cast<std::size_t>(std::ceil(p * static_cast<double>(total))) - 1;
  const double v = iqms[k];
  const double below = static_cast<double>(std::lower_bound(iqms.begin(), iqms.end(), v) -
                                           iqms.begin()) / static_cast<double>(total);
  const double at_most = static_cast<double>(std::upper_bound(iqms.begin(), iqms.end(), v) -
                                             iqms.begin()) / static_cast<double>(total);
  return {v, std::min(std::abs(at_most - p), std::abs(below - p))};
}

// B = 100 000: the empirical 2.5 % / 97.5 % points land on the exact
// distribution's whenever its CDF steps across them by more than ~6 sigma
// (sigma = sqrt(0.025 * 0.975 / B) = 0.0005; these cases: 0.0041 or more),
// checked before comparing.
TEST(BootstrapIqmTest, IntervalMatchesTheEnumeratedBootstrapDistribution) {
  for (const std::vector<double>& values :
       {std::vector<double>{1.0, 2.0, 4.0, 8.0}, std::vector<double>{3.0, 1.0, 9.0, 27.0, 5.0},
        std::vector<double>{1.0, 2.0, 3.0, 4.0, kInf}}) {
    const Interval i = bootstrap_iqm_interval(values);
    const ExactQuantile low = exact_iqm_quantile(values, 0.025);
    const ExactQuantile high = exact_iqm_quantile(values, 0.975);
    ASSERT_GT(low.margin, 0.003);
    ASSERT_GT(high.margin, 0.003);
    EXPECT_DOUBLE_EQ(i.low, low.value) << "n = " << values.size();
    if (std::isinf(high.value)) {
      EXPECT_EQ(i.high, kInf);  // P(>= 2 of 5 draws inf) = 0.26
    } else {
      EXPECT_DOUBLE_EQ(i.high, high.value) << "n = " << values.size();
    }
  }
}

TEST(BootstrapIqmTest, DrawsTheMediansResamplesAndHandlesConstantsAndOneValue) {
  const std::vector<double> values = {0.05, 0.07, 12.0, 0.04, 800.0, 0.06, 35.0, 0.05, 2600.0};
  const auto median = [](const std::vector<double>& sorted) {
    return quantile_linear_sorted(sorted, 0.5);
  };
  EXPECT_EQ(bootstrap_statistics(values, {}, median), bootstrap_medians(values));
  const Interval constant = bootstrap_iqm_interval({2e-4, 2e-4, 2e-4, 2e-4, 2e-4});
  EXPECT_EQ(constant.low, 2e-4);
  EXPECT_EQ(constant.high, 2e-4);
  const Interval one = bootstrap_iqm_interval({3e-3});
  EXPECT_EQ(one.low, 3e-3);
  EXPECT_EQ(one.high, 3e-3);
  EXPECT_THROW(bootstrap_iqm_interval({1.0, std::nan("")}), std::invalid_argument);
  const Interval all = bootstrap_iqm_interval({kInf, kInf, kInf});
  EXPECT_EQ(all.low, kInf);
}

TEST(IntervalTest, ClosedIntervalsOverlapWhenTheyShareAPoint) {
  EXPECT_TRUE((Interval{1.0, 2.0}.overlaps(Interval{2.0, 3.0})));
  EXPECT_TRUE((Interval{1.0, kInf}.overlaps(Interval{5.0, 6.0})));
  EXPECT_FALSE((Interval{1.0, 2.0}.overlaps(Interval{2.5, 3.0})));
  EXPECT_FALSE((Interval{2.5, 3.0}.overlaps(Interval{1.0, 2.0})));
}

}  // namespace
}  // namespace phnn
