// include/phnn/report/statistics.h — quantiles, the interquartile mean and
// the percentile-bootstrap intervals of a median or an IQM, for the
// reducer's tables. Pure functions: no HDF5, no
// MPI, no std:: random distributions (their output differs between standard
// libraries), so every number printed is the same on every machine.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace phnn {

/// The q-quantile of `values` with numpy's default ("linear") method:
///
///   h = (n - 1) q,   Q(q) = s[floor h] + (h - floor h) (s[floor h + 1] - s[floor h])
///
/// over the sorted values s (Hyndman & Fan type 7). E.g. {1, 2, 3, 4}:
/// Q(0.25) = 1.75, Q(0.5) = 2.5, Q(0.75) = 3.25. Infinite neighbours are
/// exact, never NaN (a diverged run's MSE is +inf):
///   s[lo] == s[hi] (also both +inf)      -> s[lo]
///   s[hi] = +inf, h not an integer       -> +inf  (numpy agrees)
///   s[lo] = -inf, h not an integer       -> -inf
/// Throws std::invalid_argument if `values` is empty, contains a NaN, or q is
/// outside [0, 1].
double quantile_linear(std::vector<double> values, double q);

/// quantile_linear of values already sorted ascending, without copying or
/// checking them (the bootstrap's inner loop). `sorted` must not be empty.
double quantile_linear_sorted(const std::vector<double>& sorted, double q);

/// The interquartile mean (IQM) of values sorted ascending: the 25 % trimmed
/// mean of Agarwal et al. (NeurIPS 2021, rliable), scipy.stats.trim_mean(x,
/// 0.25):
///
///   g = floor(n / 4),   IQM = (s[g] + ... + s[n - 1 - g]) / (n - 2 g)
///
/// (summed in ascending order). E.g. {1, 2, 3, 4, 100}: g = 1, (2 + 3 + 4) / 3
/// = 3; n <= 3 keeps every value (the mean). +inf (a diverged run) sorts to
/// the top: dropped while at most g values are +inf, else the IQM is +inf.
/// `sorted` must not be empty and hold no NaN (not checked: the bootstrap's
/// inner loop).
double interquartile_mean_sorted(const std::vector<double>& sorted);

/// interquartile_mean_sorted of `values` in any order. Throws
/// std::invalid_argument if `values` is empty or contains a NaN.
double interquartile_mean(std::vector<double> values);

/// Options of the percentile bootstrap of a median or an IQM.
struct BootstrapOptions {
  /// Resamples B. The empirical 2.5 % point is off by about
  /// sqrt(0.025 * 0.975 / B) in probability: 0.16 % at B = 10 000, 0.05 % at
  /// 100 000. The bootstrap medians of 10 seeds take a few dozen distinct
  /// values, so an end point jumps to a neighbouring value with `seed` where
  /// the exact bootstrap distribution has a cumulative probability that close
  /// to 2.5 % or 97.5 %: at B = 10 000 that moved an end point of 12 of the
  /// 15 cells of a 10-seed results file across 20 seeds (up to 2x in a
  /// bimodal cell), at B = 100 000 none. 150 cells of 10 seeds take ~3 s.
  int resamples = 100000;
  /// Coverage of the interval: its ends are the (1 - c)/2 and (1 + c)/2
  /// quantiles (quantile_linear) of the B bootstrap medians.
  double confidence = 0.95;
  /// Key of the random stream (CounterRng, splitmix64): every cell starts
  /// from the same key, so a cell's interval depends on its values only.
  std::uint64_t seed = 0x70686e6e626f6f74ULL;  // "phnnboot"

  /// Throws std::invalid_argument naming the field unless resamples >= 2000
  /// and 0 < confidence < 1.
  void validate() const;
};

/// A closed interval [low, high]; +inf allowed.
struct Interval {
  double low = 0.0, high = 0.0;
  /// True if the two closed intervals share a point.
  bool overlaps(const Interval& other) const { return low <= other.high && other.low <= high; }
};

/// The B bootstrap medians of `values` (n of them), in the order drawn:
/// with s = `values` sorted ascending (so the result depends on the multiset
/// only), resample b draws n indices i_1..i_n, each uniform on {0, ..., n - 1}
/// (CounterRng::below, Lemire's unbiased method, from one stream keyed by
/// options.seed and consumed in order), and its median is
/// quantile_linear({s[i_1], ..., s[i_n]}, 0.5). Throws
/// std::invalid_argument for empty values or a NaN among them, or invalid
/// options.
std::vector<double> bootstrap_medians(const std::vector<double>& values,
                                      const BootstrapOptions& options = {});

/// The B bootstrap statistics of `values`: the resamples of
/// bootstrap_medians (same stream, same draws), each sorted and passed to
/// `statistic` (e.g. quantile_linear_sorted at 0.5, interquartile_mean_sorted).
/// Same errors as bootstrap_medians.
std::vector<double> bootstrap_statistics(const std::vector<double>& values,
                                         const BootstrapOptions& options,
                                         double (*statistic)(const std::vector<double>& sorted));

/// The percentile interval of bootstrap draws: [Q((1 - c)/2), Q((1 + c)/2)]
/// (quantile_linear) of `draws`, c = `confidence`. `draws` must not be empty.
Interval percentile_interval(std::vector<double> draws, double confidence);

/// Percentile-bootstrap confidence interval of the median of `values`:
///   [Q((1 - c)/2), Q((1 + c)/2)] of bootstrap_medians(values, options).
/// A constant sample gives [v, v]; n = 1 gives [v, v]; n = 3 with
/// a < b < c gives [a, c] at 95 % (each of a and c is the bootstrap median
/// with probability 7/27). Same errors as bootstrap_medians.
/// Memoized per process (the values' bits and the options are the key): a
/// reducer replaying adaptive rounds asks for each cell's interval once per
/// round and table. Thread-safe.
Interval bootstrap_median_interval(const std::vector<double>& values,
                                   const BootstrapOptions& options = {});

/// Percentile-bootstrap confidence interval of the IQM of `values`, the
/// median's interval with interquartile_mean_sorted in place of the median
/// (same resamples, same key; rliable's stratified bootstrap of one stratum):
///   [Q((1 - c)/2), Q((1 + c)/2)] of bootstrap_statistics(values, options,
///                                    interquartile_mean_sorted).
/// A resample whose +inf values outnumber its trimming has IQM +inf, so the
/// upper end is +inf when such resamples pass (1 - c)/2. Same errors as
/// bootstrap_medians.
Interval bootstrap_iqm_interval(const std::vector<double>& values,
                                const BootstrapOptions& options = {});

}  // namespace phnn
