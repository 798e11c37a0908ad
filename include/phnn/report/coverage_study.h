// include/phnn/report/coverage_study.h — the measured coverage of the
// interval methods on synthetic samples with a known truth (docs/METHOD.md
// "Comparisons"): the data the choice of the verdicts' intervals rests on.
// Pure and deterministic (counter-based draws); no HDF5, no MPI.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "phnn/common/enum_names.h"

namespace phnn {

/// Where the synthetic log10 MSEs come from. "Cell" scenarios draw one
/// sample (its median's interval is measured); "pairs" scenarios draw two
/// cells over the same seeds, B = A shifted by log10 2 (an effect's interval
/// is measured). In log10 MSE:
///   log-normal   N(-3, 0.5)
///   bimodal      good mode N(-3, 0.3) w.p. 0.7, bad mode N(1, 0.3) w.p. 0.3
///                (like the Duffing cells: ~1e-3 and ~10)
///   ... shared   pairs with a seed effect common to both cells: log-normal
///                s + N(0, 0.2), s ~ N(-3, 0.5); bimodal: the mode is the
///                seed's, the within-mode noise each cell's own.
enum class CoverageScenario {
  kCellLogNormal,
  kCellBimodal,
  kPairsLogNormal,
  kPairsLogNormalShared,
  kPairsBimodal,
  kPairsBimodalShared,
};
inline constexpr EnumNames<CoverageScenario, 6> kCoverageScenarioNames{
    "scenario",
    {{{CoverageScenario::kCellLogNormal, "cell, log-normal"},
      {CoverageScenario::kCellBimodal, "cell, bimodal 0.7/0.3"},
      {CoverageScenario::kPairsLogNormal, "pairs, log-normal"},
      {CoverageScenario::kPairsLogNormalShared, "pairs, log-normal, shared seed effect"},
      {CoverageScenario::kPairsBimodal, "pairs, bimodal"},
      {CoverageScenario::kPairsBimodalShared, "pairs, bimodal, shared mode"}}}};
inline std::string to_string(CoverageScenario scenario) { return kCoverageScenarioNames.name(scenario); }
/// Cell scenarios first, then pairs.
inline std::vector<CoverageScenario> all_coverage_scenarios() { return kCoverageScenarioNames.all(); }
bool is_pairs(CoverageScenario scenario);

/// The interval methods measured. Cell scenarios: the first three on the
/// cell's sample; pairs scenarios: all but those three, on d_s = a_s - b_s
/// (paired) or on the two samples (Moses).
enum class CoverageMethod {
  kPercentileBootstrap,   // bootstrap_median_interval (the tables' interval)
  kBca,                   // bca_median_interval
  kOrderStatistic,        // order_statistic_median_interval
  kPairedBootstrap,       // percentile bootstrap of the median of d
  kPairedBca,             // BCa of the median of d
  kPairedOrderStatistic,  // sign-test interval of the median of d
  kUnpairedMoses,         // Moses's interval of the Hodges-Lehmann shift
};
inline constexpr EnumNames<CoverageMethod, 7> kCoverageMethodNames{
    "interval method",
    {{{CoverageMethod::kPercentileBootstrap, "percentile bootstrap"},
      {CoverageMethod::kBca, "BCa"},
      {CoverageMethod::kOrderStatistic, "order statistic (binomial)"},
      {CoverageMethod::kPairedBootstrap, "paired bootstrap of the log ratio"},
      {CoverageMethod::kPairedBca, "paired BCa of the log ratio"},
      {CoverageMethod::kPairedOrderStatistic, "paired order statistic (sign test)"},
      {CoverageMethod::kUnpairedMoses, "unpaired Hodges-Lehmann (Moses)"}}}};
inline std::string to_string(CoverageMethod method) { return kCoverageMethodNames.name(method); }
/// The methods that apply to a scenario, in the order above.
std::vector<CoverageMethod> coverage_methods(CoverageScenario scenario);

/// Options of measure_coverage().
struct CoverageOptions {
  /// Replications R: a coverage p is measured with standard error
  /// sqrt(p (1 - p) / R): 0.49 % at p = 0.95, R = 2000.
  int replications = 2000;
  /// Bootstrap resamples per interval (the tables use 100 000; the end
  /// points move by the Monte-Carlo error of a 2.5 % quantile, ~0.35 % in
  /// probability at 2000, which moves a coverage far less than R's error).
  int resamples = 2000;
  double confidence = 0.95;
  /// Key of the synthetic draws; replication r of (scenario, n) has its own
  /// stream, so any row can be measured alone.
  std::uint64_t seed = 0x636f766572616765ULL;  // "coverage"
};

/// One measured coverage.
struct CoverageRow {
  CoverageScenario scenario;
  CoverageMethod method;
  int n = 0;
  /// Replications whose interval holds the truth (closed interval).
  int covered = 0;
  int replications = 0;
  /// Median over replications of the interval's width, in log10 MSE.
  double median_width = 0.0;
  double coverage() const { return static_cast<double>(covered) / replications; }
};

/// The true value each scenario's intervals aim at, in log10 MSE: the median
/// of a cell (log-normal -3; bimodal -3 + 0.3 Phi^-1(5/7), the point where
/// 0.7 Phi(z) = 1/2) or the effect, log10(1/2) (A's median over B's).
double coverage_truth(CoverageScenario scenario);

/// Coverage of `method` at n seeds in `scenario`; throws std::invalid_argument
/// if the method does not apply to the scenario or n < 2.
CoverageRow measure_coverage(CoverageScenario scenario, CoverageMethod method, int n,
                             const CoverageOptions& options = {});

/// Every (scenario, method) at every n: a Markdown table, one line per
/// scenario and method, one column per n, cells "95.1 % (0.82)" = coverage
/// and median width.
std::string render_coverage_markdown(const std::vector<CoverageRow>& rows,
                                     const std::vector<int>& ns);

}  // namespace phnn
