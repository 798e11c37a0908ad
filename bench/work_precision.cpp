// bench/work_precision.cpp — integrator work-precision study on the true
// systems: wall time per trajectory against error, for the explicit
// midpoint (RK2), the Gonzalez discrete gradient (DG), classical RK4 and
// the fourth-order discrete gradient (DG4), over h = 1/12.5 s ... 1/3200 s.
//
//   build/work_precision [--trajectories N] [--repeats R] [--system FILE]... > wp.csv
//
// Without --system: the paper's three oscillators (their shipped files).
// With --system FILE or NAME (repeatable): those systems instead. Every
// system through the steps of include/phnn/integrators/integrator.h (every
// integrator of its table).
//   python3 analysis/plot_work_precision.py wp.csv docs/figures/
//
// Error: RMS over trajectories and the sample times t_k = k / 12.5 s
// (k = 1..50, common to every h) of ||x(t_k) - x_ref(t_k)||, against RK4 at
// h_ref = (1/3200 s) / 64 (its error, ~(omega h_ref)^4, is below
// round-off). Trajectories: the first N of the inference split of the data
// set (initial state and input by the generator's algorithms), 4 s each.
// Time: median over R repeats of (wall time for all trajectories) / N, the
// integration alone (errors and balance are measured in a separate pass).
// Power residual: worst |H(x_{n+1}) - H(x_n) - h P_n| / (|H(x_n)| + h |P_n|)
// with P_n the scheme's own discrete port power (DG, DG4: exact identities,
// expected at round-off); RK2 and RK4 have no discrete port power, so the
// trapezoidal P_n = -(p(x_n) + p(x_{n+1})) / 2 with p = z w + u y is used:
// their residual shows how far they are from a balance (O(h^3) per step).
// Reads no file, writes only to standard output.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "phnn/data/dataset.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/integrators/integrator.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace {

constexpr double kSampleInterval = 1.0 / 12.5;  // s: the coarsest h
constexpr int kSamples = 50;                    // 4 s
constexpr int kLevels = 9;                      // h = 1/12.5 ... 1/3200
constexpr double kDivergedNorm = 1e6;

// Continuous port power p(x) = z(w)^T w + u^T y at the true effort gradH(x).
double port_power(const PhSystem& sys, const VecX& x, const VecX& u) {
  const PhFlows f = sys.flows(sys.grad_hamiltonian(x), u);
  return f.z.dot(f.w) + u.dot(f.y);
}

template <class State>
struct StepResult {
  State x_next;
  double balance_residual = 0.0;  // relative, see the file header
  bool newton_failed = false;
};

// One step (ph_steps.h); with `diagnostics`, also the balance residual (kept
// out of the timed passes: for RK it costs two more flow evaluations).
StepResult<VecX> step(IntegratorKind m, const PhSystem& sys, const VecX& x, const VecX& u,
                      double h, bool diagnostics) {
  StepResult<VecX> r;
  const PhImplicitStep s = ph_step(m, sys, x, u, h);
  r.x_next = s.x_next;
  double power = 0.0;
  if (is_discrete_gradient(m)) {
    r.newton_failed = s.status != StepStatus::kConverged;
    power = -h * (s.flows.z.dot(s.flows.w) + u.dot(s.flows.y)) + h * h * h * s.correction_power;
  } else if (diagnostics) {
    power = -0.5 * h * (port_power(sys, x, u) + port_power(sys, r.x_next, u));
  }
  if (!diagnostics) return r;
  const double H0 = sys.hamiltonian(x);
  const double dH = sys.hamiltonian(r.x_next) - H0;
  r.balance_residual = std::abs(dH - power) / (std::abs(H0) + std::abs(power));
  return r;
}

template <class State>
struct Run {
  std::vector<State> samples;  // x(t_k), k = 1..kSamples
  double worst_balance = 0.0;
  int newton_failures = 0;
  bool diverged = false;
};

template <class System, class Spec>
auto integrate(IntegratorKind m, const System& osc, const Spec& spec, int steps_per_sample,
               bool diagnostics) {
  const double h = kSampleInterval / steps_per_sample;
  Run<std::decay_t<decltype(spec.x0)>> run;
  auto x = spec.x0;
  for (int k = 0; k < kSamples && !run.diverged; ++k) {
    for (int n = 0; n < steps_per_sample; ++n) {
      const auto s = step(m, osc, x, spec.u, h, diagnostics);
      run.worst_balance = std::max(run.worst_balance, s.balance_residual);
      run.newton_failures += s.newton_failed;
      x = s.x_next;
      if (!x.allFinite() || x.norm() > kDivergedNorm) {
        run.diverged = true;
        break;
      }
    }
    run.samples.push_back(x);
  }
  return run;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Options {
  int trajectories = 10;
  int repeats = 5;
  std::vector<std::string> systems;  // --system FILE
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--system" && i + 1 < argc) {
      o.systems.push_back(argv[++i]);
    } else if ((a == "--trajectories" || a == "--repeats") && i + 1 < argc) {
      const int v = std::atoi(argv[++i]);
      if (v < 1) {
        std::fprintf(stderr, "work_precision: %s must be >= 1\n", a.c_str());
        std::exit(2);
      }
      (a == "--trajectories" ? o.trajectories : o.repeats) = v;
    } else {
      std::fprintf(stderr,
                   "usage: work_precision [--trajectories N] [--repeats R] [--system FILE]...\n");
      std::exit(2);
    }
  }
  return o;
}

template <class System, class Spec>
void run_system(const std::string& name, const System& osc, const std::vector<Spec>& specs,
                const Options& o) {
  const int ref_steps = (1 << (kLevels - 1)) * 64;
  std::vector<decltype(integrate(IntegratorKind::kRk4, osc, specs[0], 1, false))> reference;
  for (const auto& s : specs) {
    reference.push_back(integrate(IntegratorKind::kRk4, osc, s, ref_steps, false));
  }
  for (const Integrator& integrator : all_integrators()) {
    const IntegratorKind m = integrator.kind;
    for (int level = 0; level < kLevels; ++level) {
      const int per_sample = 1 << level;
      // Timed passes integrate only; one more pass measures errors and balance.
      std::vector<double> seconds;
      for (int r = 0; r < o.repeats; ++r) {
        decltype(reference) timed;
        const auto t0 = std::chrono::steady_clock::now();
        for (const auto& s : specs) timed.push_back(integrate(m, osc, s, per_sample, false));
        const auto t1 = std::chrono::steady_clock::now();
        seconds.push_back(std::chrono::duration<double>(t1 - t0).count() /
                          o.trajectories);
      }
      decltype(reference) runs;
      for (const auto& s : specs) runs.push_back(integrate(m, osc, s, per_sample, true));
      double sum2 = 0.0, worst = 0.0, balance = 0.0;
      int failures = 0, diverged = 0;
      for (std::size_t i = 0; i < runs.size(); ++i) {
        diverged += runs[i].diverged;
        failures += runs[i].newton_failures;
        balance = std::max(balance, runs[i].worst_balance);
        for (int k = 0; k < kSamples; ++k) {
          const double e =
              runs[i].diverged
                  ? std::numeric_limits<double>::infinity()
                  : (runs[i].samples[k] - reference[i].samples[k]).norm();
          sum2 += e * e;
          worst = std::max(worst, e);
        }
      }
      std::printf("%s,%s,%.10g,%d,%.6e,%.6e,%.6e,%.3e,%d,%d\n",
                  name.c_str(), to_string(m).c_str(),
                  kSampleInterval / per_sample, per_sample * kSamples,
                  std::sqrt(sum2 / (runs.size() * kSamples)), worst,
                  median(seconds), balance, failures, diverged);
      std::fflush(stdout);
    }
  }
}

}  // namespace
}  // namespace phnn

int main(int argc, char** argv) {
  const phnn::Options o = phnn::parse(argc, argv);
  std::printf(
      "system,method,h,steps,rms_error,max_error,seconds_per_trajectory,"
      "worst_balance_residual,newton_failures,diverged_trajectories\n");
  const phnn::DatasetOptions data;
  std::vector<std::string> systems = o.systems;
  if (systems.empty()) systems = {"harmonic", "duffing", "self-sustained"};
  for (const std::string& path : systems) {
    const auto sys = phnn::make_system(path);
    if (!sys->has_energy()) {
      std::fprintf(stderr, "work_precision: %s defines no energy H (structure only); give a system "
                           "file that generates data\n", path.c_str());
      return 2;
    }
    if (sys->control_design().time_varying()) {
      std::fprintf(stderr, "work_precision: note: %s has a time-varying input; each trajectory "
                           "holds its first sample's input here (orders of the schemes at fixed u)\n",
                   path.c_str());
    }
    std::vector<phnn::PhTrajectorySpec> specs;
    for (int i = 0; i < o.trajectories; ++i) {
      specs.push_back(phnn::ph_trajectory_spec(*sys, data, data.inference_begin() + i));
    }
    phnn::run_system(sys->name(), *sys, specs, o);
  }
  return 0;
}
