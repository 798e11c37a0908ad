// include/phnn/integrators/integrator_kind.h — the integrators' names
// (IntegratorKind and its EnumNames table), without their steps: what the
// configuration needs. Their table (order, steps): integrator.h.
#pragma once

#include <string>

#include "phnn/common/enum_names.h"

namespace phnn {

/// Discrete-model integrator (Eqs. 26, 28-30): explicit midpoint, the
/// Gonzalez discrete gradient, classical RK4, the fourth-order DG.
enum class IntegratorKind { kRk2 = 0, kDg = 1, kRk4 = 2, kDg4 = 3 };
inline constexpr EnumNames<IntegratorKind, 4> kIntegratorNames{"integrator",
                                                               {{{IntegratorKind::kRk2, "rk2"},
                                                                 {IntegratorKind::kDg, "dg"},
                                                                 {IntegratorKind::kRk4, "rk4"},
                                                                 {IntegratorKind::kDg4, "dg4"}}}};
inline std::string to_string(IntegratorKind kind) { return kIntegratorNames.name(kind); }
/// Throws std::invalid_argument naming the value and listing the allowed ones.
inline IntegratorKind parse_integrator(const std::string& name) {
  return kIntegratorNames.parse(name);
}

}  // namespace phnn
