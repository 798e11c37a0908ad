// bench/bench_system_data.cpp — cost of generating a data set (the paper's
// splits: 400 train pairs, 2500 validation pairs, 100 inference trajectories
// of 2000 DG steps) for the shipped system files (the paper's three are the
// built-in names).
// Usage: bench_system_data [repeats=5] [sweeps/systems] [only=NAME] (NAME: one
// system file's name). Prints CSV:
// system,source,n_x,median_s,min_s,steps,us_per_dg_step.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "phnn/data/ph_dataset.h"
#include "phnn/systems/system_file.h"

namespace {

// DG steps the splits take: (n + 1) * stride per pair, 2000 per inference trajectory.
template <class Pairs>
long pair_steps(const Pairs& p, int stride) {
  long steps = 0;
  for (int n : p.position) steps += (n + 1) * stride;
  return steps;
}

template <class F>
std::vector<double> time_runs(int repeats, F&& f) {
  std::vector<double> s;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(s.begin(), s.end());
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace phnn;
  const int repeats = argc > 1 ? std::atoi(argv[1]) : 5;
  const std::string dir = argc > 2 ? argv[2] : "sweeps/systems";
  const std::string only = argc > 3 ? argv[3] : "";
  const DatasetOptions options;
  std::cout << "system,source,n_x,median_s,min_s,steps,us_per_dg_step\n";
  auto report = [&](const std::string& name, const std::string& source, int nx,
                    const std::vector<double>& s, long steps) {
    const double median = s[s.size() / 2];
    std::cout << name << "," << source << "," << nx << "," << median << "," << s.front() << ","
              << steps << "," << 1e6 * median / static_cast<double>(steps) << "\n";
  };
  for (const std::string name : {"harmonic", "duffing", "self-sustained", "pendulum",
                                 "coupled-duffing", "mass-chain"}) {
    if (!only.empty() && name != only) continue;
    const auto system = load_system_file(dir + "/" + name + ".toml");
    PhSystemData data;
    const auto s = time_runs(repeats, [&] { data = make_ph_system_data(*system, options, 400); });
    const long steps = pair_steps(data.train, options.stride()) +
                       pair_steps(data.validation, options.stride()) + 100L * 2000;
    report(name, "file", system->n_x(), s, steps);
  }
  return 0;
}
