// tests/report/comparison_test.cpp — compare_cells against numpy/scipy values
// on fixed samples, the four readings, diverged seeds, and the pairing rule.
#include "phnn/report/comparison.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

constexpr double kInf = std::numeric_limits<double>::infinity();
// log10(10^x) round trips to a few ulps.
constexpr double kTight = 1e-12;

// Log10 MSEs of two cells, seeds 0..9 (the samples of intervals_test).
const std::vector<double> kX = {-3.1, -2.7, -2.95, -1.2, -3.4, -2.2, -2.85, -3.05, 0.8, -2.6};
const std::vector<double> kY = {-2.5, -2.1, -2.8, -1.9, -0.4, -2.35, -2.05, 1.1, -2.65, -2.2};

SeedResults cell(const std::vector<double>& log10_mse, int first_seed = 0) {
  SeedResults r;
  for (std::size_t i = 0; i < log10_mse.size(); ++i) {
    r[first_seed + static_cast<int>(i)] = std::pow(10.0, log10_mse[i]);
  }
  return r;
}

TEST(CompareCellsTest, PairedMatchesNumpyAndScipy) {
  // d = x - y: np.median(d) = -0.5; sorted d[1] = -3.0, d[8] = 0.7 (ranks
  // 2 and 9 of 10); 7 of 10 negative: binomtest(7, 10) Wilson interval.
  const Comparison c = compare_cells(cell(kX), cell(kY), /*paired=*/true);
  EXPECT_TRUE(c.paired);
  EXPECT_EQ(c.n_pairs, 10);
  EXPECT_NEAR(c.effect, -0.5, kTight);
  EXPECT_NEAR(c.effect_interval.low, -3.0, kTight);
  EXPECT_NEAR(c.effect_interval.high, 0.7, kTight);
  EXPECT_NEAR(c.effect_coverage, 0.978515625, kTight);
  EXPECT_NEAR(c.p_a_less, 0.7, kTight);
  EXPECT_NEAR(c.p_a_less_interval.low, 0.39677814746114526, kTight);
  EXPECT_NEAR(c.p_a_less_interval.high, 0.892208732593699, kTight);
  EXPECT_EQ(c.reading, ComparisonReading::kUndecided);
}

TEST(CompareCellsTest, UnpairedMatchesNumpyAndScipyMannWhitney) {
  // Hodges-Lehmann -0.575 and Moses ranks 24, 77 (intervals_test);
  // scipy.stats.mannwhitneyu(y, x).statistic / 100 = 0.755.
  const Comparison c = compare_cells(cell(kX), cell(kY), /*paired=*/false);
  EXPECT_FALSE(c.paired);
  EXPECT_EQ(c.n_a, 10);
  EXPECT_EQ(c.n_b, 10);
  EXPECT_NEAR(c.effect, -0.575, kTight);
  EXPECT_NEAR(c.effect_interval.low, -1.05, kTight);
  EXPECT_NEAR(c.effect_interval.high, 0.05, kTight);
  EXPECT_NEAR(c.effect_coverage, 0.9567429474550218, kTight);
  EXPECT_NEAR(c.p_a_less, 0.755, kTight);
  const Interval expected = newcombe_interval(0.755, 10, 10, 0.95);
  EXPECT_EQ(c.p_a_less_interval.low, expected.low);
  EXPECT_EQ(c.p_a_less_interval.high, expected.high);
  EXPECT_EQ(c.reading, ComparisonReading::kUndecided);
}

// A seed effect spread over 3 decades, shared by both cells, and B 2x worse
// on every seed up to +-0.05 decades: pairing resolves what pooling cannot.
TEST(CompareCellsTest, PairingRemovesASharedSeedEffect) {
  const std::vector<double> seed_effect = {-4.0, -2.5, -3.2, -1.5, -3.8,
                                           -2.0, -1.1, -3.5, -2.8, -1.8};
  const std::vector<double> noise = {0.05, -0.03, 0.01, -0.05, 0.02, 0.0, 0.04, -0.02, -0.04, 0.03};
  std::vector<double> a, b;
  for (std::size_t i = 0; i < seed_effect.size(); ++i) {
    a.push_back(seed_effect[i] + noise[i]);
    b.push_back(seed_effect[i] + std::log10(2.0) - noise[i]);
  }
  const Comparison paired = compare_cells(cell(a), cell(b), true);
  EXPECT_EQ(paired.reading, ComparisonReading::kABetter);
  EXPECT_LT(paired.effect_interval.high, 0.0);
  EXPECT_EQ(paired.p_a_less, 1.0);
  const Comparison pooled = compare_cells(cell(a), cell(b), false);
  EXPECT_EQ(pooled.reading, ComparisonReading::kUndecided);
  // And with B == A up to the noise: equivalent within x1.5 (log10 1.5 = 0.176).
  std::vector<double> same;
  for (std::size_t i = 0; i < a.size(); ++i) same.push_back(seed_effect[i] - noise[i]);
  EXPECT_EQ(compare_cells(cell(a), cell(same), true).reading, ComparisonReading::kEquivalent);
  ComparisonOptions tight;
  tight.delta = 1.1;  // log10 1.1 = 0.041 < the noise's 0.1 spread
  EXPECT_EQ(compare_cells(cell(a), cell(same), true, tight).reading, ComparisonReading::kUndecided);
}

TEST(CompareCellsTest, ReadsBBetterAndEquivalenceBeforeDirection) {
  const std::vector<double> a = {0.30, 0.31, 0.29, 0.30, 0.32, 0.28, 0.30, 0.31};
  const std::vector<double> zero(a.size(), 0.0);
  EXPECT_EQ(compare_cells(cell(a), cell(zero), true).reading, ComparisonReading::kBBetter);
  // Every ratio x1.1-x1.3: a sure difference inside the x1.5 margin.
  const std::vector<double> small = {0.05, 0.06, 0.07, 0.08, 0.09, 0.10, 0.11, 0.06};
  ComparisonOptions options;
  const Comparison c = compare_cells(cell(small), cell(zero), true, options);
  EXPECT_GT(c.effect_interval.low, 0.0);
  EXPECT_EQ(c.reading, ComparisonReading::kEquivalent);
}

TEST(CompareCellsTest, DivergedSeedLosesItsPairAndTwoDivergedTie) {
  // Seeds 0-7: A diverged, B finite (d = +inf); 8: both diverged (d = 0;
  // NaN is read as diverged); 9: both finite, A lower (d = -1).
  SeedResults a = cell({0, 0, 0, 0, 0, 0, 0, 0, 0, -3});
  SeedResults b = cell({-2, -2, -2, -2, -2, -2, -2, -2, -2, -2});
  for (int s = 0; s < 9; ++s) a[s] = kInf;
  b[8] = std::nan("");
  Comparison c = compare_cells(a, b, true);
  EXPECT_EQ(c.diverged_a, 9);
  EXPECT_EQ(c.diverged_b, 1);
  EXPECT_EQ(c.effect, kInf);
  EXPECT_NEAR(c.p_a_less, (1 + 0.5) / 10.0, kTight);
  // Sorted d = {-1, 0, inf x 8}: ranks 2 and 9 give [0, inf], which holds 0.
  EXPECT_EQ(c.effect_interval.low, 0.0);
  EXPECT_EQ(c.effect_interval.high, kInf);
  EXPECT_EQ(c.reading, ComparisonReading::kUndecided);
  // Seed 9 diverged on A's side too: d = {0, inf x 9}, [inf, inf].
  a[9] = kInf;
  c = compare_cells(a, b, true);
  EXPECT_EQ(c.effect_interval.low, kInf);
  EXPECT_EQ(c.reading, ComparisonReading::kBBetter);
  // Unpaired, the same rules: inf - inf ties, inf - finite is +inf.
  c = compare_cells(a, b, false);
  EXPECT_EQ(c.effect, kInf);
  EXPECT_NEAR(c.p_a_less, (0.5 * 10) / 100.0, kTight);
}

TEST(CompareCellsTest, PairsOnlyTheCommonSeedsAndNeedsMinSeeds) {
  const Comparison c =
      compare_cells(cell(kX), cell({-2.5, -2.1, -2.8, -1.9}, /*first_seed=*/7), true);
  EXPECT_EQ(c.n_pairs, 3);  // seeds 7, 8, 9
  EXPECT_EQ(c.reading, ComparisonReading::kUndecided);
  const Comparison none = compare_cells(cell({1.0}, 0), cell({1.0}, 5), true);
  EXPECT_EQ(none.n_pairs, 0);
  EXPECT_TRUE(std::isnan(none.effect));
  EXPECT_EQ(none.reading, ComparisonReading::kUndecided);
}

TEST(CompareCellsTest, BootstrapIntervalIsThePercentileIntervalOfTheLogRatios) {
  ComparisonOptions options;
  options.effect_interval = EffectInterval::kPercentileBootstrap;
  const Comparison c = compare_cells(cell(kX), cell(kY), true, options);
  std::vector<double> d;
  for (std::size_t i = 0; i < kX.size(); ++i) {
    d.push_back(std::log10(std::pow(10.0, kX[i])) - std::log10(std::pow(10.0, kY[i])));
  }
  const Interval expected = bootstrap_median_interval(d);
  EXPECT_EQ(c.effect_interval.low, expected.low);
  EXPECT_EQ(c.effect_interval.high, expected.high);
  EXPECT_TRUE(std::isnan(c.effect_coverage));
}

TEST(ComparisonCsvTest, PrintsOneLinePerComparisonWithInfinitiesAndQuotes) {
  SeedResults a = cell({0, 0, 0, 0, 0});
  for (auto& entry : a) entry.second = kInf;
  const Comparison c = compare_cells(a, cell({-2, -2, -2, -2, -2}), true);
  const std::string csv = render_comparisons_csv({{"x,1", "y", c}}, 1.5);
  EXPECT_EQ(csv,
            "a,b,paired,n_a,n_b,n_pairs,diverged_a,diverged_b,effect,effect_low,effect_high,"
            "effect_coverage,p_a_less,p_low,p_high,delta,reading\n"
            "\"x,1\",y,1,5,5,5,5,0,inf,inf,inf,9.375000e-01,0.000000e+00,0.000000e+00,"
            "4.344825e-01,1.500000e+00,B better\n");
}

TEST(ComparisonOptionsTest, RejectsAMarginOfOneOrLess) {
  ComparisonOptions options;
  options.delta = 1.0;
  EXPECT_THAT([&] { options.validate(); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("delta = 1")));
  EXPECT_THROW(compare_cells({}, {{0, 1.0}}, true), std::invalid_argument);
}

TEST(CellsArePairedTest, SameNetworkDataAndBatchesOnly) {
  RunConfig a;
  a.model = ModelKind::kPhnnS;
  a.integrator = IntegratorKind::kDg;
  RunConfig b = a;
  b.integrator = IntegratorKind::kRk2;
  b.seed = 3;
  EXPECT_TRUE(cells_are_paired(a, b));
  b.regularizer = Regularizer::kCn;
  b.training.learning_rate *= 2.0;
  EXPECT_TRUE(cells_are_paired(a, b));
  RunConfig other = b;
  other.model = ModelKind::kNode;
  EXPECT_FALSE(cells_are_paired(a, other));
  other = b;
  other.size = ModelSize::kMedium;
  EXPECT_FALSE(cells_are_paired(a, other));
  other = b;
  other.n_train = 100;
  EXPECT_FALSE(cells_are_paired(a, other));
  other = b;
  other.training.batch_size = 32;
  EXPECT_FALSE(cells_are_paired(a, other));
  other = b;
  other.system = SystemKind::kDuffing;
  EXPECT_FALSE(cells_are_paired(a, other));
}

}  // namespace
}  // namespace phnn
