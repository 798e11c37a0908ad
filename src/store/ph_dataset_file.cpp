// src/store/ph_dataset_file.cpp — data-set files and groups
// (include/phnn/store/ph_dataset_file.h): format_version 2 written and read;
// version 1 (built-in systems before 2026-11-28) read by dataset_file.cpp.
#include "phnn/store/ph_dataset_file.h"

#include <sstream>
#include <stdexcept>
#include <tuple>

#include "h5/h5file.h"
#include "phnn/common/check.h"
#include "phnn/config/run_config.h"
#include "store/dataset_file_io.h"

namespace phnn {
namespace {

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ",") + s;
  return out;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  if (s.empty()) return out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  if (!s.empty() && s.back() == ',') out.push_back("");
  return out;
}

// `count` rows of `width` from a dataset's values; a dataset of another size
// (a damaged or hand-made file) is refused before anything is indexed.
std::vector<VecX> unflatten(const std::vector<double>& flat, int width, std::size_t count,
                            const std::string& what = "a data-set file's dataset") {
  if (width < 0 || width > kMaxDimension || flat.size() != count * static_cast<std::size_t>(width)) {
    throw std::runtime_error(what + ": " + std::to_string(flat.size()) + " values where " +
                             std::to_string(count) + " rows of " + std::to_string(width) +
                             " are expected; the file is damaged or was not written by phnn: "
                             "write it again with phnn data or phnn import");
  }
  std::vector<VecX> out(count, VecX(width));
  for (std::size_t i = 0; i < count; ++i) {
    for (int j = 0; j < width; ++j) out[i](j) = flat[i * static_cast<std::size_t>(width) + static_cast<std::size_t>(j)];
  }
  return out;
}

// One [m, samples, width] array as [trajectory][sample] vectors (inference
// states and time-varying inputs).
std::vector<std::vector<VecX>> unflatten_trajectories(const std::vector<double>& flat, std::size_t m,
                                                      std::size_t samples, int width) {
  std::vector<std::vector<VecX>> out;
  const std::size_t per = samples * static_cast<std::size_t>(width);
  for (std::size_t i = 0; i < m; ++i) {
    const std::vector<double> part(flat.begin() + static_cast<long>(i * per),
                                   flat.begin() + static_cast<long>((i + 1) * per));
    out.push_back(unflatten(part, width, samples));
  }
  return out;
}

void write_pairs(h5::File& file, const std::string& group, const PhPairRows& p) {
  file.create_group(group);
  const std::uint64_t n = p.size();
  const auto nx = static_cast<std::uint64_t>(p.n_x), nu = static_cast<std::uint64_t>(p.n_u);
  file.write(group + "/x", {n, nx}, p.x);
  file.write(group + "/x_next", {n, nx}, p.x_next);
  if (nu > 0) file.write(group + "/u", {n, nu}, p.u);
  file.write(group + "/trajectory", {n}, p.trajectory);
  file.write(group + "/position", {n}, p.position);
  file.set_attribute(group, "step_s", p.step);
}

// Trajectory i's samples are rows [i samples, (i+1) samples) of states
// (and inputs, when they vary).
void write_inference(h5::File& file, const std::string& group, const PhInferenceRows& r) {
  file.create_group(group);
  const std::uint64_t m = r.size(), steps = r.samples;
  const auto nx = static_cast<std::uint64_t>(r.n_x), nu = static_cast<std::uint64_t>(r.n_u);
  PHNN_CHECK(r.states.size() >= m * steps * nx && r.u.size() >= m * nu &&
                 (r.inputs.empty() || r.inputs.size() >= m * steps * nu),
             "write_inference: " << r.states.size() << " state values for " << m << " x " << steps
                                 << " samples");
  file.write(group + "/states", {m, steps, nx}, r.states);
  if (nu > 0) file.write(group + "/u", {m, nu}, r.u);
  if (!r.inputs.empty()) file.write(group + "/inputs", {m, steps, nu}, r.inputs);
  file.write(group + "/trajectory", {m}, r.trajectory);
  if (!r.position.empty()) file.write(group + "/position", {m}, r.position);
  file.set_attribute(group, "step_s", r.step);
}

PhPairSet read_pairs(const h5::File& file, const std::string& group, int nx, int nu) {
  PhPairSet p;
  p.trajectory = file.read_ints(group + "/trajectory");
  const std::size_t n = p.trajectory.size();
  p.x = unflatten(file.read_doubles(group + "/x"), nx, n, group + "/x");
  p.x_next = unflatten(file.read_doubles(group + "/x_next"), nx, n, group + "/x_next");
  p.u = nu > 0 ? unflatten(file.read_doubles(group + "/u"), nu, n, group + "/u")
               : std::vector<VecX>(n, VecX(0));
  for (auto v : file.read_ints(group + "/position")) p.position.push_back(static_cast<int>(v));
  p.step = file.double_attribute(group, "step_s");
  return p;
}

void write_options(h5::File& file, const std::string& g, const DatasetOptions& o) {
  file.set_attribute(g, "data_seed", static_cast<std::int64_t>(o.data_seed));
  file.set_attribute(g, "generation_step_s", o.generation_step);
  file.set_attribute(g, "period_s", o.period);
  file.set_attribute(g, "alpha", o.alpha);
  file.set_attribute(g, "beta", o.beta);
  file.set_attribute(g, "sample_rate_Hz", o.sample_rate);
  file.set_attribute(g, "energy_sampling", to_string(o.energy_sampling));
  file.set_attribute(g, "num_trajectories", static_cast<std::int64_t>(o.num_trajectories));
  file.set_attribute(g, "num_train_max", static_cast<std::int64_t>(o.num_train_max));
  file.set_attribute(g, "num_validation", static_cast<std::int64_t>(o.num_validation));
  file.set_attribute(g, "num_inference", static_cast<std::int64_t>(o.num_inference));
  file.set_attribute(g, "newton_tolerance", o.newton.newton_tolerance);
}

DatasetOptions read_options(const h5::File& file, const std::string& g) {
  DatasetOptions o = internal::read_dataset_timing(file, g);
  o.energy_sampling = file.string_attribute(g, "energy_sampling") == "direct"
                          ? EnergySampling::kDirect
                          : EnergySampling::kAlgorithm1;
  return o;
}

}  // namespace

namespace internal {

DatasetOptions read_dataset_timing(const h5::File& file, const std::string& g) {
  DatasetOptions o;
  o.data_seed = static_cast<std::uint64_t>(file.int_attribute(g, "data_seed"));
  o.generation_step = file.double_attribute(g, "generation_step_s");
  o.period = file.double_attribute(g, "period_s");
  o.alpha = file.double_attribute(g, "alpha");
  o.beta = file.double_attribute(g, "beta");
  o.sample_rate = file.double_attribute(g, "sample_rate_Hz");
  o.num_trajectories = static_cast<int>(file.int_attribute(g, "num_trajectories"));
  o.num_train_max = static_cast<int>(file.int_attribute(g, "num_train_max"));
  o.num_validation = static_cast<int>(file.int_attribute(g, "num_validation"));
  o.num_inference = static_cast<int>(file.int_attribute(g, "num_inference"));
  o.newton.newton_tolerance = file.double_attribute(g, "newton_tolerance");
  return o;
}

}  // namespace internal

void describe_data_file(const PhSystemData& data, SystemFileText* text) {
  text->data_checksum = data_set_checksum(data);
  text->data_train_pairs = static_cast<int>(data.train.size());
  text->data_inference = static_cast<int>(data.inference.size());
  text->data_inference_points = 0;
  for (const auto& states : data.inference.states) {
    text->data_inference_points = std::max(text->data_inference_points, static_cast<int>(states.size()));
  }
}

std::string data_set_checksum(const PhSystemData& data) {
  // The bytes hashed, field by field: sizes as uint64, doubles as stored;
  // hashed as they come (the hash of them joined, without joining them).
  std::uint64_t hash = kFnv1a64Basis;
  const auto raw = [&hash](const void* p, std::size_t n) { hash = fnv1a64_update(hash, p, n); };
  const auto text = [&](const std::string& s) {
    const std::uint64_t n = s.size();
    raw(&n, sizeof n);
    raw(s.data(), s.size());
  };
  const auto vec = [&](const VecX& v) {
    const std::uint64_t n = static_cast<std::uint64_t>(v.size());
    raw(&n, sizeof n);
    raw(v.data(), sizeof(double) * static_cast<std::size_t>(v.size()));
  };
  text(data.system_text);
  for (const auto& s : data.state_names) text(s);
  for (const auto& s : data.input_names) text(s);
  for (const PhPairSet* p : {&data.train, &data.validation}) {
    raw(&p->step, sizeof p->step);
    for (std::size_t i = 0; i < p->size(); ++i) {
      vec(p->x[i]);
      vec(p->x_next[i]);
      vec(p->u[i]);
    }
  }
  raw(&data.inference.step, sizeof data.inference.step);
  for (std::size_t i = 0; i < data.inference.size(); ++i) {
    vec(data.inference.u[i]);
    for (const VecX& x : data.inference.states[i]) vec(x);
  }
  // Time-varying inputs (absent from the data sets before them: their
  // checksums are unchanged).
  for (const auto& traj : data.inference.inputs) {
    for (const VecX& u : traj) vec(u);
  }
  return hex64(hash);
}

namespace internal {

void write_ph_system_data(h5::File& file, const std::string& group, const PhSystemData& data,
                          const SplitRows& rows) {
  const std::string g = group;
  const std::string p = group == "/" ? "" : group;  // prefix of the sub-groups
  const int nx = static_cast<int>(data.state_names.size());
  const int nu = static_cast<int>(data.input_names.size());
  if (g != "/") file.create_group(g);
  file.set_attribute(g, "format", std::string("phnn-dataset"));
  file.set_attribute(g, "format_version", std::int64_t{2});
  file.set_attribute(g, "system", data.system_name);
  file.set_attribute(g, "system_file", data.system_text);
  file.set_attribute(g, "n_x", static_cast<std::int64_t>(nx));
  file.set_attribute(g, "n_w", static_cast<std::int64_t>(data.n_w));
  file.set_attribute(g, "n_u", static_cast<std::int64_t>(nu));
  file.set_attribute(g, "state_names", join(data.state_names));
  file.set_attribute(g, "state_units", join(data.state_units));
  file.set_attribute(g, "input_names", join(data.input_names));
  file.set_attribute(g, "time_units", std::string("s"));
  if (!data.noise.empty()) file.set_attribute(g, "noise", data.noise);
  if (!data.split.empty()) file.set_attribute(g, "split", data.split);
  write_options(file, g, data.options);
  // Splits given as PhPairSet / PhInferenceSet are written through a flat
  // copy of one at a time; rows as they are (if / else: `cond ? *rows :
  // copy` would copy the rows too).
  for (const auto& [name, given, set] : {std::tuple{"/train", rows.train, &data.train},
                                         std::tuple{"/validation", rows.validation, &data.validation}}) {
    if (given) {
      write_pairs(file, p + name, *given);
    } else {
      write_pairs(file, p + name, PhPairRows::of(*set, nx, nu));
    }
  }
  if (rows.inference) {
    write_inference(file, p + "/inference", *rows.inference);
  } else {
    write_inference(file, p + "/inference", PhInferenceRows::of(data.inference, nx, nu));
  }
}

PhSystemData read_ph_system_data(const h5::File& file, const std::string& group) {
  if (!file.has_attribute(group, "format_version") || file.int_attribute(group, "format_version") == 1) {
    return read_version1_data(file, group);
  }
  if (file.int_attribute(group, "format_version") != 2) {
    throw std::runtime_error(file.path() + ": " + group + " is a data set of format_version " +
                             std::to_string(file.int_attribute(group, "format_version")) +
                             "; this phnn reads versions 1 and 2: read it with a newer phnn");
  }
  const std::string g = group;
  const std::string p = group == "/" ? "" : group;
  PhSystemData d;
  d.system_name = file.string_attribute(g, "system");
  d.system_text = file.string_attribute(g, "system_file");
  d.state_names = split(file.string_attribute(g, "state_names"));
  d.state_units = split(file.string_attribute(g, "state_units"));
  d.input_names = split(file.string_attribute(g, "input_names"));
  d.n_w = static_cast<int>(file.int_attribute(g, "n_w"));
  if (file.has_attribute(g, "noise")) d.noise = file.string_attribute(g, "noise");
  if (file.has_attribute(g, "split")) d.split = file.string_attribute(g, "split");
  const int nx = static_cast<int>(d.state_names.size());
  const int nu = static_cast<int>(d.input_names.size());
  if (nx < 1 || d.n_w < 0 || nx + d.n_w + nu > kMaxDimension) {
    throw std::runtime_error(g + ": " + std::to_string(nx) + " states, " + std::to_string(d.n_w) +
                             " ports and " + std::to_string(nu) + " inputs: not a data set phnn "
                             "can read (at least 1 state, at most " + std::to_string(kMaxDimension) +
                             " in all); the file is damaged or was not written by phnn");
  }
  d.options = read_options(file, g);
  d.train = read_pairs(file, p + "/train", nx, nu);
  d.validation = read_pairs(file, p + "/validation", nx, nu);
  d.inference.trajectory = file.read_ints(p + "/inference/trajectory");
  d.inference.step = file.double_attribute(p + "/inference", "step_s");
  const std::size_t m = d.inference.trajectory.size();
  if (file.exists(p + "/inference/position")) {
    d.inference.position = file.read_ints(p + "/inference/position");
    if (d.inference.position.size() != m) {
      throw std::runtime_error(p + "/inference/position: " + std::to_string(d.inference.position.size()) +
                               " start samples for " + std::to_string(m) + " windows; the file is "
                               "damaged or was not written by phnn");
    }
  }
  const auto dims = file.dims(p + "/inference/states");
  const auto flat = file.read_doubles(p + "/inference/states");
  const std::size_t steps = dims.size() == 3 ? dims[1] : 0;
  if (flat.size() != m * steps * static_cast<std::size_t>(nx)) {
    throw std::runtime_error(p + "/inference/states: " + std::to_string(flat.size()) +
                             " values for " + std::to_string(m) + " trajectories of " +
                             std::to_string(steps) + " samples of " + std::to_string(nx) +
                             " states; the file is damaged or was not written by phnn");
  }
  d.inference.states = unflatten_trajectories(flat, m, steps, nx);
  d.inference.u = nu > 0 ? unflatten(file.read_doubles(p + "/inference/u"), nu, m, p + "/inference/u")
                         : std::vector<VecX>(m, VecX(0));
  if (nu > 0 && file.exists(p + "/inference/inputs")) {
    const auto in_dims = file.dims(p + "/inference/inputs");
    if (in_dims.size() != 3 || in_dims[0] != m || in_dims[1] != steps ||
        in_dims[2] != static_cast<std::uint64_t>(nu)) {
      throw std::runtime_error(p + "/inference/inputs: expected [" + std::to_string(m) + ", " +
                               std::to_string(steps) + ", " + std::to_string(nu) +
                               "] (trajectories, samples, inputs); rewrite the file with phnn data or phnn import");
    }
    d.inference.inputs = unflatten_trajectories(file.read_doubles(p + "/inference/inputs"), m, steps, nu);
  }
  return d;
}

}  // namespace internal

void write_ph_dataset_file(const std::string& path, const PhSystemData& data) {
  h5::File file = h5::File::create(path);
  internal::write_ph_system_data(file, "/", data);
}

void write_ph_dataset_file(const std::string& path, const PhSystemData& data, const PhPairRows& train,
                           const PhPairRows& validation, const PhInferenceRows& inference) {
  PHNN_REQUIRE(data.train.size() == 0 && data.validation.size() == 0 && data.inference.size() == 0,
               "write_ph_dataset_file: splits both in the data set (" << data.train.size() << ", "
               << data.validation.size() << ", " << data.inference.size() << ") and given as rows");
  h5::File file = h5::File::create(path);
  internal::write_ph_system_data(file, "/", data, {&train, &validation, &inference});
}

PhSystemData read_ph_dataset_file(const std::string& path) {
  const h5::File file = h5::File::open(path, h5::Access::kReadOnly);
  if (!file.has_attribute("/", "format") || file.string_attribute("/", "format") != "phnn-dataset") {
    throw std::runtime_error(path + ": not a phnn data set (no format = \"phnn-dataset\" "
                                    "attribute); write one with `phnn data`");
  }
  return internal::read_ph_system_data(file, "/");
}

}  // namespace phnn
