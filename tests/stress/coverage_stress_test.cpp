// tests/stress/coverage_stress_test.cpp — the coverage study, small (ctest -L
// stats): the chosen interval methods hold their exact coverage on synthetic
// samples, and every method of the full study (build/bench_coverage) runs.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "phnn/report/coverage_study.h"
#include "phnn/report/intervals.h"

namespace phnn {
namespace {

// A coverage measured over R replications has standard error
// sqrt(p (1 - p) / R); 4 of them leave a correct method a chance below 1e-4
// of failing (the draws are fixed, so a pass is a pass on every machine),
// while an off-by-one rank moves the coverage by 5-9 points (n = 5, 10).
double tolerance(double p, int replications) {
  return 4.0 * std::sqrt(p * (1.0 - p) / replications);
}

constexpr int kReplications = 2000;

// Distribution-free intervals: their coverage is exact for continuous data
// whatever the distribution (bimodal included), so measured = exact +- error.
TEST(CoverageStudyTest, OrderStatisticIntervalsHoldTheirExactCoverage) {
  CoverageOptions options;
  options.replications = kReplications;
  struct Case {
    CoverageScenario scenario;
    CoverageMethod method;
  };
  for (const Case& c :
       {Case{CoverageScenario::kCellLogNormal, CoverageMethod::kOrderStatistic},
        Case{CoverageScenario::kCellBimodal, CoverageMethod::kOrderStatistic},
        Case{CoverageScenario::kPairsBimodal, CoverageMethod::kPairedOrderStatistic},
        Case{CoverageScenario::kPairsLogNormalShared, CoverageMethod::kPairedOrderStatistic}}) {
    for (int n : {5, 10}) {
      const double exact = median_rank_interval(n, options.confidence).coverage;
      const CoverageRow row = measure_coverage(c.scenario, c.method, n, options);
      EXPECT_NEAR(row.coverage(), exact, tolerance(exact, kReplications))
          << to_string(c.scenario) << ", " << to_string(c.method) << ", n = " << n;
    }
  }
}

// Moses's interval is exact for two independent samples of one shape shifted.
TEST(CoverageStudyTest, MosesIntervalHoldsItsExactCoverageOnIndependentSamples) {
  CoverageOptions options;
  options.replications = kReplications;
  for (CoverageScenario scenario :
       {CoverageScenario::kPairsLogNormal, CoverageScenario::kPairsBimodal}) {
    for (int n : {5, 10}) {
      const double exact = shift_rank_interval(n, n, options.confidence).coverage;
      const CoverageRow row =
          measure_coverage(scenario, CoverageMethod::kUnpairedMoses, n, options);
      EXPECT_NEAR(row.coverage(), exact, tolerance(exact, kReplications))
          << to_string(scenario) << ", n = " << n;
    }
  }
}

// The whole study at n = 5 and 10 with few replications: every row exists
// and the table names every method.
TEST(CoverageStudyTest, SmallStudyRunsEveryMethod) {
  CoverageOptions options;
  options.replications = 200;
  std::vector<CoverageRow> rows;
  for (CoverageScenario scenario : all_coverage_scenarios()) {
    for (CoverageMethod method : coverage_methods(scenario)) {
      for (int n : {5, 10}) {
        rows.push_back(measure_coverage(scenario, method, n, options));
        EXPECT_GT(rows.back().coverage(), 0.5) << to_string(method);
        EXPECT_GT(rows.back().median_width, 0.0) << to_string(method);
      }
    }
  }
  EXPECT_EQ(rows.size(), 2u * (2 * 3 + 4 * 4));
  const std::string table = render_coverage_markdown(rows, {5, 10});
  EXPECT_NE(table.find("| pairs, bimodal, shared mode | paired BCa of the log ratio |"),
            std::string::npos);
  EXPECT_THROW(
      measure_coverage(CoverageScenario::kCellBimodal, CoverageMethod::kUnpairedMoses, 10, options),
      std::invalid_argument);
}

}  // namespace
}  // namespace phnn
