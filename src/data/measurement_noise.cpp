// src/data/measurement_noise.cpp — Gaussian measurement noise on a
// generated data set's pairs (add_measurement_noise, include/phnn/data/
// measured.h; docs/METHOD.md "Measured data"). In memory only.
#include <cmath>
#include <sstream>

#include "phnn/common/check.h"
#include "phnn/common/cr_math.h"
#include "phnn/data/counter_rng.h"
#include "phnn/data/measured.h"

namespace phnn {

void NoiseOptions::validate(int n_x) const {
  PHNN_REQUIRE(levels.empty() || static_cast<int>(levels.size()) == n_x,
               "noise: " << levels.size() << " levels for " << n_x << " states; give one per state "
               "(or one for all)");
  for (double l : levels) {
    PHNN_REQUIRE(std::isfinite(l) && l >= 0, "noise level " << l << " must be finite and >= 0");
  }
}

std::vector<double> add_measurement_noise(PhSystemData* data, int rng_id,
                                          const NoiseOptions& options) {
  const int nx = static_cast<int>(data->state_names.size());
  options.validate(nx);
  if (options.levels.empty()) return {};
  // spread_j: standard deviation (two passes) of x_j over the clean
  // validation pairs' x — a fixed split, so sigma does not depend on n_train.
  std::vector<double> sigma(static_cast<std::size_t>(nx));
  const std::vector<VecX>& xs = data->validation.x;
  for (int j = 0; j < nx; ++j) {
    const double n = static_cast<double>(xs.size());
    double mean = 0, var = 0;
    for (const VecX& x : xs) mean += x(j) / n;
    for (const VecX& x : xs) var += (x(j) - mean) * (x(j) - mean) / (n - 1);
    const double spread = xs.size() > 1 ? std::sqrt(var) : 0.0;
    const double level = options.levels[static_cast<std::size_t>(j)];
    sigma[static_cast<std::size_t>(j)] = options.relative ? level * spread : level;
  }
  // Box-Muller: z = sqrt(-2 ln(1 - u1)) cos(2 pi u2), u in [0, 1).
  const auto normal = [](CounterRng* rng) {
    const double u1 = rng->uniform(), u2 = rng->uniform();
    return std::sqrt(-2.0 * cr::log(1.0 - u1)) * cr::cos(2.0 * M_PI * u2);
  };
  for (PhPairSet* p : {&data->train, &data->validation}) {
    for (std::size_t i = 0; i < p->size(); ++i) {
      CounterRng rng = CounterRng::for_trajectory(data->options.data_seed, rng_id, p->trajectory[i],
                                                  CounterRng::kMeasurementNoise);
      for (VecX* x : {&p->x[i], &p->x_next[i]}) {
        for (int j = 0; j < nx; ++j) (*x)(j) += sigma[static_cast<std::size_t>(j)] * normal(&rng);
      }
    }
  }
  std::ostringstream note;
  note.precision(6);
  note << (options.relative ? "relative" : "absolute") << " levels";
  for (double l : options.levels) note << " " << l;
  note << ": sigma";
  for (int j = 0; j < nx; ++j) note << " " << data->state_names[static_cast<std::size_t>(j)] << "=" << sigma[static_cast<std::size_t>(j)];
  note << " (training and validation pairs; inference clean)";
  data->noise = note.str();
  return sigma;
}

}  // namespace phnn
