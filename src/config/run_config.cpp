// src/config/run_config.cpp — a run's canonical string, cell key and id: every
// field that affects its result, nothing else.
#include "phnn/config/run_config.h"

#include <cstdio>
#include <sstream>

#include "phnn/common/number_text.h"
#include "phnn/config/training_settings.h"

namespace phnn {

std::uint64_t fnv1a64(const std::string& text) {
  return fnv1a64_update(kFnv1a64Basis, text.data(), text.size());
}

std::uint64_t fnv1a64_update(std::uint64_t hash, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

std::string hex64(std::uint64_t value) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(value));
  return buf;
}

std::string RunConfig::system_name() const {
  return has_system_file() ? system_file : to_string(system);
}

namespace {

// A built-in system: only the parameters it uses, then the data options.
void builtin_system_key(const RunConfig& run, std::ostringstream& s) {
  const OscillatorOptions& physics = run.physics;
  const DatasetOptions& data = run.data;
  const SystemKind system = run.system;
  s << ";mass=" << exact_number(physics.mass) << ";stiffness=" << exact_number(physics.stiffness);
  if (system == SystemKind::kDuffing) {
    s << ";cubic_stiffness=" << exact_number(physics.cubic_stiffness);
  }
  if (system == SystemKind::kSelfSustained) {
    s << ";z=" << exact_number(physics.z_coefficients[0]) << ","
      << exact_number(physics.z_coefficients[1]) << "," << exact_number(physics.z_coefficients[2]);
  } else {
    s << ";damping=" << exact_number(physics.damping);
  }
  s << ";data_seed=" << data.data_seed << ";h_gen=" << exact_number(data.generation_step)
    << ";period=" << exact_number(data.period) << ";alpha=" << exact_number(data.alpha)
    << ";beta=" << exact_number(data.beta) << ";sample_rate=" << exact_number(data.sample_rate)
    << ";e0=" << exact_number(data.energy_min) << "," << exact_number(data.energy_max)
    << ";eeq=" << exact_number(data.equilibrium_energy_min) << ","
    << exact_number(data.equilibrium_energy_max) << ";n_traj=" << data.num_trajectories
    << ";splits=" << data.num_train_max << "," << data.num_validation << "," << data.num_inference
    << ";gen_tol=" << exact_number(data.newton.newton_tolerance);
  // Algorithm 1 only (harmonic, self-sustained); only away from the default.
  if (system != SystemKind::kDuffing && data.energy_sampling != EnergySampling::kAlgorithm1) {
    s << ";energy_sampling=" << to_string(data.energy_sampling);
  }
}

// A system file: its text (hash) holds the parameters, the energy intervals
// and the designs; the data options below are the ones its data use.
void file_system_key(const RunConfig& run, std::ostringstream& s) {
  const DatasetOptions& data = run.data;
  s << ";system_file=" << run.system_file_hash << ";data_seed=" << data.data_seed
    << ";h_gen=" << exact_number(data.generation_step) << ";period=" << exact_number(data.period)
    << ";sample_rate=" << exact_number(data.sample_rate) << ";n_traj=" << data.num_trajectories
    << ";splits=" << data.num_train_max << "," << data.num_validation << "," << data.num_inference
    << ";gen_tol=" << exact_number(data.newton.newton_tolerance);
  if (data.energy_sampling != EnergySampling::kAlgorithm1) {
    s << ";energy_sampling=" << to_string(data.energy_sampling);
  }
}

}  // namespace

std::string RunConfig::cell_key() const {
  std::ostringstream s;
  s << "system=" << system_name() << ";model=" << to_string(model)
    << ";integrator=" << to_string(integrator) << ";size=" << to_string(size)
    << ";n_train=" << n_train << ";regularizer=" << to_string(regularizer);
  if (has_system_file()) {
    file_system_key(*this, s);
  } else {
    builtin_system_key(*this, s);
  }
  // The training settings' parts (phnn/config/training_settings.h); settings
  // added later are printed only away from their defaults, so the identity
  // of every run made before they existed is unchanged.
  const TrainerOptions& t = training;
  s << training_key(t, model, integrator, regularizer);
  // Only when set, so the identity of every run without checkpoints is
  // unchanged from before they existed.
  if (!t.checkpoints.empty()) {
    s << ";checkpoints=";
    for (std::size_t i = 0; i < t.checkpoints.size(); ++i) s << (i ? "," : "") << t.checkpoints[i];
  }
  if (t.skip_inference) s << ";inference=skipped";
  return s.str();
}

std::string RunConfig::canonical() const {
  return cell_key() + ";seed=" + std::to_string(seed);
}

std::string RunConfig::id() const { return hex64(fnv1a64(canonical())); }

}  // namespace phnn
