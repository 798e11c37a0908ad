// src/store/dataset_file.cpp — format_version 1 data-set files (the built-in
// systems' SystemData) and their groups inside results files.
#include "phnn/store/dataset_file.h"

#include <sys/stat.h>

#include <stdexcept>

#include "store/dataset_file_io.h"

namespace phnn {

SystemData make_system_data(const OscillatorOptions& system,
                            const DatasetOptions& options, int num_train) {
  options.validate();
  const Oscillator oscillator(system);
  SystemData data;
  data.system = system;
  data.options = options;
  data.train = training_pairs(oscillator, options, num_train);
  data.validation = validation_pairs(oscillator, options);
  data.inference = inference_set(oscillator, options);
  return data;
}

namespace internal {
namespace {

std::string join(const std::string& group, const std::string& name) {
  return group == "/" ? "/" + name : group + "/" + name;
}

std::vector<double> flatten(const std::vector<Vec2>& v) {
  std::vector<double> out;
  out.reserve(2 * v.size());
  for (const Vec2& x : v) {
    out.push_back(x(0));
    out.push_back(x(1));
  }
  return out;
}

std::vector<Vec2> unflatten(const std::vector<double>& v) {
  std::vector<Vec2> out(v.size() / 2);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec2(v[2 * i], v[2 * i + 1]);
  return out;
}

void write_pairs(h5::File& file, const std::string& group, const PairSet& pairs) {
  file.create_group(group);
  const std::uint64_t n = pairs.size();
  file.write(group + "/x", {n, 2}, flatten(pairs.x));
  file.write(group + "/x_next", {n, 2}, flatten(pairs.x_next));
  file.write(group + "/u", {n}, pairs.u);
  file.write(group + "/trajectory", {n}, pairs.trajectory);
  std::vector<std::int64_t> pos(pairs.position.begin(), pairs.position.end());
  file.write(group + "/position", {n}, pos);
  file.set_attribute(group, "step_s", pairs.step);
  file.set_attribute(group + "/x", "units", std::string("q [m], p [kg m/s]"));
  file.set_attribute(group + "/x_next", "units", std::string("q [m], p [kg m/s]"));
  file.set_attribute(group + "/u", "units", std::string("N (harmonic, duffing); m/s (self-sustained)"));
}

PairSet read_pairs(const h5::File& file, const std::string& group) {
  PairSet pairs;
  pairs.x = unflatten(file.read_doubles(group + "/x"));
  pairs.x_next = unflatten(file.read_doubles(group + "/x_next"));
  pairs.u = file.read_doubles(group + "/u");
  pairs.trajectory = file.read_ints(group + "/trajectory");
  for (auto p : file.read_ints(group + "/position")) pairs.position.push_back(static_cast<int>(p));
  pairs.step = file.double_attribute(group, "step_s");
  return pairs;
}

}  // namespace

void write_system_data(h5::File& file, const std::string& group,
                       const SystemData& data) {
  file.create_group(group);
  const OscillatorOptions& s = data.system;
  const DatasetOptions& o = data.options;
  file.set_attribute(group, "format", std::string("phnn-dataset"));
  file.set_attribute(group, "format_version", std::int64_t{1});
  file.set_attribute(group, "system", to_string(s.kind));
  file.set_attribute(group, "mass_kg", s.mass);
  file.set_attribute(group, "stiffness_N_per_m", s.stiffness);
  file.set_attribute(group, "cubic_stiffness_N_per_m3", s.cubic_stiffness);
  file.set_attribute(group, "damping_N_s_per_m", s.damping);
  file.set_attribute(group, "z_coefficients",
                     "z(w) = " + std::to_string(s.z_coefficients[0]) + " w + " +
                         std::to_string(s.z_coefficients[1]) + " w^2 + " +
                         std::to_string(s.z_coefficients[2]) + " w^3");
  file.set_attribute(group, "z1", s.z_coefficients[0]);
  file.set_attribute(group, "z2", s.z_coefficients[1]);
  file.set_attribute(group, "z3", s.z_coefficients[2]);
  file.set_attribute(group, "data_seed", static_cast<std::int64_t>(o.data_seed));
  file.set_attribute(group, "generation_step_s", o.generation_step);
  file.set_attribute(group, "period_s", o.period);
  file.set_attribute(group, "alpha", o.alpha);
  file.set_attribute(group, "beta", o.beta);
  file.set_attribute(group, "sample_rate_Hz", o.sample_rate);
  file.set_attribute(group, "energy_min_J", o.energy_min);
  file.set_attribute(group, "energy_max_J", o.energy_max);
  file.set_attribute(group, "energy_sampling", to_string(o.energy_sampling));
  file.set_attribute(group, "equilibrium_energy_min_J", o.equilibrium_energy_min);
  file.set_attribute(group, "equilibrium_energy_max_J", o.equilibrium_energy_max);
  file.set_attribute(group, "num_trajectories", static_cast<std::int64_t>(o.num_trajectories));
  file.set_attribute(group, "num_train_max", static_cast<std::int64_t>(o.num_train_max));
  file.set_attribute(group, "num_validation", static_cast<std::int64_t>(o.num_validation));
  file.set_attribute(group, "num_inference", static_cast<std::int64_t>(o.num_inference));
  file.set_attribute(group, "newton_tolerance", o.newton.newton_tolerance);
  file.set_attribute(group, "state_units", std::string("q [m], p [kg m/s]"));
  file.set_attribute(group, "time_units", std::string("s"));
  write_pairs(file, join(group, "train"), data.train);
  write_pairs(file, join(group, "validation"), data.validation);
  const std::string inf = join(group, "inference");
  file.create_group(inf);
  const std::uint64_t n = data.inference.size();
  const std::uint64_t steps = n ? data.inference.states[0].size() : 0;
  std::vector<double> states;
  states.reserve(n * steps * 2);
  for (const auto& traj : data.inference.states) {
    for (const Vec2& x : traj) {
      states.push_back(x(0));
      states.push_back(x(1));
    }
  }
  file.write(inf + "/states", {n, steps, 2}, states);
  file.write(inf + "/u", {n}, data.inference.u);
  file.write(inf + "/trajectory", {n}, data.inference.trajectory);
  file.set_attribute(inf, "step_s", data.inference.step);
  file.set_attribute(inf + "/states", "units", std::string("q [m], p [kg m/s]"));
}

namespace {

// Files written before the attribute existed used Algorithm 1 as written.
EnergySampling read_energy_sampling(const h5::File& file, const std::string& group) {
  if (!file.has_attribute(group, "energy_sampling")) return EnergySampling::kAlgorithm1;
  const std::string name = file.string_attribute(group, "energy_sampling");
  for (EnergySampling s : all_energy_samplings()) {
    if (to_string(s) == name) return s;
  }
  throw std::runtime_error(file.path() + ": " + group + " has energy_sampling = \"" + name +
                           "\"; expected algorithm1 or direct");
}

}  // namespace

SystemData read_system_data(const h5::File& file, const std::string& group) {
  if (!file.has_attribute(group, "format") ||
      file.string_attribute(group, "format") != "phnn-dataset") {
    throw std::runtime_error(file.path() + ": " + group +
                             " is not a phnn data set (no format = "
                             "\"phnn-dataset\" attribute); write one with "
                             "`phnn data`");
  }
  if (file.has_attribute(group, "format_version") &&
      file.int_attribute(group, "format_version") != 1) {
    throw std::runtime_error(
        file.path() + ": " + group + " is a data set of the system file \"" +
        file.string_attribute(group, "system") +
        "\" (format_version " + std::to_string(file.int_attribute(group, "format_version")) +
        "); read it with read_ph_dataset_file (this reader takes built-in systems' data sets)");
  }
  SystemData data;
  OscillatorOptions& s = data.system;
  s.kind = parse_system(file.string_attribute(group, "system"));
  s.mass = file.double_attribute(group, "mass_kg");
  s.stiffness = file.double_attribute(group, "stiffness_N_per_m");
  s.cubic_stiffness = file.double_attribute(group, "cubic_stiffness_N_per_m3");
  s.damping = file.double_attribute(group, "damping_N_s_per_m");
  s.z_coefficients = {file.double_attribute(group, "z1"), file.double_attribute(group, "z2"),
                      file.double_attribute(group, "z3")};
  DatasetOptions& o = data.options;
  o.data_seed = static_cast<std::uint64_t>(file.int_attribute(group, "data_seed"));
  o.generation_step = file.double_attribute(group, "generation_step_s");
  o.period = file.double_attribute(group, "period_s");
  o.alpha = file.double_attribute(group, "alpha");
  o.beta = file.double_attribute(group, "beta");
  o.sample_rate = file.double_attribute(group, "sample_rate_Hz");
  o.energy_min = file.double_attribute(group, "energy_min_J");
  o.energy_max = file.double_attribute(group, "energy_max_J");
  o.energy_sampling = read_energy_sampling(file, group);
  o.equilibrium_energy_min = file.double_attribute(group, "equilibrium_energy_min_J");
  o.equilibrium_energy_max = file.double_attribute(group, "equilibrium_energy_max_J");
  o.num_trajectories = static_cast<int>(file.int_attribute(group, "num_trajectories"));
  o.num_train_max = static_cast<int>(file.int_attribute(group, "num_train_max"));
  o.num_validation = static_cast<int>(file.int_attribute(group, "num_validation"));
  o.num_inference = static_cast<int>(file.int_attribute(group, "num_inference"));
  o.newton.newton_tolerance = file.double_attribute(group, "newton_tolerance");
  data.train = read_pairs(file, join(group, "train"));
  data.validation = read_pairs(file, join(group, "validation"));
  const std::string inf = join(group, "inference");
  data.inference.u = file.read_doubles(inf + "/u");
  data.inference.trajectory = file.read_ints(inf + "/trajectory");
  data.inference.step = file.double_attribute(inf, "step_s");
  const auto dims = file.dims(inf + "/states");
  const auto flat = file.read_doubles(inf + "/states");
  data.inference.states.resize(dims[0]);
  for (std::uint64_t i = 0; i < dims[0]; ++i) {
    auto& traj = data.inference.states[i];
    traj.resize(dims[1]);
    for (std::uint64_t n = 0; n < dims[1]; ++n) {
      traj[n] = Vec2(flat[(i * dims[1] + n) * 2], flat[(i * dims[1] + n) * 2 + 1]);
    }
  }
  return data;
}

}  // namespace internal

void write_dataset_file(const std::string& path, const SystemData& data) {
  h5::File file = h5::File::create(path);
  internal::write_system_data(file, "/", data);
}

bool is_dataset_file(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || !h5::File::is_hdf5(path)) {
    return false;
  }
  try {
    const h5::File file = h5::File::open(path, h5::Access::kReadOnly);
    return file.has_attribute("/", "format") &&
           file.string_attribute("/", "format") == "phnn-dataset";
  } catch (const std::exception&) {
    return false;
  }
}

SystemData read_dataset_file(const std::string& path) {
  const h5::File file = h5::File::open(path, h5::Access::kReadOnly);
  return internal::read_system_data(file, "/");
}

}  // namespace phnn
