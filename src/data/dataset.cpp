// src/data/dataset.cpp — the data-set options (dataset.h).
#include "phnn/data/dataset.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "phnn/common/check.h"

namespace phnn {
namespace {

// Integer ratio a / b when it is one to 1e-9 relative; -1 otherwise.
long integer_ratio(double a, double b) {
  const double r = a / b;
  const double n = std::round(r);
  return std::abs(r - n) <= 1e-9 * std::max(1.0, std::abs(r))
             ? static_cast<long>(n)
             : -1;
}

}  // namespace

int DatasetOptions::stride() const {
  const long s = integer_ratio(1.0 / generation_step, sample_rate);
  PHNN_REQUIRE(s >= 1, "Invalid DatasetOptions: sr_gen / sample_rate = "
                           << (1.0 / generation_step) << " / " << sample_rate
                           << " is not a positive integer; choose "
                              "generation_step = 1 / (k sample_rate).");
  return static_cast<int>(s);
}

int DatasetOptions::num_pair_positions() const {
  // t_{n+1} = (n + 1) / sr <= alpha T0  <=>  n + 1 <= floor(alpha T0 sr).
  const int count =
      static_cast<int>(std::floor(alpha * period * sample_rate + 1e-9));
  return count;
}

int DatasetOptions::num_inference_steps() const {
  return static_cast<int>(std::floor(beta * period * sample_rate + 1e-9));
}

void DatasetOptions::validate() const {
  auto positive = [](const char* field, double v) {
    PHNN_REQUIRE(std::isfinite(v) && v > 0.0,
                 "Invalid DatasetOptions: " << field << " = " << v
                                            << "; violated constraint: "
                                            << field << " > 0.");
  };
  positive("generation_step", generation_step);
  positive("period", period);
  positive("beta", beta);
  positive("alpha", alpha);
  positive("sample_rate", sample_rate);
  positive("energy_min", energy_min);
  positive("equilibrium_energy_min", equilibrium_energy_min);
  PHNN_REQUIRE(energy_max >= energy_min,
               "Invalid DatasetOptions: energy_max = "
                   << energy_max << " < energy_min = " << energy_min << ".");
  PHNN_REQUIRE(equilibrium_energy_max >= equilibrium_energy_min,
               "Invalid DatasetOptions: equilibrium_energy_max = "
                   << equilibrium_energy_max << " < equilibrium_energy_min = "
                   << equilibrium_energy_min << ".");
  PHNN_REQUIRE(alpha <= beta, "Invalid DatasetOptions: alpha = "
                                  << alpha << " > beta = " << beta << ".");
  PHNN_REQUIRE(num_train_max >= 1 && num_validation >= 1 && num_inference >= 1,
               "Invalid DatasetOptions: split sizes (train "
                   << num_train_max << ", validation " << num_validation
                   << ", inference " << num_inference << ") must be >= 1.");
  PHNN_REQUIRE(num_train_max + num_validation + num_inference <=
                   num_trajectories,
               "Invalid DatasetOptions: the splits need "
                   << num_train_max + num_validation + num_inference
                   << " trajectories but num_trajectories = "
                   << num_trajectories << ".");
  (void)stride();
  PHNN_REQUIRE(num_pair_positions() >= 1,
               "Invalid DatasetOptions: alpha T0 sample_rate = "
                   << alpha * period * sample_rate
                   << " < 1 leaves no training pair.");
  newton.validate();
}

BuiltinEnergies builtin_energies(const DatasetOptions& options) {
  BuiltinEnergies e;
  e.initial = {options.energy_min, options.energy_max};
  e.equilibrium = {options.equilibrium_energy_min, options.equilibrium_energy_max};
  return e;
}

std::unique_ptr<PhSystem> builtin_system(const OscillatorOptions& physics,
                                         const DatasetOptions& options) {
  return builtin_system(physics, builtin_energies(options));
}

}  // namespace phnn
