// include/phnn/report/comparison.h — a comparison of two cells as one object:
// the effect (log10 MSE ratio) with an interval, P(A < B) with an interval,
// and a four-way reading at a margin delta; paired by seed when the two
// cells' runs share initialization, batches and data (docs/METHOD.md
// "Comparisons"). Reads config and statistics; no HDF5, no MPI.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "phnn/common/enum_names.h"
#include "phnn/config/run_config.h"
#include "phnn/report/intervals.h"
#include "phnn/report/statistics.h"

namespace phnn {

/// One cell's results by seed: seed -> inference MSE, +inf for a diverged
/// run (NaN is read as +inf). Only finished runs belong in it.
using SeedResults = std::map<int, double>;

/// The four-way reading of a comparison of A against B at a margin delta.
enum class ComparisonReading { kABetter, kBBetter, kEquivalent, kUndecided };
inline constexpr EnumNames<ComparisonReading, 4> kComparisonReadingNames{
    "reading", {{{ComparisonReading::kABetter, "A better"}, {ComparisonReading::kBBetter, "B better"},
                 {ComparisonReading::kEquivalent, "equivalent"},
                 {ComparisonReading::kUndecided, "undecided"}}}};
inline std::string to_string(ComparisonReading reading) { return kComparisonReadingNames.name(reading); }

/// How the effect's interval is computed.
enum class EffectInterval {
  /// Distribution-free: the sign-test interval of the median per-seed log
  /// ratio (paired), Moses's interval of the Hodges-Lehmann shift (unpaired).
  kOrderStatistic,
  /// Percentile bootstrap of the same statistic (paired: of the median of
  /// the per-seed log ratios; unpaired: falls back to kOrderStatistic).
  kPercentileBootstrap,
};

/// Options of compare_cells(); the defaults are docs/METHOD.md's.
struct ComparisonOptions {
  /// Equivalence margin, a factor on the MSE: "equivalent within x delta"
  /// needs the effect's interval inside (-log10 delta, +log10 delta).
  double delta = 1.5;
  /// Confidence of both intervals.
  double confidence = 0.95;
  /// Fewest seeds (paired: pairs; unpaired: on each side) for any reading
  /// but "undecided" (the tables' kMinSeedsForInterval).
  int min_seeds = 5;
  /// Chosen from the measured coverage (docs/METHOD.md "Comparisons").
  EffectInterval effect_interval = EffectInterval::kOrderStatistic;
  /// Resampling of kPercentileBootstrap (a fixed key: the interval is a
  /// function of the values alone).
  BootstrapOptions bootstrap;

  /// Throws std::invalid_argument naming the field unless delta > 1,
  /// 0 < confidence < 1, min_seeds >= 1 and bootstrap is valid.
  void validate() const;
};

/// A comparison of cell A against cell B. Effects are log10(MSE_A / MSE_B):
/// below 0 A has the smaller error.
struct Comparison {
  bool paired = false;
  /// Seeds entering: paired, both equal n_pairs (the seeds in both cells).
  int n_a = 0, n_b = 0, n_pairs = 0;
  /// Diverged runs (MSE +inf) among those entering.
  int diverged_a = 0, diverged_b = 0;
  /// Paired: median over seeds s of d_s = log10 MSE_A(s) - log10 MSE_B(s),
  /// with d_s = +inf (A diverged), -inf (B diverged), 0 (both diverged).
  /// Unpaired: the Hodges-Lehmann shift of log10 MSE (the same rules for inf).
  double effect = 0.0;
  Interval effect_interval;
  /// The order-statistic interval's exact coverage for continuous data
  /// (below `confidence` where no interval reaches it: 93.75 % for 5 pairs
  /// at 95 %); NaN for a bootstrap interval.
  double effect_coverage = 0.0;
  /// Paired: share of seeds with A < B (a tie counts 1/2), Wilson interval.
  /// Unpaired: Mann-Whitney P(A < B) + P(A = B)/2, Newcombe interval.
  double p_a_less = 0.0;
  Interval p_a_less_interval;
  ComparisonReading reading = ComparisonReading::kUndecided;
};

/// Compares A against B. With `paired`, only seeds present in both enter,
/// as pairs; otherwise every seed of each side. Reading, with [lo, hi] the
/// effect's interval and D = log10 delta:
///   fewer than min_seeds seeds (pairs, or on a side) -> undecided
///   -D < lo and hi < D                               -> equivalent
///   hi < 0                                           -> A better
///   lo > 0                                           -> B better
///   otherwise                                        -> undecided
/// Equivalence is read first: an interval inside the margin says the two
/// cells differ by less than x delta, even when it also excludes 0.
/// Deterministic: a function of the two maps alone (fixed resampling key).
/// Throws std::invalid_argument on invalid options or an empty side.
///
///   const Comparison c = compare_cells({{0, 1e-3}, {1, 2e-3}, ...},
///                                      {{0, 4e-3}, {1, 5e-3}, ...},
///                                      /*paired=*/true);
///   if (c.reading == ComparisonReading::kABetter) ...
Comparison compare_cells(const SeedResults& a, const SeedResults& b, bool paired,
                         const ComparisonOptions& options = {});

/// A comparison with the names of its two cells (any labels the caller
/// chooses, e.g. "study/system/model/column").
struct NamedComparison {
  std::string a, b;
  Comparison comparison;
};

/// The exported form of comparisons (one header line, one line each):
///   a,b,paired,n_a,n_b,n_pairs,diverged_a,diverged_b,effect,effect_low,
///   effect_high,effect_coverage,p_a_less,p_low,p_high,delta,reading
/// paired 0/1; numbers "%.6e", "inf" / "-inf" for infinities, empty for
/// NaN; reading as to_string(); names quoted when they hold , or ".
/// With list > 0 (one of several seed lists, `phnn reduce --seed-lists`) the
/// header starts with a column `list` and every record with the number.
std::string render_comparisons_csv(const std::vector<NamedComparison>& comparisons, double delta,
                                   int list = 0);

/// Whether runs of the cells of `a` and `b` with equal seeds share their
/// seed effect (docs/METHOD.md "Comparisons"): the same initial weights (same
/// model kind, size and system dimensions), the same data (system, physics,
/// data options, N_train) and the same minibatch order (batch size). They
/// may differ in integrator, regularizer, its weight and other training
/// options. The seeds of a and b are ignored.
bool cells_are_paired(const RunConfig& a, const RunConfig& b);

}  // namespace phnn
