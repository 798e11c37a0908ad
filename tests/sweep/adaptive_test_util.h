// tests/sweep/adaptive_test_util.h — shared by the [adaptive] tests
// (adaptive_test.cpp, adaptive_options_test.cpp): a one-study sweep text
// with an [adaptive] table, the parse error of a bad one, and synthetic
// results for every run of a grid.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "phnn/sweep/adaptive.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace adaptive_test {

inline std::string sweep_text(const std::string& models, const std::string& adaptive) {
  return "name = \"a\"\n"                         // 1
         "[grid]\n"                               // 2
         "systems = [\"harmonic\"]\n"             // 3
         "models = [" + models + "]\n"            // 4
         "seeds = \"0-4\"\n"                      // 5
         "[adaptive]\n"                           // 6
         + adaptive;                              // 7 ...
}

inline const std::string kTwoModels = "\"phnn-jr-rk2\", \"phnn-jr-rk4\"";
inline const std::string kColumnBest = "max_seeds = 12\nbatch = 3\nrule = \"column-best\"\n";

inline std::string error_of(const std::string& text) {
  try {
    parse_sweep_text(text, "x.toml");
  } catch (const SweepFileError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a SweepFileError for:\n" << text;
  return "";
}

// Results for every run: status done and mse = value(model label, seed).
struct Results {
  std::vector<RunStatus> status;
  std::vector<double> mse;
};
inline Results results_of(const Grid& grid, const std::function<double(const RunConfig&)>& value) {
  Results r;
  for (const RunConfig& run : grid.runs) {
    r.status.push_back(RunStatus::kDone);
    r.mse.push_back(value(run));
  }
  return r;
}

inline int seeds_of(const AdaptiveState& s, const Grid& grid, IntegratorKind integrator) {
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    if (grid.runs[static_cast<std::size_t>(grid.cells[c].runs[0])].integrator == integrator) {
      return s.cell_seeds[c];
    }
  }
  return -1;
}

}  // namespace adaptive_test
}  // namespace phnn
