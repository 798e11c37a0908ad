// src/config/model_config.cpp — network widths and parameter counts of each
// model and size (LibTorch-free; the names are in the header).
#include "phnn/config/model_config.h"

#include <cctype>
#include <stdexcept>

namespace phnn {

NetworkWidths network_widths(ModelSize size) {
  switch (size) {
    case ModelSize::kSmall: return {{24, 24}, {16, 16}, {16, 16}, {20, 20}};
    case ModelSize::kMedium: return {{60, 60}, {42, 42}, {42, 42}, {42, 42}};
    case ModelSize::kLarge: return {{100, 100, 100}, {100, 100}, {100, 100}, {100, 100}};
  }
  return {};
}

long mlp_parameter_count(int in, const std::vector<int>& hidden, int out) {
  long count = 0;
  int prev = in;
  for (int w : hidden) {
    count += static_cast<long>(prev) * w + w;
    prev = w;
  }
  return count + static_cast<long>(prev) * out + out;
}


long parameter_count(ModelKind kind, ModelSize size, int n_x, int n_w, int n_u) {
  const NetworkWidths w = network_widths(size);
  const int m = n_x + n_u;
  const long l_h = mlp_parameter_count(n_x, w.l_h, n_x * (n_x + 1) / 2);
  switch (kind) {
    case ModelKind::kNode: return mlp_parameter_count(m, w.node, n_x);
    case ModelKind::kPhnnJr: return l_h + mlp_parameter_count(m, w.l_r, m * (m + 1) / 2);
    case ModelKind::kPhnnS:  // L_z: n_w(n_w+1)/2 lower-triangle + n_w(n_w-1)/2 skew outputs
      return l_h + (n_w > 0 ? mlp_parameter_count(n_w, w.l_z, n_w * n_w) : 0);
  }
  return 0;
}

namespace {

// An MLP's tensors: per layer its weight [fan_in, fan_out] and bias [fan_out].
void add_mlp(const std::string& net, int in, const std::vector<int>& hidden, int out,
             std::vector<WeightTensor>* layout) {
  int prev = in;
  std::vector<int> widths = hidden;
  widths.push_back(out);
  for (std::size_t l = 0; l < widths.size(); ++l) {
    const std::string layer = net + "." + std::to_string(l);
    layout->push_back({layer + ".weight", {prev, widths[l]}});
    layout->push_back({layer + ".bias", {widths[l]}});
    prev = widths[l];
  }
}

}  // namespace

std::vector<WeightTensor> weight_layout(ModelKind kind, ModelSize size, int n_x, int n_w, int n_u) {
  const NetworkWidths w = network_widths(size);
  const int m = n_x + n_u;
  std::vector<WeightTensor> layout;
  if (kind == ModelKind::kNode) {
    add_mlp("node", m, w.node, n_x, &layout);
    return layout;
  }
  add_mlp("l_h", n_x, w.l_h, n_x * (n_x + 1) / 2, &layout);
  if (kind == ModelKind::kPhnnJr) add_mlp("l_r", m, w.l_r, m * (m + 1) / 2, &layout);
  if (kind == ModelKind::kPhnnS && n_w > 0) add_mlp("l_z", n_w, w.l_z, n_w * n_w, &layout);
  return layout;
}

std::string weight_layout_text(const std::vector<WeightTensor>& layout) {
  std::string text;
  for (const WeightTensor& t : layout) {
    if (!text.empty()) text += "; ";
    text += t.name + " ";
    for (std::size_t d = 0; d < t.shape.size(); ++d) {
      text += (d ? "x" : "") + std::to_string(t.shape[d]);
    }
  }
  return text;
}

std::string model_label(ModelKind kind, IntegratorKind integrator) {
  std::string m = kind == ModelKind::kNode ? "NODE" : kind == ModelKind::kPhnnS ? "PHNN-S" : "PHNN-JR";
  std::string i = to_string(integrator);
  for (char& c : i) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return m + "-" + i;
}

}  // namespace phnn
