// tests/sweep/training_settings_test.cpp — the table of training settings:
// run ids it writes equal those written before it existed (canonical keys
// taken from results files of the binary of 4f45ae1), sweeps/FORMAT.md shows
// the table it generates, and the sweep file and `phnn train` read it.
#include "phnn/config/training_settings.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace {

// "model=...;regularizer=..." -> the key from ";steps=" on, of every
// harmonic run of `text` (built-in system) or self-sustained run.
std::map<std::string, std::string> training_keys(const std::string& text) {
  std::map<std::string, std::string> out;
  const Grid grid = expand_grid(parse_sweep_text(text, "x.toml"));
  for (const RunConfig& run : grid.runs) {
    const std::string c = run.canonical();
    if (c.rfind("system=harmonic", 0) != 0 && c.rfind("system=self-sustained", 0) != 0) continue;
    const auto model = c.find("model=");
    const auto reg_end = c.find(';', c.find("regularizer="));
    out[c.substr(model, reg_end - model)] = c.substr(c.find(";steps="));
  }
  return out;
}

// The sweeps of the two results files the expected keys come from.
const char* kVariants = R"(name = "keys"
[data]
num_validation = 8
num_inference = 1
[training]
steps = 10
eval_every = 5
checkpoints = [5]
[grid]
systems = ["harmonic", "duffing"]
models = ["phnn-jr-dg", "phnn-s-rk2", "node-rk2", "phnn-jr-dg4"]
sizes = ["small"]
n_train = [8]
regularizers = ["none", "sr"]
seeds = [0]
)";

const char* kKnobs = R"(name = "keys2"
[data]
num_validation = 8
num_inference = 1
[training]
steps = 10
eval_every = 5
loss_norm = "mse"
precision = "float32"
inference_weights = "final"
dg_structure_point = "start"
learning_rate = 3e-4
newton_tolerance = 1e-11
lambda_cn = 2e-6
[grid]
systems = ["self-sustained"]
models = ["phnn-jr-dg", "phnn-s-dg"]
sizes = ["small"]
n_train = [8]
regularizers = ["cn", "none"]
seeds = [0]
)";

TEST(TrainingSettingsTest, CanonicalKeysAreThoseOfRunsWrittenBeforeTheTable) {
  const std::map<std::string, std::string> variants = {
      {"model=node;integrator=rk2;size=small;n_train=8;regularizer=none",
       ";steps=10;lr=0.001;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;jac_eps=9.9999999999999995e-07;divergence=1000000;checkpoints=5;seed=0"},
      {"model=node;integrator=rk2;size=small;n_train=8;regularizer=sr",
       ";steps=10;lr=0.001;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;lambda=0.0001;jac_eps=9.9999999999999995e-07;divergence=1000000;checkpoints=5;seed=0"},
      {"model=phnn-jr;integrator=dg4;size=small;n_train=8;regularizer=none",
       ";steps=10;lr=0.001;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;jac_eps=9.9999999999999995e-07;newton=9.9999999999999998e-13,20;tau=6.0000000000000002e-06;divergence=1000000;checkpoints=5;seed=0"},
      {"model=phnn-jr;integrator=dg4;size=small;n_train=8;regularizer=sr",
       ";steps=10;lr=0.001;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;lambda=0.0001;jac_eps=9.9999999999999995e-07;newton=9.9999999999999998e-13,20;tau=6.0000000000000002e-06;divergence=1000000;checkpoints=5;seed=0"},
      {"model=phnn-jr;integrator=dg;size=small;n_train=8;regularizer=none",
       ";steps=10;lr=0.001;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;jac_eps=9.9999999999999995e-07;newton=9.9999999999999998e-13,20;tau=6.0000000000000002e-06;divergence=1000000;checkpoints=5;seed=0"},
      {"model=phnn-jr;integrator=dg;size=small;n_train=8;regularizer=sr",
       ";steps=10;lr=0.001;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;lambda=0.0001;jac_eps=9.9999999999999995e-07;newton=9.9999999999999998e-13,20;tau=6.0000000000000002e-06;divergence=1000000;checkpoints=5;seed=0"},
      {"model=phnn-s;integrator=rk2;size=small;n_train=8;regularizer=none",
       ";steps=10;lr=0.001;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;jac_eps=9.9999999999999995e-07;divergence=1000000;checkpoints=5;seed=0"},
      {"model=phnn-s;integrator=rk2;size=small;n_train=8;regularizer=sr",
       ";steps=10;lr=0.001;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;lambda=0.0001;jac_eps=9.9999999999999995e-07;divergence=1000000;checkpoints=5;seed=0"},
  };
  EXPECT_EQ(training_keys(kVariants), variants);
  const std::map<std::string, std::string> knobs = {
      {"model=phnn-jr;integrator=dg;size=small;n_train=8;regularizer=cn",
       ";steps=10;lr=0.00029999999999999997;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;lambda=1.9999999999999999e-06;loss_norm=mse;precision=float32;inference_weights=final;jac_eps=9.9999999999999995e-07;newton=9.9999999999999994e-12,20;tau=6.0000000000000002e-06;dg_structure_point=start;divergence=1000000;seed=0"},
      {"model=phnn-jr;integrator=dg;size=small;n_train=8;regularizer=none",
       ";steps=10;lr=0.00029999999999999997;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;loss_norm=mse;precision=float32;inference_weights=final;jac_eps=9.9999999999999995e-07;newton=9.9999999999999994e-12,20;tau=6.0000000000000002e-06;dg_structure_point=start;divergence=1000000;seed=0"},
      {"model=phnn-s;integrator=dg;size=small;n_train=8;regularizer=cn",
       ";steps=10;lr=0.00029999999999999997;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;lambda=1.9999999999999999e-06;loss_norm=mse;precision=float32;inference_weights=final;jac_eps=9.9999999999999995e-07;newton=9.9999999999999994e-12,20;tau=6.0000000000000002e-06;divergence=1000000;seed=0"},
      {"model=phnn-s;integrator=dg;size=small;n_train=8;regularizer=none",
       ";steps=10;lr=0.00029999999999999997;adam=0.90000000000000002,0.999,1e-08;batch=64;eval_every=5;loss_norm=mse;precision=float32;inference_weights=final;jac_eps=9.9999999999999995e-07;newton=9.9999999999999994e-12,20;tau=6.0000000000000002e-06;divergence=1000000;seed=0"},
  };
  EXPECT_EQ(training_keys(kKnobs), knobs);
}

TEST(TrainingSettingsTest, FormatMdShowsTheGeneratedTable) {
  std::ifstream in(std::string(PHNN_SOURCE_DIR) + "/sweeps/FORMAT.md");
  ASSERT_TRUE(in) << "cannot read sweeps/FORMAT.md";
  std::stringstream all;
  all << in.rdbuf();
  const std::string text = all.str();
  const std::string begin = "<!-- training settings: generated, do not edit by hand -->\n";
  const std::string end = "<!-- end of training settings -->";
  const auto a = text.find(begin), b = text.find(end);
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  EXPECT_EQ(text.substr(a + begin.size(), b - a - begin.size()), training_settings_markdown())
      << "sweeps/FORMAT.md's [training] table is stale; replace it by:\n"
      << training_settings_markdown();
}

TEST(TrainingSettingsTest, EveryKeyIsReadFromASweepFileIntoItsField) {
  // A value away from the default for each setting: read back through the table.
  std::string text = "name = \"t\"\n[training]\n";
  const TrainerOptions defaults;
  for (const TrainingSetting& s : training_settings()) {
    text += std::string(s.key) + " = ";
    if (s.kind == TrainingSetting::Kind::kChoice) {
      text += "\"" + s.choices().back() + "\"\n";
    } else if (s.kind == TrainingSetting::Kind::kInteger) {
      text += std::to_string(defaults.*s.integer + 7) + "\n";
    } else {
      text += "0.125\n";
    }
  }
  text += "[grid]\nsystems = [\"harmonic\"]\nmodels = [\"phnn-jr-dg\"]\nn_train = [8]\nseeds = [0]\n";
  const SweepSpec spec = parse_sweep_text(text, "t.toml");
  const TrainerOptions& t = spec.training;
  for (const TrainingSetting& s : training_settings()) {
    EXPECT_FALSE(s.is_default(t)) << s.key;
    if (s.kind == TrainingSetting::Kind::kReal) {
      EXPECT_EQ(t.*s.real, 0.125) << s.key;
    }
  }
  const auto with_key = [](const std::string& key) -> const TrainingSetting* {
    for (const TrainingSetting& s : training_settings()) {
      if (key == s.key) return &s;
    }
    return nullptr;
  };
  ASSERT_NE(with_key("learning_rate"), nullptr);
  EXPECT_EQ(with_key("learning_rate")->real, &TrainerOptions::learning_rate);
  EXPECT_EQ(with_key("lr"), nullptr);  // the canonical spelling is not a key
}

}  // namespace
}  // namespace phnn
