// src/report/coverage_study.cpp — synthetic log10 MSE samples, the intervals
// of each method on them, and the coverage table.
#include "phnn/report/coverage_study.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "phnn/data/counter_rng.h"
#include "phnn/report/intervals.h"
#include "phnn/report/statistics.h"

namespace phnn {
namespace {

constexpr double kShift = -0.30102999566398120;  // log10(1/2): A's median / B's

// A standard normal draw by inversion of a uniform on the open (0, 1).
double normal(CounterRng& rng) {
  const double u = (static_cast<double>(rng.next_u64() >> 11) + 0.5) * 0x1.0p-53;
  return normal_quantile(u);
}

// A bimodal cell's value given its mode (good with probability 0.7).
double bimodal(bool good, double noise) { return (good ? -3.0 : 1.0) + 0.3 * noise; }

struct Sample {
  std::vector<double> a, b;  // b empty for a cell scenario
};

Sample draw(CoverageScenario scenario, int n, CounterRng& rng) {
  Sample s;
  for (int i = 0; i < n; ++i) {
    switch (scenario) {
      case CoverageScenario::kCellLogNormal:
        s.a.push_back(-3.0 + 0.5 * normal(rng));
        break;
      case CoverageScenario::kCellBimodal:
        s.a.push_back(bimodal(rng.uniform() < 0.7, normal(rng)));
        break;
      case CoverageScenario::kPairsLogNormal:
        s.a.push_back(-3.0 + kShift + 0.5 * normal(rng));
        s.b.push_back(-3.0 + 0.5 * normal(rng));
        break;
      case CoverageScenario::kPairsLogNormalShared: {
        const double seed_effect = -3.0 + 0.5 * normal(rng);
        s.a.push_back(seed_effect + kShift + 0.2 * normal(rng));
        s.b.push_back(seed_effect + 0.2 * normal(rng));
        break;
      }
      case CoverageScenario::kPairsBimodal:
        s.a.push_back(kShift + bimodal(rng.uniform() < 0.7, normal(rng)));
        s.b.push_back(bimodal(rng.uniform() < 0.7, normal(rng)));
        break;
      case CoverageScenario::kPairsBimodalShared: {
        const bool good = rng.uniform() < 0.7;
        s.a.push_back(kShift + bimodal(good, normal(rng)));
        s.b.push_back(bimodal(good, normal(rng)));
        break;
      }
    }
  }
  return s;
}

Interval interval_of(CoverageMethod method, const Sample& s, const BootstrapOptions& bootstrap) {
  std::vector<double> d;
  for (std::size_t i = 0; i < s.b.size(); ++i) d.push_back(s.a[i] - s.b[i]);
  switch (method) {
    case CoverageMethod::kPercentileBootstrap:
      return bootstrap_median_interval(s.a, bootstrap);
    case CoverageMethod::kBca:
      return bca_median_interval(s.a, bootstrap);
    case CoverageMethod::kOrderStatistic:
      return order_statistic_median_interval(s.a, bootstrap.confidence);
    case CoverageMethod::kPairedBootstrap:
      return bootstrap_median_interval(d, bootstrap);
    case CoverageMethod::kPairedBca:
      return bca_median_interval(d, bootstrap);
    case CoverageMethod::kPairedOrderStatistic:
      return order_statistic_median_interval(d, bootstrap.confidence);
    case CoverageMethod::kUnpairedMoses:
      return hodges_lehmann_interval(s.a, s.b, bootstrap.confidence);
  }
  throw std::logic_error("interval_of: unknown method");
}

}  // namespace

bool is_pairs(CoverageScenario scenario) {
  return scenario != CoverageScenario::kCellLogNormal && scenario != CoverageScenario::kCellBimodal;
}

std::vector<CoverageMethod> coverage_methods(CoverageScenario scenario) {
  if (!is_pairs(scenario)) {
    return {CoverageMethod::kPercentileBootstrap, CoverageMethod::kBca,
            CoverageMethod::kOrderStatistic};
  }
  return {CoverageMethod::kPairedBootstrap, CoverageMethod::kPairedBca,
          CoverageMethod::kPairedOrderStatistic, CoverageMethod::kUnpairedMoses};
}

double coverage_truth(CoverageScenario scenario) {
  switch (scenario) {
    case CoverageScenario::kCellLogNormal:
      return -3.0;
    case CoverageScenario::kCellBimodal:
      return -3.0 + 0.3 * normal_quantile(0.5 / 0.7);
    default:
      return kShift;
  }
}

CoverageRow measure_coverage(CoverageScenario scenario, CoverageMethod method, int n,
                             const CoverageOptions& options) {
  const auto methods = coverage_methods(scenario);
  if (std::find(methods.begin(), methods.end(), method) == methods.end() || n < 2) {
    throw std::invalid_argument("measure_coverage: " + to_string(method) + " at n = " +
                                std::to_string(n) + " does not apply to " + to_string(scenario));
  }
  BootstrapOptions bootstrap;
  bootstrap.resamples = options.resamples;
  bootstrap.confidence = options.confidence;
  const double truth = coverage_truth(scenario);
  CoverageRow row{scenario, method, n, 0, options.replications, 0.0};
  std::vector<double> widths;
  for (int r = 0; r < options.replications; ++r) {
    // The same samples for every method of a scenario: methods compare on
    // equal draws.
    CounterRng rng(mix64(options.seed ^ mix64((static_cast<std::uint64_t>(scenario) << 48) ^
                                              (static_cast<std::uint64_t>(n) << 32) ^
                                              static_cast<std::uint64_t>(r))));
    const Interval i = interval_of(method, draw(scenario, n, rng), bootstrap);
    row.covered += (i.low <= truth && truth <= i.high) ? 1 : 0;
    widths.push_back(i.high - i.low);
  }
  row.median_width = quantile_linear(widths, 0.5);
  return row;
}

std::string render_coverage_markdown(const std::vector<CoverageRow>& rows,
                                     const std::vector<int>& ns) {
  std::string out = "| scenario | method |";
  std::string rule = "|---|---|";
  for (int n : ns) {
    out += " n = " + std::to_string(n) + " |";
    rule += "---|";
  }
  out += "\n" + rule + "\n";
  for (CoverageScenario scenario : all_coverage_scenarios()) {
    for (CoverageMethod method : coverage_methods(scenario)) {
      std::string line = "| " + to_string(scenario) + " | " + to_string(method) + " |";
      bool any = false;
      for (int n : ns) {
        const auto it = std::find_if(rows.begin(), rows.end(), [&](const CoverageRow& r) {
          return r.scenario == scenario && r.method == method && r.n == n;
        });
        char cell[48] = " — |";
        if (it != rows.end()) {
          std::snprintf(cell, sizeof cell, " %.1f %% (%.2f) |", 100.0 * it->coverage(),
                        it->median_width);
          any = true;
        }
        line += cell;
      }
      if (any) out += line + "\n";
    }
  }
  return out;
}

}  // namespace phnn
