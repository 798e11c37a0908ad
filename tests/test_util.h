// tests/test_util.h — shared references for the tests.
#pragma once

#include <cmath>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "phnn/data/ph_dataset.h"
#include "reference/discrete_gradient.h"
#include "reference/explicit_midpoint.h"
#include "reference/oscillator.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace testing_util {

/// Closed-form solution of the damped, forced harmonic oscillator
///   m q'' + c q' + k q = -u,  p = m q'   (underdamped: c^2 < 4 k m)
/// from x0 = (q0, p0): q(t) = q* + e^{-g t} (A cos(wd t) + B sin(wd t)),
/// q* = -u / k, g = c / 2m, wd = sqrt(k/m - g^2).
inline Vec2 damped_harmonic_solution(const OscillatorOptions& o, const Vec2& x0,
                                     double u, double t) {
  const double m = o.mass, k = o.stiffness, c = o.damping;
  const double g = c / (2.0 * m);
  const double wd = std::sqrt(k / m - g * g);
  const double q_star = -u / k;
  const double A = x0(0) - q_star;
  const double v0 = x0(1) / m;
  const double B = (v0 + g * A) / wd;
  const double e = std::exp(-g * t), cs = std::cos(wd * t), sn = std::sin(wd * t);
  const double q = q_star + e * (A * cs + B * sn);
  const double v = e * ((-g * A + wd * B) * cs + (-g * B - wd * A) * sn);
  return Vec2(q, m * v);
}

/// The bytes of the file at `path` ("" if it cannot be read).
inline std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Runs `command` through the shell with stdout and stderr captured into
/// *output (if given); returns its exit status (-1 if it did not exit).
inline int run_shell(const std::string& command, std::string* output = nullptr) {
  const std::string log =
      std::string(P_tmpdir) + "/phnn_test_cmd_" + std::to_string(::getpid()) + ".log";
  const int status = std::system((command + " > " + log + " 2>&1").c_str());
  if (output) {
    std::ifstream in(log);
    output->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

#if defined(PHNN_MPIEXEC) && defined(PHNN_BINARY)
/// "mpiexec -n RANKS <preflags> build/phnn": the start of a command line.
inline std::string mpiexec_phnn(int ranks) {
  return std::string(PHNN_MPIEXEC) + " -n " + std::to_string(ranks) + " " + PHNN_MPIEXEC_PREFLAGS +
         " " + PHNN_BINARY;
}
#endif

#ifdef PHNN_SOURCE_DIR
/// A shipped system file, sweeps/systems/<name>.toml, compiled.
inline std::unique_ptr<PhSystem> shipped_system(const std::string& name) {
  return load_system_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name + ".toml");
}
#endif

/// Trajectory `index` of the paper's system `kind` as the 2-state closed
/// forms see it: the initial state and constant input its shipped file
/// draws, and `steps` closed-form DG steps at options.generation_step
/// (states[0] = x0).
struct PaperTrajectory {
  double u = 0.0;
  std::vector<Vec2> states;
};
inline PaperTrajectory paper_trajectory(SystemKind kind, const DatasetOptions& options,
                                        std::int64_t index, int steps) {
  const auto system = builtin_system(OscillatorOptions::defaults(kind), options);
  const PhTrajectorySpec spec = ph_trajectory_spec(*system, options, index);
  const Oscillator osc(OscillatorOptions::defaults(kind));
  PaperTrajectory t;
  t.u = spec.u(0);
  t.states.push_back(Vec2(spec.x0(0), spec.x0(1)));
  for (int n = 0; n < steps; ++n) {
    const DiscreteGradientStep step =
        discrete_gradient_step(osc, t.states.back(), t.u, options.generation_step, options.newton);
    if (step.status != StepStatus::kConverged) {
      throw std::runtime_error("paper_trajectory: Newton failed at step " + std::to_string(n));
    }
    t.states.push_back(step.x_next);
  }
  return t;
}

}  // namespace testing_util
}  // namespace phnn
