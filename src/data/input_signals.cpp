// src/data/input_signals.cpp — src/data/input_signals.h.
#include "data/input_signals.h"

#include <cmath>

#include "phnn/common/check.h"
#include "phnn/common/cr_math.h"

namespace phnn {
namespace internal {
namespace {

// Steps: a new level per input ~ U(range[i]) every `hold` seconds, drawn in
// order as the samples reach it.
std::vector<VecX> step_samples(const ControlDesign& c, int nu, int count, double hs,
                               CounterRng* rng) {
  std::vector<VecX> out;
  VecX level = VecX::Zero(nu);
  long drawn = -1;
  for (int k = 0; k < count; ++k) {
    const long j = static_cast<long>(std::floor(k * hs / c.hold + 1e-9));
    for (; drawn < j; ++drawn) level = uniform_in_ranges(c.range, nu, rng);
    out.push_back(level);
  }
  return out;
}

// Time-varying designs (ControlDesign::time_varying): the inputs at the
// samples k = 0..count-1, t_k = k h_s, each held over [t_k, t_{k+1}). Drawn
// from the control stream input by input: the offset c_i (if a range is
// given), then (a, phi) per sine, or (a, phi) of the chirp.
}  // namespace

std::vector<VecX> input_samples(const PhSystem& system, const DatasetOptions& options,
                                CounterRng* rng) {
  const ControlDesign& c = system.control_design();
  const int nu = system.n_u();
  const int count = options.num_inference_steps() + 1;
  const double hs = options.stride() * options.generation_step;
  if (c.design == ControlDesign::Design::kSteps) {
    // A level per sample at most: a shorter hold would draw levels nobody
    // samples (and, for a tiny hold, without end).
    PHNN_REQUIRE(c.hold >= hs * (1.0 - 1e-9),
                 system.control_location("hold") << ": control.hold = " << c.hold
                                           << " s is shorter than one sample (" << hs << " s at "
                                           << options.sample_rate << " Hz); use hold >= " << hs);
    return step_samples(c, nu, count, hs, rng);
  }
  // Above half the sample rate the held samples cannot represent a sine
  // (it aliases to a slower one): refused rather than silently folded.
  const double nyquist = 0.5 / hs;
  for (double f : c.frequencies) {
    PHNN_REQUIRE(f <= nyquist, system.control_location(c.design == ControlDesign::Design::kSines
                                                           ? "frequencies" : "frequency")
                                   << ": " << f << " Hz is above half the sample rate (" << nyquist
                                   << " Hz at " << options.sample_rate
                                   << " Hz): the held samples cannot represent it; use frequencies <= "
                                   << nyquist << " Hz");
  }
  const double two_pi = 2.0 * M_PI, duration = options.beta * options.period;
  std::vector<VecX> out(static_cast<std::size_t>(count), VecX::Zero(nu));
  for (int i = 0; i < nu; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const double offset = c.range.empty() ? 0.0 : rng->uniform(c.range[iu][0], c.range[iu][1]);
    const std::size_t m = c.design == ControlDesign::Design::kSines ? c.frequencies.size() : 1;
    std::vector<double> a(m), phi(m);
    for (std::size_t j = 0; j < m; ++j) {
      a[j] = rng->uniform(c.amplitude[0], c.amplitude[1]);
      phi[j] = rng->uniform(0.0, two_pi);
    }
    for (int k = 0; k < count; ++k) {
      const double t = k * hs;
      double v = offset;
      if (c.design == ControlDesign::Design::kSines) {
        for (std::size_t j = 0; j < m; ++j) v += a[j] * cr::sin(two_pi * c.frequencies[j] * t + phi[j]);
      } else {
        const double f0 = c.frequencies[0], f1 = c.frequencies[1];
        v += a[0] * cr::sin(two_pi * (f0 * t + (f1 - f0) * t * t / (2.0 * duration)) + phi[0]);
      }
      out[static_cast<std::size_t>(k)](i) = v;
    }
  }
  return out;
}


// u_i ~ U(range[i]) for each input, in order.
VecX uniform_in_ranges(const std::vector<std::array<double, 2>>& range, int nu, CounterRng* rng) {
  VecX u(nu);
  for (int i = 0; i < nu; ++i) {
    u(i) = rng->uniform(range[static_cast<std::size_t>(i)][0], range[static_cast<std::size_t>(i)][1]);
  }
  return u;
}

}  // namespace internal
}  // namespace phnn
