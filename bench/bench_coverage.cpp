// bench/bench_coverage.cpp — the coverage study of the interval methods
// (include/phnn/report/coverage_study.h) in full: a Markdown table for
// docs/METHOD.md "Comparisons" (not a test; ctest -L stats runs a small one).
//
//   bench_coverage [replications [resamples [n ...]]]
//                  defaults 2000, 2000, n = 5 10 20 40
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "phnn/report/coverage_study.h"

int main(int argc, char** argv) {
  phnn::CoverageOptions options;
  if (argc > 1) options.replications = std::atoi(argv[1]);
  if (argc > 2) options.resamples = std::atoi(argv[2]);
  std::vector<int> ns;
  for (int i = 3; i < argc; ++i) ns.push_back(std::atoi(argv[i]));
  if (ns.empty()) ns = {5, 10, 20, 40};
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<phnn::CoverageRow> rows;
  for (phnn::CoverageScenario scenario : phnn::all_coverage_scenarios()) {
    for (phnn::CoverageMethod method : phnn::coverage_methods(scenario)) {
      for (int n : ns) rows.push_back(phnn::measure_coverage(scenario, method, n, options));
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "Coverage of nominal %.0f %% intervals, %d replications, %d resamples "
      "(coverage, median width in log10 MSE):\n\n%s\n%.1f s\n",
      100.0 * options.confidence, options.replications, options.resamples,
      phnn::render_coverage_markdown(rows, ns).c_str(), seconds);
  return 0;
}
