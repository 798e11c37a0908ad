// src/store/dataset_file.cpp — format_version 1 data sets (the built-in
// systems' 2-state layout, written before 2026-11-28 by `phnn data` and in
// results files' /data), read into the one data-set form: the text is the
// built-in system's with the physics and energies the file states, inputs
// of one component, states q, p.
#include "phnn/store/dataset_file.h"

#include <sys/stat.h>

#include <stdexcept>

#include "store/dataset_file_io.h"

namespace phnn {
namespace internal {
namespace {

std::string join(const std::string& group, const std::string& name) {
  return group == "/" ? "/" + name : group + "/" + name;
}

// Rows of `width` doubles as vectors.
std::vector<VecX> rows(const std::vector<double>& v, int width) {
  std::vector<VecX> out(v.size() / static_cast<std::size_t>(width));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = Eigen::Map<const Eigen::VectorXd>(v.data() + i * static_cast<std::size_t>(width), width);
  }
  return out;
}

PhPairSet read_pairs(const h5::File& file, const std::string& group) {
  PhPairSet pairs;
  pairs.x = rows(file.read_doubles(group + "/x"), 2);
  pairs.x_next = rows(file.read_doubles(group + "/x_next"), 2);
  pairs.u = rows(file.read_doubles(group + "/u"), 1);
  pairs.trajectory = file.read_ints(group + "/trajectory");
  for (auto p : file.read_ints(group + "/position")) pairs.position.push_back(static_cast<int>(p));
  pairs.step = file.double_attribute(group, "step_s");
  if (pairs.x.size() != pairs.trajectory.size() || pairs.x_next.size() != pairs.x.size() ||
      pairs.u.size() != pairs.x.size() || pairs.position.size() != pairs.x.size()) {
    throw std::runtime_error(file.path() + ": " + group + ": x, x_next, u, trajectory and position "
                             "hold different counts; the file is damaged");
  }
  return pairs;
}

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

OscillatorOptions read_physics(const h5::File& file, const std::string& group) {
  OscillatorOptions s;
  s.kind = parse_system(file.string_attribute(group, "system"));
  s.mass = file.double_attribute(group, "mass_kg");
  s.stiffness = file.double_attribute(group, "stiffness_N_per_m");
  s.cubic_stiffness = file.double_attribute(group, "cubic_stiffness_N_per_m3");
  s.damping = file.double_attribute(group, "damping_N_s_per_m");
  s.z_coefficients = {file.double_attribute(group, "z1"), file.double_attribute(group, "z2"),
                      file.double_attribute(group, "z3")};
  return s;
}

// Version 1 also stores the energy intervals (version 2 keeps them in the
// system file's text).
DatasetOptions read_options(const h5::File& file, const std::string& group) {
  DatasetOptions o = read_dataset_timing(file, group);
  o.energy_min = file.double_attribute(group, "energy_min_J");
  o.energy_max = file.double_attribute(group, "energy_max_J");
  o.energy_sampling = read_energy_sampling(file, group);
  o.equilibrium_energy_min = file.double_attribute(group, "equilibrium_energy_min_J");
  o.equilibrium_energy_max = file.double_attribute(group, "equilibrium_energy_max_J");
  return o;
}

}  // namespace

PhSystemData read_version1_data(const h5::File& file, const std::string& group) {
  const OscillatorOptions physics = read_physics(file, group);
  PhSystemData data;
  data.system_name = to_string(physics.kind);
  data.state_names = {"q", "p"};
  data.state_units = {"m", "kg m/s"};
  data.input_names = {"u"};
  data.n_w = 1;
  data.options = read_options(file, group);
  data.system_text = builtin_system_text(physics, builtin_energies(data.options));
  data.train = read_pairs(file, join(group, "train"));
  data.validation = read_pairs(file, join(group, "validation"));
  const std::string inf = join(group, "inference");
  data.inference.u = rows(file.read_doubles(inf + "/u"), 1);
  data.inference.trajectory = file.read_ints(inf + "/trajectory");
  data.inference.step = file.double_attribute(inf, "step_s");
  const auto dims = file.dims(inf + "/states");
  const auto flat = file.read_doubles(inf + "/states");
  if (dims.size() != 3 || dims[2] != 2 || dims[0] != data.inference.u.size() ||
      flat.size() != dims[0] * dims[1] * 2) {
    throw std::runtime_error(file.path() + ": " + inf + "/states is not [trajectories, samples, 2] "
                             "for the trajectories of " + inf + "/u; the file is damaged");
  }
  for (std::uint64_t i = 0; i < dims[0]; ++i) {
    const std::vector<double> one(flat.begin() + static_cast<long>(i * dims[1] * 2),
                                  flat.begin() + static_cast<long>((i + 1) * dims[1] * 2));
    data.inference.states.push_back(rows(one, 2));
  }
  return data;
}

}  // namespace internal

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

}  // namespace phnn
