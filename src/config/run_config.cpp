// src/config/run_config.cpp — a run's canonical string, cell key and id: every
// field that affects its result, nothing else.
#include "phnn/config/run_config.h"

#include <cstdio>
#include <sstream>

#include "phnn/config/data_settings.h"
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

// A built-in system: only the parameters it uses, then the data options
// (phnn/config/data_settings.h).
void builtin_system_key(const RunConfig& run, std::ostringstream& s) {
  s << physics_key(run.physics, run.system) << data_key(run.data, /*builtin=*/true, run.system);
}

// A system file: its text (hash) holds the parameters, the energy intervals
// and the designs; the data options below are the ones its data use.
void file_system_key(const RunConfig& run, std::ostringstream& s) {
  s << ";system_file=" << run.system_file_hash << data_key(run.data, /*builtin=*/false, run.system);
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
