// src/systems/oscillators.cpp — include/phnn/systems/oscillators.h.
#include "phnn/systems/oscillators.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "phnn/common/check.h"

namespace phnn {

SystemKind parse_system(const std::string& name) {
  SystemKind kind{};
  if (kSystemNames.find(name, &kind)) return kind;
  throw std::invalid_argument(kSystemNames.unknown(
      name, ", the name of a shipped system file (sweeps/systems/NAME.toml), or a system file "
            "(a path ending in .toml)"));
}

OscillatorOptions OscillatorOptions::defaults(SystemKind kind) {
  OscillatorOptions options;
  options.kind = kind;
  return options;
}

namespace {
void require_positive_finite(const char* field, double value) {
  PHNN_REQUIRE(std::isfinite(value) && value > 0.0,
               "Invalid OscillatorOptions: " << field << " = " << value
                                             << "; violated constraint: "
                                             << field << " > 0 and finite.");
}
}  // namespace

void OscillatorOptions::validate() const {
  require_positive_finite("mass", mass);
  require_positive_finite("stiffness", stiffness);
  if (kind == SystemKind::kDuffing) {
    require_positive_finite("cubic_stiffness", cubic_stiffness);
  }
  if (kind != SystemKind::kSelfSustained) {
    PHNN_REQUIRE(std::isfinite(damping) && damping >= 0.0,
                 "Invalid OscillatorOptions: damping = "
                     << damping
                     << "; violated constraint: damping >= 0 and finite.");
  } else {
    for (double a : z_coefficients) {
      PHNN_REQUIRE(std::isfinite(a),
                   "Invalid OscillatorOptions: z_coefficients contains "
                       << a << "; violated constraint: finite.");
    }
  }
}

std::array<double, 2> stable_quadratic_roots(double A, double B, double C) {
  const double disc = B * B - 4.0 * A * C;
  const double t = -0.5 * (B + std::copysign(std::sqrt(disc), B));
  double r1 = t / A, r2 = C / t;
  if (r1 > r2) std::swap(r1, r2);
  return {r1, r2};
}

std::array<double, 2> self_oscillation_interval(const std::array<double, 3>& a) {
  // z'(w) = a1 + 2 a2 w + 3 a3 w^2 < 0 between its real roots (a3 > 0).
  const double A = 3.0 * a[2], B = 2.0 * a[1], C = a[0];
  const double disc = B * B - 4.0 * A * C;
  PHNN_REQUIRE(A > 0.0 && disc > 0.0,
               "self_oscillation_interval: z'(w) < 0 has no interval for "
               "z_coefficients = ("
                   << a[0] << ", " << a[1] << ", " << a[2] << ")");
  return stable_quadratic_roots(A, B, C);
}

}  // namespace phnn
