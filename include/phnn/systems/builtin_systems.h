// include/phnn/systems/builtin_systems.h — the paper's three oscillators
// ("harmonic", "duffing", "self-sustained") as what they are: the shipped
// system files sweeps/systems/NAME.toml, with a sweep's [physics.NAME] values
// and energy intervals written into the file's text by one alias table.
// Reads the shipped file; writes nothing.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "phnn/systems/oscillators.h"
#include "phnn/systems/ph_system.h"

namespace phnn {

/// One entry of the alias table: a [physics.NAME] key of sweep files (and
/// the canonical strings of runs, which keep these names) and the
/// [parameters] name of the shipped file it sets.
struct BuiltinAlias {
  const char* physics_key;  // "mass", "damping", "z_coefficients[0]", ...
  const char* parameter;    // "m", "c", "z1", ...
  double OscillatorOptions::*field = nullptr;  // scalar fields
  int z_index = -1;                            // z_coefficients[z_index]
};

/// The aliases `kind` uses, in its file's parameter order:
///   harmonic        mass -> m, stiffness -> k, damping -> c
///   duffing         mass -> m, stiffness -> k, cubic_stiffness -> k3, damping -> c
///   self-sustained  mass -> m, stiffness -> k, z_coefficients -> z1, z2, z3
const std::vector<BuiltinAlias>& builtin_aliases(SystemKind kind);

/// The energy intervals of a built-in system's designs: [initial] energy
/// (I_E0 of Algorithms 1 and 2) and [control] energy (I_Eeq of Algorithm 3;
/// unused by the self-sustained oscillator's Algorithm 4).
struct BuiltinEnergies {
  std::array<double, 2> initial = {0.1, 1.0};
  std::array<double, 2> equilibrium = {0.1, 1.0};
};

/// The text of the built-in system `physics.kind`: the shipped file
/// NAME.toml (shipped_systems_dir()) with every aliased parameter and the
/// energy intervals set to the given values (a line is rewritten only where
/// its value differs, so the defaults give the shipped text byte for byte).
/// Throws SystemFileError when the shipped file cannot be read or does not
/// define the paper's system (its name, states, ports, H, z or S changed).
std::string builtin_system_text(const OscillatorOptions& physics, const BuiltinEnergies& energies);

/// The compiled system of builtin_system_text.
std::unique_ptr<PhSystem> builtin_system(const OscillatorOptions& physics,
                                         const BuiltinEnergies& energies);

/// The inverse of the alias table: the physics a built-in system's text
/// (builtin_system_text's, stored in data and results files) sets.
/// Throws SystemFileError when `text` is not one of the three.
OscillatorOptions builtin_physics(const std::string& text, const std::string& where);

}  // namespace phnn
