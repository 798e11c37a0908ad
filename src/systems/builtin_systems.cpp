// src/systems/builtin_systems.cpp — the paper's three oscillators from their
// shipped system files (builtin_systems.h): the alias table, the check that a
// shipped file still defines the paper's system, and the rewriting of its
// parameter and energy lines.
#include "phnn/systems/builtin_systems.h"

#include <cstring>
#include <sstream>

#include "phnn/common/number_text.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace {

const std::vector<BuiltinAlias>& aliases_of(SystemKind kind) {
  using O = OscillatorOptions;
  static const std::vector<BuiltinAlias> harmonic = {
      {"mass", "m", &O::mass}, {"stiffness", "k", &O::stiffness}, {"damping", "c", &O::damping}};
  static const std::vector<BuiltinAlias> duffing = {{"mass", "m", &O::mass},
                                                    {"stiffness", "k", &O::stiffness},
                                                    {"cubic_stiffness", "k3", &O::cubic_stiffness},
                                                    {"damping", "c", &O::damping}};
  static const std::vector<BuiltinAlias> self_sustained = {
      {"mass", "m", &O::mass},
      {"stiffness", "k", &O::stiffness},
      {"z_coefficients[0]", "z1", nullptr, 0},
      {"z_coefficients[1]", "z2", nullptr, 1},
      {"z_coefficients[2]", "z3", nullptr, 2}};
  switch (kind) {
    case SystemKind::kHarmonic: return harmonic;
    case SystemKind::kDuffing: return duffing;
    case SystemKind::kSelfSustained: return self_sustained;
  }
  return harmonic;
}

double& value_of(OscillatorOptions& o, const BuiltinAlias& a) {
  return a.field ? o.*a.field : o.z_coefficients[static_cast<std::size_t>(a.z_index)];
}

// What the paper's system is, beyond its parameter values (paper Table 1,
// docs/METHOD.md §1): a shipped file that says otherwise is refused.
struct Expected {
  const char* energy;
  const char* dissipation;
  InitialConditionDesign::Method initial;
  ControlDesign::Design control;
  // S of eq:phs_S, rows and columns (q, p, w, u): a force input and a damper
  // on p (harmonic, Duffing), or the self-sustained oscillator's series port.
  std::array<std::array<int, 4>, 4> S;
};

constexpr std::array<std::array<int, 4>, 4> kForceS = {
    {{0, 1, 0, 0}, {-1, 0, -1, -1}, {0, 1, 0, 0}, {0, 1, 0, 0}}};
constexpr std::array<std::array<int, 4>, 4> kSelfSustainedS = {
    {{0, -1, 1, 0}, {1, 0, 0, 0}, {-1, 0, 0, -1}, {0, 0, 1, 0}}};

Expected expected(SystemKind kind) {
  using I = InitialConditionDesign::Method;
  using C = ControlDesign::Design;
  switch (kind) {
    case SystemKind::kHarmonic:
      return {"p^2/(2*m) + k*q^2/2", "c*w", I::kAlgorithm1, C::kEnergyShaping, kForceS};
    case SystemKind::kDuffing:
      return {"p^2/(2*m) + k*q^2/2 + k3*q^4/4", "c*w", I::kEnergy, C::kEnergyShaping, kForceS};
    case SystemKind::kSelfSustained:
      return {"p^2/(2*m) + k*q^2/2", "z1*w + z2*w^2 + z3*w^3", I::kAlgorithm1, C::kLimitCycle,
              kSelfSustainedS};
  }
  return {"", "", I::kEnergy, C::kConstant, {}};
}

bool same_structure(const MatX& S, const std::array<std::array<int, 4>, 4>& expected) {
  if (S.rows() != 4 || S.cols() != 4) return false;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (S(r, c) != expected[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)]) return false;
    }
  }
  return true;
}

// Throws unless `def` is the paper's `kind` (any parameter values).
void check_definition(const SystemDefinition& def, SystemKind kind) {
  const Expected e = expected(kind);
  std::string problem;
  if (def.states != std::vector<std::string>{"q", "p"} || def.inputs != std::vector<std::string>{"u"} ||
      def.ports != std::vector<std::string>{"w"}) {
    problem = "states, inputs or ports are not q, p / u / w";
  } else if (def.energy != e.energy || def.dissipation != std::vector<std::string>{e.dissipation}) {
    problem = "H or z is not the paper's (H = \"" + std::string(e.energy) + "\", z = [\"" +
              e.dissipation + "\"])";
  } else if (!same_structure(def.S, e.S)) {
    problem = "S is not the paper's";
  } else if (def.initial.method != e.initial || def.control.design != e.control) {
    problem = "[initial] method or [control] design is not the paper's algorithm";
  }
  for (const BuiltinAlias& a : aliases_of(kind)) {
    bool found = false;
    for (const auto& p : def.parameters) found = found || p.first == a.parameter;
    if (!found && problem.empty()) problem = std::string("no parameter ") + a.parameter;
  }
  if (!problem.empty()) {
    throw SystemFileError(def.file, 0, "the shipped system file of the built-in system \"" +
                                           to_string(kind) + "\" does not define it: " + problem +
                                           "; restore it from the source tree (sweeps/systems/), "
                                           "and save a changed system under another name");
  }
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Line `line` (1-based) of `text`, `key = old  # note`, with `value` in
// place of old (the note kept). `key` (e.g. "control.energy") names a key
// the shipped file `path` must have for the value to be written.
void set_value(std::string* text, int line, const std::string& value, const std::string& key,
               const std::string& path) {
  if (line <= 0) {
    throw SystemFileError(path, 0, "the shipped system file has no " + key + " to set to " + value +
                                       "; restore it from the source tree (sweeps/systems/)");
  }
  std::size_t begin = 0;
  for (int l = 1; l < line; ++l) begin = text->find('\n', begin) + 1;
  const std::size_t end = std::min(text->find('\n', begin), text->size());
  const std::string old = text->substr(begin, end - begin);
  const std::size_t eq = old.find('=');
  const std::size_t hash = old.find('#', eq);
  std::string updated = old.substr(0, eq) + "= " + value;
  if (hash != std::string::npos) updated += "  " + old.substr(hash);
  text->replace(begin, end - begin, updated);
}

std::string interval_text(const std::array<double, 2>& v) { return "[" + shortest_number(v[0]) + ", " + shortest_number(v[1]) + "]"; }

// The rewritten text reads back as the values asked for (a line rewritten
// in place cannot have hit another key), else the shipped file's layout is
// not one this rewriting handles.
void check_written(const std::string& text, const OscillatorOptions& physics,
                   const BuiltinEnergies& energies, const std::string& path) {
  const SystemDefinition def = parse_system_definition(text, path);
  OscillatorOptions values = physics;
  bool same = same_bits(def.initial.energy_min, energies.initial[0]) &&
              same_bits(def.initial.energy_max, energies.initial[1]);
  if (def.control.design == ControlDesign::Design::kEnergyShaping) {
    same = same && same_bits(def.control.equilibrium_energy_min, energies.equilibrium[0]) &&
           same_bits(def.control.equilibrium_energy_max, energies.equilibrium[1]);
  }
  for (const BuiltinAlias& a : aliases_of(physics.kind)) {
    for (const auto& [name, stored] : def.parameters) {
      if (name == a.parameter) same = same && same_bits(stored, value_of(values, a));
    }
  }
  if (!same) {
    throw SystemFileError(path, 0, "the shipped system file does not take the built-in system's "
                                   "physics (a parameter or energy written on a shared line?); "
                                   "restore it from the source tree (sweeps/systems/)");
  }
}

}  // namespace

const std::vector<BuiltinAlias>& builtin_aliases(SystemKind kind) { return aliases_of(kind); }

std::string builtin_system_text(const OscillatorOptions& physics, const BuiltinEnergies& energies) {
  physics.validate();
  const std::string path = shipped_systems_dir() + "/" + to_string(physics.kind) + ".toml";
  std::string text = read_system_file_text(path);
  const SystemDefinition def = parse_system_definition(text, path);
  check_definition(def, physics.kind);
  OscillatorOptions values = physics;
  for (const BuiltinAlias& a : aliases_of(physics.kind)) {
    for (const auto& [name, stored] : def.parameters) {
      const double wanted = value_of(values, a);
      if (name == a.parameter && !same_bits(stored, wanted)) {
        set_value(&text, def.line_of("parameters." + name), shortest_number(wanted), "parameters." + name, path);
      }
    }
  }
  const InitialConditionDesign& d = def.initial;
  if (!same_bits(d.energy_min, energies.initial[0]) || !same_bits(d.energy_max, energies.initial[1])) {
    set_value(&text, def.line_of("initial.energy"), interval_text(energies.initial), "initial.energy", path);
  }
  const ControlDesign& c = def.control;
  if (c.design == ControlDesign::Design::kEnergyShaping &&
      (!same_bits(c.equilibrium_energy_min, energies.equilibrium[0]) ||
       !same_bits(c.equilibrium_energy_max, energies.equilibrium[1]))) {
    set_value(&text, def.line_of("control.energy"), interval_text(energies.equilibrium),
              "control.energy", path);
  }
  check_written(text, physics, energies, path);
  return text;
}

std::unique_ptr<PhSystem> builtin_system(const OscillatorOptions& physics,
                                         const BuiltinEnergies& energies) {
  return compile_system(builtin_system_text(physics, energies),
                        shipped_systems_dir() + "/" + to_string(physics.kind) + ".toml");
}

OscillatorOptions builtin_physics(const std::string& text, const std::string& where) {
  const SystemDefinition def = parse_system_definition(text, where);
  SystemKind kind;
  try {
    kind = parse_system(def.name);
  } catch (const std::invalid_argument&) {
    throw SystemFileError(where, def.line_of("name"), "system \"" + def.name +
                                                          "\" is not a built-in system (harmonic, "
                                                          "duffing, self-sustained)");
  }
  check_definition(def, kind);
  OscillatorOptions physics = OscillatorOptions::defaults(kind);
  for (const BuiltinAlias& a : aliases_of(kind)) {
    for (const auto& [name, value] : def.parameters) {
      if (name == a.parameter) value_of(physics, a) = value;
    }
  }
  return physics;
}

}  // namespace phnn
