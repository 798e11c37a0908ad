// tests/models/weight_layout_test.cpp — weight_layout() (config, no
// LibTorch) names the tensors RunResult::weights stores, in the order and
// with the shapes of DynamicsModel::parameters(): for every model and size on
// the built-in 2-state structure and on 4- and 6-state system files.
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "phnn/config/model_config.h"
#include "phnn/models/dynamics_model.h"
#include "phnn/systems/system_file.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace {

// parameters() shapes without the member axis: per layer a weight [E, in,
// out] -> {in, out}, then a bias [E, 1, out] -> {out}.
std::vector<std::vector<int>> stored_shapes(const DynamicsModel& model) {
  std::vector<std::vector<int>> out;
  const std::vector<torch::Tensor> params = model.parameters();
  for (std::size_t k = 0; k < params.size(); ++k) {
    const torch::Tensor& p = params[k];
    EXPECT_EQ(p.dim(), 3) << k;
    if (k % 2 == 0) {
      out.push_back({static_cast<int>(p.size(1)), static_cast<int>(p.size(2))});
    } else {
      EXPECT_EQ(p.size(1), 1) << k;
      out.push_back({static_cast<int>(p.size(2))});
    }
  }
  return out;
}

void expect_layout(const DynamicsModel& model, const std::vector<WeightTensor>& layout) {
  const auto shapes = stored_shapes(model);
  ASSERT_EQ(shapes.size(), layout.size());
  long total = 0;
  for (std::size_t k = 0; k < layout.size(); ++k) {
    EXPECT_EQ(shapes[k], layout[k].shape) << layout[k].name;
    long n = 1;
    for (int d : layout[k].shape) n *= d;
    total += n;
    EXPECT_EQ(layout[k].name.substr(layout[k].name.size() - (k % 2 ? 5 : 7)),
              k % 2 ? ".bias" : ".weight");
  }
  EXPECT_EQ(total, model.parameter_count());
}

TEST(WeightLayoutTest, MatchesTheBuiltInModels) {
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
    for (ModelSize size : {ModelSize::kSmall, ModelSize::kMedium, ModelSize::kLarge}) {
      SCOPED_TRACE(to_string(kind) + " " + to_string(size));
      const auto model = DynamicsModel::create(ModelOptions{kind, size, SystemKind::kDuffing}, {0});
      expect_layout(*model, weight_layout(kind, size, 2, 1, 1));
    }
  }
  const std::string w = std::to_string(network_widths(ModelSize::kSmall).l_h[0]);
  const std::string text =
      weight_layout_text(weight_layout(ModelKind::kPhnnS, ModelSize::kSmall, 2, 1, 1));
  EXPECT_EQ(text.rfind("l_h.0.weight 2x" + w + "; l_h.0.bias " + w + "; l_h.1.weight " + w + "x", 0),
            0u)
      << text;
}

TEST(WeightLayoutTest, MatchesTheModelsOfSystemFiles) {
  for (const std::string name : {"coupled-duffing", "mass-chain"}) {
    const auto system =
        load_system_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name + ".toml");
    for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnS, ModelKind::kPhnnJr}) {
      SCOPED_TRACE(name + " " + to_string(kind));
      ModelOptions options{kind, ModelSize::kSmall, SystemKind::kHarmonic};
      options.general = std::make_shared<ModelStructure>(model_structure(*system));
      const auto model = DynamicsModel::create(options, {0, 1});
      expect_layout(*model, weight_layout(kind, ModelSize::kSmall, system->n_x(), system->n_w(),
                                          system->n_u()));
    }
  }
}

}  // namespace
}  // namespace phnn
