// tests/data/ph_dataset_test.cpp — data sets of file-defined systems: the
// paper's three systems as files reproduce the built-in data, every stored
// step of the new systems satisfies the discrete power balance, and the
// version-2 data-set file round-trips.
#include "phnn/data/ph_dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/integrators/ph_steps.h"
#include "phnn/store/dataset_file.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::string shipped(const std::string& name) {
  return std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name + ".toml";
}

double max_diff(const std::vector<Vec2>& a, const std::vector<VecX>& b) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    for (int j = 0; j < 2; ++j) worst = std::max(worst, std::abs(a[i](j) - b[i](j)));
  }
  return worst;
}

// Acceptance: `phnn data --system sweeps/systems/X.toml` equals `--system X`
// to <= 1e-12 (the splits at reduced sizes, every index drawn as in the paper).
TEST(PhDatasetTest, PaperSystemFilesReproduceTheBuiltInData) {
  DatasetOptions options;
  options.num_validation = 40;
  options.num_inference = 3;
  for (SystemKind kind : all_systems()) {
    const std::string name = to_string(kind);
    const SystemData builtin = make_system_data(OscillatorOptions::defaults(kind), options, 25);
    const auto system = load_system_file(shipped(name));
    const PhSystemData file = make_ph_system_data(*system, options, 25);
    EXPECT_EQ(file.train.position, builtin.train.position) << name;
    EXPECT_EQ(file.validation.position, builtin.validation.position) << name;
    EXPECT_LE(max_diff(builtin.train.x, file.train.x), 1e-12) << name;
    EXPECT_LE(max_diff(builtin.train.x_next, file.train.x_next), 1e-12) << name;
    EXPECT_LE(max_diff(builtin.validation.x_next, file.validation.x_next), 1e-12) << name;
    for (std::size_t i = 0; i < builtin.train.size(); ++i) {
      EXPECT_NEAR(file.train.u[i](0), builtin.train.u[i], 1e-12) << name;
    }
    for (std::size_t i = 0; i < builtin.inference.size(); ++i) {
      EXPECT_NEAR(file.inference.u[i](0), builtin.inference.u[i], 1e-12) << name;
      EXPECT_LE(max_diff(builtin.inference.states[i], file.inference.states[i]), 1e-12) << name;
    }
  }
}

// A whole 2000-step trajectory of the paper's inference split, per system.
TEST(PhDatasetTest, PaperSystemFilesReproduceAFullInferenceTrajectory) {
  const DatasetOptions options;
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    const Trajectory builtin = generate_trajectory(osc, options, 2950, 2000);
    const auto system = load_system_file(shipped(to_string(kind)));
    const PhTrajectory file = ph_generate_trajectory(*system, options, 2950, 2000);
    double worst = max_diff(builtin.states, file.states);
    EXPECT_LE(worst, 1e-12) << to_string(kind);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", worst);
    RecordProperty("file_vs_builtin_" + to_string(kind), buf);
  }
}

// H(x_{n+1}) - H(x_n) = -h (z^T w + u^T y) on every stored step, relative to
// the step's power scale |H_n| + |H_{n+1}| + h |z^T w| + h |u^T y|.
TEST(PhDatasetTest, GeneratedTrajectoriesSatisfyTheDiscretePowerBalance) {
  const DatasetOptions options;
  for (const std::string name : {"pendulum", "coupled-duffing", "mass-chain"}) {
    const auto system = load_system_file(shipped(name));
    double worst = 0.0;
    for (std::int64_t index : {0, 17, 401, 2950}) {
      const PhTrajectory traj = ph_generate_trajectory(*system, options, index, 2000);
      const double h = options.generation_step;
      for (std::size_t n = 0; n + 1 < traj.states.size(); ++n) {
        const VecX& x = traj.states[n];
        const PhImplicitStep step = ph_discrete_gradient_step(*system, x, traj.u, h, options.newton);
        ASSERT_EQ(step.status, StepStatus::kConverged);
        ASSERT_EQ(step.x_next, traj.states[n + 1]);  // the generator's own step
        const double h0 = system->hamiltonian(x), h1 = system->hamiltonian(step.x_next);
        const double zw = step.flows.z.dot(step.flows.w), uy = traj.u.dot(step.flows.y);
        const double scale = std::abs(h0) + std::abs(h1) + h * std::abs(zw) + h * std::abs(uy);
        worst = std::max(worst, std::abs(h1 - h0 + h * (zw + uy)) / scale);
      }
    }
    EXPECT_LE(worst, 1e-12) << name;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", worst);
    RecordProperty("power_balance_" + name, buf);
  }
}

TEST(PhDatasetTest, InitialEnergiesLieInTheFilesInterval) {
  const DatasetOptions options;
  for (const std::string name : {"pendulum", "coupled-duffing", "mass-chain"}) {
    const auto system = load_system_file(shipped(name));
    const auto& design = system->initial_design();
    for (std::int64_t index = 0; index < 50; ++index) {
      const PhTrajectorySpec spec = ph_trajectory_spec(*system, options, index);
      const double h = system->hamiltonian(spec.x0);
      EXPECT_GE(h, design.energy_min) << name;
      EXPECT_LE(h, design.energy_max) << name;
      const auto& range = system->control_design().range[0];
      EXPECT_GE(spec.u(0), range[0]);
      EXPECT_LE(spec.u(0), range[1]);
      // Counter-based: the same index gives the same draw, alone.
      EXPECT_EQ(ph_trajectory_spec(*system, options, index).x0, spec.x0);
    }
  }
}

TEST(PhDatasetTest, EnergyIntervalNoDrawReachesIsAnErrorAtTheInitialTable) {
  const std::string text = R"(name = "toy"
states = ["q", "p"]
H = "q^2 + p^2"
S = [[0, 1], [-1, 0]]
[initial]
method = "energy"
energy = [0.999999999999, 1.0]
box = [[-0.1, 0.1], [-0.1, 0.1]]
)";
  const auto system = compile_system(text, "toy.toml");
  EXPECT_THAT([&] { ph_trajectory_spec(*system, DatasetOptions{}, 0); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  ::testing::AllOf(HasSubstr("toy.toml:5:"), HasSubstr("widen initial.energy"))));
}

TEST(PhDatasetTest, VersionTwoFileRoundTripsWithNamesAndTheSystemText) {
  DatasetOptions options;
  options.num_validation = 5;
  options.num_inference = 2;
  const auto system = load_system_file(shipped("coupled-duffing"));
  const PhSystemData data = make_ph_system_data(*system, options, 3);
  const std::string path = ::testing::TempDir() + "ph_dataset_roundtrip.h5";
  write_ph_dataset_file(path, data);
  const PhSystemData back = read_ph_dataset_file(path);
  EXPECT_EQ(back.system_name, "coupled-duffing");
  EXPECT_EQ(back.system_text, system->source_text());
  EXPECT_EQ(back.state_names, data.state_names);
  EXPECT_EQ(back.state_units, data.state_units);
  EXPECT_EQ(back.n_w, 2);
  ASSERT_EQ(back.train.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.train.x[i], data.train.x[i]);
    EXPECT_EQ(back.train.x_next[i], data.train.x_next[i]);
    EXPECT_EQ(back.train.u[i], data.train.u[i]);
  }
  EXPECT_EQ(back.inference.states[1], data.inference.states[1]);
  EXPECT_TRUE(is_dataset_file(path));
  // The built-in reader names the version instead of failing on a missing attribute.
  EXPECT_THAT([&] { read_dataset_file(path); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("format_version 2")));
  std::remove(path.c_str());
}

// Damaged or hand-made files: more states than the vectors hold (40 names),
// and a dataset shorter than its names say, are refused before anything
// is indexed (no write past a fixed-capacity vector).
TEST(PhDatasetTest, DamagedFilesAreRefusedBeforeAnythingIsIndexed) {
  DatasetOptions options;
  options.num_validation = 5;
  options.num_inference = 2;
  const auto system = load_system_file(shipped("pendulum"));
  const std::string path = ::testing::TempDir() + "ph_dataset_damaged.h5";
  std::string names = "q0";
  for (int i = 1; i < 40; ++i) names += ",q" + std::to_string(i);
  write_ph_dataset_file(path, make_ph_system_data(*system, options, 3));
  h5::File::open(path, h5::Access::kReadWrite).set_attribute("/", "state_names", names);
  EXPECT_THAT([&] { read_ph_dataset_file(path); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  AllOf(HasSubstr("40 states"), HasSubstr("not a data set phnn can read"))));
  write_ph_dataset_file(path, make_ph_system_data(*system, options, 3));
  h5::File::open(path, h5::Access::kReadWrite).set_attribute("/", "state_names", std::string("q,p,r"));
  EXPECT_THAT([&] { read_ph_dataset_file(path); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  AllOf(HasSubstr("/train/x: 6 values where 3 rows of 3"), HasSubstr("damaged"))));
  std::remove(path.c_str());
}

}  // namespace
}  // namespace phnn
