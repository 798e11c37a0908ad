// include/phnn/config/model_config.h — what a model is, without LibTorch.
#pragma once

#include <string>
#include <vector>

#include "phnn/common/enum_names.h"
#include "phnn/integrators/integrator_kind.h"

namespace phnn {

/// Model formulation (paper §4.1): NODE baseline, PHNN-S (eq:f_theta-PHS-DAF),
/// PHNN-JR (eq:f_theta-PHS-JR).
enum class ModelKind { kNode = 0, kPhnnS = 1, kPhnnJr = 2 };
/// Network size (paper Tables 10-12, docs/METHOD.md §3).
enum class ModelSize { kSmall = 0, kMedium = 1, kLarge = 2 };

/// Where the DG step (docs/METHOD.md §4) evaluates PHNN-JR's state-dependent
/// dissipation R_theta(x, u): at the midpoint x_n + dx/2 (the default) or at
/// the start x_n. J and the structure S of PHNN-S are constant, so PHNN-S,
/// RK2/RK4 and DG4 (always the midpoint) do not depend on it.
enum class DgStructurePoint { kMidpoint = 0, kStart = 1 };

/// The known interconnection of an n-dimensional (file-defined) system, as
/// the models need it: S of eq:phs_S ((n_x + n_w + n_u) square, rows and
/// columns ordered states, ports, inputs) for PHNN-S and J of eq:phs_JR
/// ((n_x + n_u) square) for PHNN-JR, both row-major.
struct ModelStructure {
  int n_x = 2, n_w = 1, n_u = 1;
  std::vector<double> S, J;
};

inline constexpr EnumNames<ModelKind, 3> kModelNames{
    "model", {{{ModelKind::kNode, "node"}, {ModelKind::kPhnnS, "phnn-s"}, {ModelKind::kPhnnJr, "phnn-jr"}}}};
inline constexpr EnumNames<ModelSize, 3> kSizeNames{
    "size", {{{ModelSize::kSmall, "small"}, {ModelSize::kMedium, "medium"}, {ModelSize::kLarge, "large"}}}};
inline constexpr EnumNames<DgStructurePoint, 2> kDgStructurePointNames{
    "DG structure point", {{{DgStructurePoint::kMidpoint, "midpoint"}, {DgStructurePoint::kStart, "start"}}}};

inline std::string to_string(ModelKind kind) { return kModelNames.name(kind); }
inline std::string to_string(ModelSize size) { return kSizeNames.name(size); }
inline std::string to_string(DgStructurePoint point) { return kDgStructurePointNames.name(point); }
/// Every DgStructurePoint, default first.
inline std::vector<DgStructurePoint> all_dg_structure_points() { return kDgStructurePointNames.all(); }

/// Parsers: throw std::invalid_argument naming the value and listing the
/// allowed values.
inline ModelKind parse_model(const std::string& name) { return kModelNames.parse(name); }
inline ModelSize parse_size(const std::string& name) { return kSizeNames.parse(name); }

/// Hidden widths of each MLP of a model (docs/METHOD.md §3 table).
struct NetworkWidths {
  std::vector<int> node;  // NODE: 3 -> ... -> 2
  std::vector<int> l_h;   // L_H: 2 -> ... -> 3
  std::vector<int> l_r;   // L_R: 3 -> ... -> 6
  std::vector<int> l_z;   // L_z: 1 -> ... -> 1
};
NetworkWidths network_widths(ModelSize size);

/// Number of trainable parameters of one member (docs/METHOD.md §3) of the
/// models (general_ph.h) of a system with n_x states, n_w dissipation ports
/// and n_u inputs: PHNN-JR = L_H + L_R; PHNN-S = L_H + L_z; at (2, 1, 1)
/// NODE 746 / 4022 / 20802.
long parameter_count(ModelKind kind, ModelSize size, int n_x, int n_w, int n_u);
/// Parameters of an MLP with the given input, hidden widths and output.
long mlp_parameter_count(int in, const std::vector<int>& hidden, int out);

/// One stored weight tensor of a member: `name` ("l_h.0.weight"), its shape
/// ({fan_in, fan_out} for a weight, {fan_out} for a bias).
struct WeightTensor {
  std::string name;
  std::vector<int> shape;
};

/// The member's weights in the order RunResult::weights stores them
/// (DynamicsModel::parameters(): each network, then per layer its weight
/// [fan_in, fan_out] row-major and its bias): NODE `node`; PHNN-S `l_h`, then
/// `l_z` (if n_w > 0); PHNN-JR `l_h`, then `l_r`; with the input and output
/// widths of parameter_count(kind, size, n_x, n_w, n_u) (the built-in
/// systems: n_x = 2, n_w = n_u = 1). Sizes sum to that count.
std::vector<WeightTensor> weight_layout(ModelKind kind, ModelSize size, int n_x, int n_w, int n_u);

/// weight_layout as text, "l_h.0.weight 2x16; l_h.0.bias 16; ..." (the
/// results file's /runs/weights_layout).
std::string weight_layout_text(const std::vector<WeightTensor>& layout);

/// Paper's label, e.g. "PHNN-JR-DG", "NODE-RK2".
std::string model_label(ModelKind kind, IntegratorKind integrator);

}  // namespace phnn
