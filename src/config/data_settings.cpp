// src/config/data_settings.cpp — the tables of [data] and [physics.<system>]
// settings (phnn/config/data_settings.h) and the canonical-key parts they
// write. Touches no file.
#include "phnn/config/data_settings.h"

#include <cstdint>

#include "config/key_parts.h"
#include "phnn/common/number_text.h"

namespace phnn {
namespace {

using Kind = DataSetting::Kind;
using InKey = DataSetting::InKey;
using D = DatasetOptions;

template <double D::*F>
DataSetting real(const char* key, const char* column, const char* canonical, InKey in_key,
                 const char* doc) {
  DataSetting s{key, column, Kind::kReal, canonical, in_key, doc};
  s.get_real = [](const D& d) { return d.*F; };
  s.set_real = [](D* d, double v) { d->*F = v; };
  return s;
}

template <int D::*F>
DataSetting integer(const char* key, const char* canonical, const char* doc) {
  DataSetting s{key, key, Kind::kInteger, canonical, InKey::kAlways, doc};
  s.get_integer = [](const D& d) { return static_cast<std::int64_t>(d.*F); };
  s.set_integer = [](D* d, std::int64_t v) { d->*F = static_cast<int>(v); };
  return s;
}

DataSetting seed() {
  DataSetting s{
      "seed",         "data_seed",
      Kind::kInteger, "data_seed",
      InKey::kAlways, "data seed: keys every random stream with (seed, system, trajectory)"};
  s.get_integer = [](const D& d) { return static_cast<std::int64_t>(d.data_seed); };
  s.set_integer = [](D* d, std::int64_t v) { d->data_seed = static_cast<std::uint64_t>(v); };
  s.get_text = [](const D& d) { return std::to_string(d.data_seed); };
  s.min_integer = 0;
  s.max_integer = INT64_MAX;
  return s;
}

DataSetting generation_tolerance() {
  DataSetting s{"newton_tolerance", "generation_newton_tolerance",
                Kind::kReal,        "gen_tol",
                InKey::kAlways,     "Newton tolerance of the DG data generator"};
  s.get_real = [](const D& d) { return d.newton.newton_tolerance; };
  s.set_real = [](D* d, double v) { d->newton.newton_tolerance = v; };
  return s;
}

DataSetting energy_sampling() {
  DataSetting s{"energy_sampling",
                "energy_sampling",
                Kind::kChoice,
                "energy_sampling",
                InKey::kEnergySampling,
                "initial energy of harmonic and self-sustained trajectories from r ~ U(I_E0): "
                "`algorithm1` = E0 = √r (the paper's Algorithm 1 as printed, H(x0) ∈ [√E_min, "
                "√E_max]); `direct` = E0 = r (H(x0) ∈ I_E0). Duffing (Algorithm 2) ignores it; a "
                "file whose studies are all Duffing may not set `direct` (docs/METHOD.md §2)"};
  s.choices = [] { return kEnergySamplingNames.names(); };
  s.get_choice = [](const D& d) { return static_cast<int>(d.energy_sampling); };
  s.set_choice = [](D* d, int index) {
    d->energy_sampling = kEnergySamplingNames.all().at(static_cast<std::size_t>(index));
  };
  return s;
}

bool in_key(const DataSetting& s, const D& d, bool builtin, SystemKind system) {
  switch (s.in_key) {
    case InKey::kAlways:
      return true;
    case InKey::kBuiltin:
      return builtin;
    case InKey::kEnergySampling:
      return s.text(d) != s.text(D()) && !(builtin && system == SystemKind::kDuffing);
  }
  return false;
}

}  // namespace

// In canonical-key order (RunConfig::cell_key()): changing it, a canonical
// spelling or an InKey changes the id of every run.
const std::vector<DataSetting>& data_settings() {
  static const std::vector<DataSetting> table = {
      seed(),
      real<&D::generation_step>("generation_step", "generation_step", "h_gen", InKey::kAlways,
                                "h_gen of the DG generator [s] (default 1/400); 1 / (h_gen · "
                                "sample_rate) must be an integer"),
      real<&D::period>("period", "period", "period", InKey::kAlways, "nominal period T0 [s]"),
      real<&D::alpha>("alpha", "alpha", "alpha", InKey::kBuiltin,
                      "training pairs have t_{n+1} ≤ α T0"),
      real<&D::beta>("beta", "beta", "beta", InKey::kBuiltin,
                     "trajectory and inference duration D = β T0"),
      real<&D::sample_rate>("sample_rate", "sample_rate", "sample_rate", InKey::kAlways,
                            "sr_train = sr_infer [Hz]"),
      real<&D::energy_min>("energy_min", "energy_min", "e0", InKey::kBuiltin,
                           "I_E0 of the initial conditions [J]: lower end"),
      real<&D::energy_max>("energy_max", "energy_max", "e0", InKey::kBuiltin,
                           "I_E0 of the initial conditions [J]: upper end"),
      real<&D::equilibrium_energy_min>("equilibrium_energy_min", "equilibrium_energy_min", "eeq",
                                       InKey::kBuiltin,
                                       "I_Eeq of the controlled equilibria [J]: lower end"),
      real<&D::equilibrium_energy_max>("equilibrium_energy_max", "equilibrium_energy_max", "eeq",
                                       InKey::kBuiltin,
                                       "I_Eeq of the controlled equilibria [J]: upper end"),
      integer<&D::num_trajectories>("num_trajectories", "n_traj",
                                    "addressable trajectories N_traj"),
      integer<&D::num_train_max>("num_train_max", "splits",
                                 "train split [0, num_train_max); every n_train must be ≤ it"),
      integer<&D::num_validation>("num_validation", "splits",
                                  "validation split, after the train split"),
      integer<&D::num_inference>("num_inference", "splits",
                                 "inference split, after the validation split"),
      generation_tolerance(),
      energy_sampling(),
  };
  return table;
}

std::string DataSetting::text(const DatasetOptions& d) const {
  if (get_text) return get_text(d);
  switch (kind) {
    case Kind::kReal:
      return exact_number(get_real(d));
    case Kind::kInteger:
      return std::to_string(get_integer(d));
    case Kind::kChoice:
      return choices().at(static_cast<std::size_t>(get_choice(d)));
  }
  return "";
}

std::string data_key(const DatasetOptions& d, bool builtin, SystemKind system) {
  return internal::key_parts(
      data_settings(), [&](const DataSetting& s) { return in_key(s, d, builtin, system); },
      [&](const DataSetting& s) { return s.text(d); });
}

const std::vector<PhysicsSetting>& physics_settings() {
  using O = OscillatorOptions;
  using S = SystemKind;
  static const std::vector<PhysicsSetting> table = {
      {"mass",
       "mass",
       {"mass"},
       {S::kHarmonic, S::kDuffing, S::kSelfSustained},
       "m [kg]",
       [](const O& p) { return std::vector<double>{p.mass}; },
       [](O* p, const std::vector<double>& v) { p->mass = v.at(0); }},
      {"stiffness",
       "stiffness",
       {"stiffness"},
       {S::kHarmonic, S::kDuffing, S::kSelfSustained},
       "k = k1 [N/m] (default 1/0.16: f0 = 1 Hz)",
       [](const O& p) { return std::vector<double>{p.stiffness}; },
       [](O* p, const std::vector<double>& v) { p->stiffness = v.at(0); }},
      {"cubic_stiffness",
       "cubic_stiffness",
       {"cubic_stiffness"},
       {S::kDuffing},
       "k3 [N/m³] (default 100 k1)",
       [](const O& p) { return std::vector<double>{p.cubic_stiffness}; },
       [](O* p, const std::vector<double>& v) { p->cubic_stiffness = v.at(0); }},
      {"z_coefficients",
       "z",
       {"z1", "z2", "z3"},
       {S::kSelfSustained},
       "z(w) = z1 w + z2 w² + z3 w³ (3 numbers)",
       [](const O& p) {
         return std::vector<double>(p.z_coefficients.begin(), p.z_coefficients.end());
       },
       [](O* p, const std::vector<double>& v) {
         p->z_coefficients = {v.at(0), v.at(1), v.at(2)};
       }},
      {"damping",
       "damping",
       {"damping"},
       {S::kHarmonic, S::kDuffing},
       "c of z(w) = c w [N s/m] (default m ln(100)/5)",
       [](const O& p) { return std::vector<double>{p.damping}; },
       [](O* p, const std::vector<double>& v) { p->damping = v.at(0); }},
  };
  return table;
}

bool PhysicsSetting::applies_to(SystemKind system) const {
  for (SystemKind s : systems) {
    if (s == system) return true;
  }
  return false;
}

std::string physics_key(const OscillatorOptions& p, SystemKind system) {
  std::string out;
  for (const PhysicsSetting& s : physics_settings()) {
    if (!s.applies_to(system)) continue;
    out += ";" + std::string(s.canonical) + "=";
    const std::vector<double> values = s.get(p);
    for (std::size_t i = 0; i < values.size(); ++i) out += (i ? "," : "") + exact_number(values[i]);
  }
  return out;
}

std::string data_settings_markdown() {
  const DatasetOptions defaults;
  std::string out = "| key | default | values | per-run column | what |\n|---|---|---|---|---|\n";
  for (const DataSetting& s : data_settings()) {
    std::string values, value = "`" + s.text(defaults) + "`";
    switch (s.kind) {
      case Kind::kReal:
        values = "number";
        value = "`" + roundtrip_number(s.get_real(defaults)) + "`";
        break;
      case Kind::kInteger:
        values = "integer >= " + std::to_string(s.min_integer);
        break;
      case Kind::kChoice:
        for (const std::string& n : s.choices())
          values += (values.empty() ? "" : ", ") + ("`\"" + n + "\"`");
        value = "`\"" + s.text(defaults) + "\"`";
        break;
    }
    out += "| `" + std::string(s.key) + "` | " + value + " | " + values + " | `" + s.column +
           "` | " + s.doc + " |\n";
  }
  return out;
}

std::string physics_settings_markdown() {
  std::string out = "| key | default | systems | per-run columns | what |\n|---|---|---|---|---|\n";
  for (const PhysicsSetting& s : physics_settings()) {
    const std::vector<double> values = s.get(OscillatorOptions::defaults(s.systems.front()));
    std::string value, systems, columns;
    for (std::size_t i = 0; i < values.size(); ++i)
      value += (i ? ", " : "") + roundtrip_number(values[i]);
    if (values.size() > 1) value = "[" + value + "]";
    for (SystemKind k : s.systems) systems += (systems.empty() ? "" : ", ") + to_string(k);
    for (const char* c : s.columns)
      columns += (columns.empty() ? "`" : ", `") + std::string(c) + "`";
    out += "| `" + std::string(s.key) + "` | `" + value + "` | " + systems + " | " + columns +
           " | " + s.doc + " |\n";
  }
  return out;
}

}  // namespace phnn
