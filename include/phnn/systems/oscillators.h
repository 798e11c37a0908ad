// include/phnn/systems/oscillators.h — the paper's three oscillators as
// names (SystemKind) and physics options (OscillatorOptions, a sweep's
// [physics.NAME]); their systems are the shipped files (builtin_systems.h).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "phnn/common/enum_names.h"

namespace phnn {

/// The three controlled oscillators of the paper (tab:PHS-examples-and-formulations,
/// docs/METHOD.md §1).
enum class SystemKind { kHarmonic = 0, kDuffing = 1, kSelfSustained = 2 };

inline constexpr EnumNames<SystemKind, 3> kSystemNames{
    "system", {{{SystemKind::kHarmonic, "harmonic"}, {SystemKind::kDuffing, "duffing"},
                {SystemKind::kSelfSustained, "self-sustained"}}}};
inline std::string to_string(SystemKind kind) { return kSystemNames.name(kind); }
/// Parses a system name; throws std::invalid_argument naming the value and
/// listing the allowed names.
SystemKind parse_system(const std::string& name);
/// All systems, in paper order.
inline std::vector<SystemKind> all_systems() { return kSystemNames.all(); }

/// Physical parameters of one oscillator. Defaults are docs/METHOD.md §1; build them
/// with OscillatorOptions::defaults(kind).
struct OscillatorOptions {
  SystemKind kind = SystemKind::kHarmonic;
  /// m [kg].
  double mass = 0.16;
  /// k = k1 [N/m]; with m = 0.16 this gives f0 = 1 Hz.
  double stiffness = 1.0 / 0.16;
  /// k3 [N/m^3] of the Duffing oscillator (ignored by the others).
  double cubic_stiffness = 100.0 / 0.16;
  /// c [N s/m] of z(w) = c w (harmonic, Duffing). docs/METHOD.md §1: the text's
  /// "99 % of the energy dissipated in 5 s" gives c = m ln(100) / 5 = 0.14737;
  /// the paper's Table 5 prints 0.9 (see sweeps/paper-table-damping.toml).
  double damping = 0.16 * 4.605170185988091 / 5.0;
  /// z(w) = z1 w + z2 w^2 + z3 w^3 of the self-sustained oscillator.
  std::array<double, 3> z_coefficients = {3.0, -4.0, 1.3};

  /// docs/METHOD.md §1 defaults for `kind`.
  static OscillatorOptions defaults(SystemKind kind);
  /// Throws std::invalid_argument naming the field, value and constraint.
  void validate() const;
};

/// Roots r1 <= r2 of A w^2 + B w + C (A > 0, B^2 - 4AC > 0 checked by the
/// caller), computed without cancellation: t = -(B + sign(B) sqrt(disc)) / 2,
/// roots t / A and C / t. Between them the quadratic is negative
/// (Algorithm 4's I_w = {w : z'(w) < 0} for a cubic z).
std::array<double, 2> stable_quadratic_roots(double A, double B, double C);

/// I_w = {w : z'(w) < 0} of Algorithm 4 for z(w) = z1 w + z2 w^2 + z3 w^3:
/// the open interval between the roots of z'(w). Throws std::invalid_argument
/// if it is empty (z3 <= 0 or no real roots).
std::array<double, 2> self_oscillation_interval(const std::array<double, 3>& z_coefficients);

}  // namespace phnn
