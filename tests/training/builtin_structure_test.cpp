// tests/training/builtin_structure_test.cpp — the structure the n-state
// models take for a built-in system (builtin_structure, from the 2-state
// oscillator's S and J) is exactly the one of its shipped system file
// (model_structure of sweeps/systems/NAME.toml, from the file's S): one model
// family, the same models whichever way the system is named.
#include <string>

#include <gtest/gtest.h>

#include "phnn/models/dynamics_model.h"
#include "phnn/systems/system_file.h"
#include "phnn/training/trainer.h"

namespace phnn {
namespace {

TEST(BuiltinStructureTest, EqualsTheShippedSystemFiles) {
  for (const SystemKind kind :
       {SystemKind::kHarmonic, SystemKind::kDuffing, SystemKind::kSelfSustained}) {
    const std::string name = to_string(kind);
    const auto file = load_system_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name +
                                       ".toml");
    const ModelStructure expected = model_structure(*file);
    const ModelStructure builtin = builtin_structure(kind);
    EXPECT_EQ(builtin.n_x, expected.n_x) << name;
    EXPECT_EQ(builtin.n_w, expected.n_w) << name;
    EXPECT_EQ(builtin.n_u, expected.n_u) << name;
    EXPECT_EQ(builtin.S, expected.S) << name;
    EXPECT_EQ(builtin.J, expected.J) << name;
  }
}

}  // namespace
}  // namespace phnn
