// include/phnn/config/data_settings.h — the tables of [data] settings
// (DatasetOptions) and [physics.<system>] settings (OscillatorOptions of a
// built-in system): each written once, with its sweep-file key, its per-run
// CSV column(s), its part of the canonical key and one line of doc. The
// sweep reader, the canonical key (RunConfig::cell_key), the per-run columns
// and the tables in sweeps/FORMAT.md read them. Defaults: the structs'
// member initializers (physics: OscillatorOptions::defaults).
#pragma once

#include <climits>
#include <cstdint>
#include <string>
#include <vector>

#include "phnn/data/dataset.h"
#include "phnn/systems/oscillators.h"

namespace phnn {

/// One setting of DatasetOptions.
struct DataSetting {
  enum class Kind { kReal, kInteger, kChoice };
  /// Which runs' canonical keys hold it.
  enum class InKey {
    kAlways,
    kBuiltin,         // built-in systems only (a system file sets its own)
    kEnergySampling,  // energy_sampling's rule: only away from its default,
                      // and of a built-in system only where it applies (not
                      // Duffing, whose Algorithm 2 ignores it)
  };
  /// Sweep-file key in [data].
  const char* key;
  /// Per-run CSV column.
  const char* column;
  Kind kind;
  /// Canonical-key part ("h_gen"); consecutive settings sharing one are
  /// printed together, comma-separated ("e0=0.10000000000000001,1").
  const char* canonical;
  InKey in_key;
  /// One line for sweeps/FORMAT.md.
  const char* doc;
  double (*get_real)(const DatasetOptions&) = nullptr;
  void (*set_real)(DatasetOptions*, double) = nullptr;
  std::int64_t (*get_integer)(const DatasetOptions&) = nullptr;
  void (*set_integer)(DatasetOptions*, std::int64_t) = nullptr;
  /// kInteger: smallest value allowed (largest: INT64_MAX for the seed,
  /// INT_MAX otherwise).
  std::int64_t min_integer = 1;
  std::int64_t max_integer = INT_MAX;
  /// Where the value has a spelling of its own (the unsigned seed).
  std::string (*get_text)(const DatasetOptions&) = nullptr;
  /// kChoice: its names (default first) and the value's index among them.
  std::vector<std::string> (*choices)() = nullptr;
  int (*get_choice)(const DatasetOptions&) = nullptr;
  void (*set_choice)(DatasetOptions*, int index) = nullptr;

  /// The value in `d` as the canonical key spells it (reals %.17g, choices
  /// by name).
  std::string text(const DatasetOptions& d) const;
};

/// Every setting of DatasetOptions a sweep file sets, in canonical-key order.
const std::vector<DataSetting>& data_settings();

/// The canonical-key parts of a run's data settings, each preceded by ';':
/// of a built-in system `system` (builtin = true) or of a system file.
std::string data_key(const DatasetOptions& d, bool builtin, SystemKind system);

/// One parameter of a built-in system ([physics.<system>]).
struct PhysicsSetting {
  /// Sweep-file key ("z_coefficients").
  const char* key;
  /// Canonical-key part ("z"); its values comma-separated.
  const char* canonical;
  /// Per-run CSV columns, one per value ({"z1", "z2", "z3"}).
  std::vector<const char*> columns;
  /// The systems that use it.
  std::vector<SystemKind> systems;
  /// One line for sweeps/FORMAT.md.
  const char* doc;
  /// Its values (1, or 3 for z_coefficients).
  std::vector<double> (*get)(const OscillatorOptions&);
  void (*set)(OscillatorOptions*, const std::vector<double>&);

  bool applies_to(SystemKind system) const;
};

/// Every parameter, in canonical-key order.
const std::vector<PhysicsSetting>& physics_settings();

/// The canonical-key parts of a built-in system's parameters, each
/// preceded by ';': only those `system` uses.
std::string physics_key(const OscillatorOptions& p, SystemKind system);

/// The two tables as sweeps/FORMAT.md shows them (Markdown); a test keeps
/// FORMAT.md equal to them.
std::string data_settings_markdown();
std::string physics_settings_markdown();

}  // namespace phnn
