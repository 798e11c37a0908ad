// tests/data/ph_dataset_test.cpp — data sets of system files: the paper's
// three follow the closed-form discrete gradient, their figure trajectories
// start at their energies, every stored step of the other systems satisfies
// the discrete power balance, and the version-2 data-set file round-trips.
#include "phnn/data/ph_dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "h5/h5file.h"
#include "phnn/integrators/ph_steps.h"
#include "phnn/store/dataset_file.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/system_file.h"
#include "reference/discrete_gradient.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::string shipped(const std::string& name) {
  return std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name + ".toml";
}

// The closed-form 2-state discrete gradient (integrators/discrete_gradient.h,
// the Oscillator class: an implementation independent of the system files'
// compiled expressions and generic Gonzalez quotient) from x0 under u.
std::vector<Vec2> closed_form_trajectory(SystemKind kind, const DatasetOptions& options,
                                         const VecX& x0, double u, int steps) {
  const Oscillator osc(OscillatorOptions::defaults(kind));
  std::vector<Vec2> out = {Vec2(x0(0), x0(1))};
  for (int n = 0; n < steps; ++n) {
    const auto step = discrete_gradient_step(osc, out.back(), u, options.generation_step, options.newton);
    EXPECT_EQ(step.status, StepStatus::kConverged);
    out.push_back(step.x_next);
  }
  return out;
}

double max_diff(const std::vector<Vec2>& a, const std::vector<VecX>& b) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    for (int j = 0; j < 2; ++j) worst = std::max(worst, std::abs(a[i](j) - b[i](j)));
  }
  return worst;
}

// The paper's three systems, generated from their shipped files, follow the
// closed-form discrete gradient to <= 1e-12 over whole 2000-step trajectories
// (training, validation and inference indices).
TEST(PhDatasetTest, BuiltInTrajectoriesFollowTheClosedFormDiscreteGradient) {
  const DatasetOptions options;
  for (SystemKind kind : all_systems()) {
    const auto system = make_system(to_string(kind));
    double worst = 0.0;
    for (std::int64_t index : {0, 401, 2950}) {
      const PhTrajectory traj = ph_generate_trajectory(*system, options, index, 2000);
      worst = std::max(worst, max_diff(closed_form_trajectory(kind, options, traj.states[0], traj.u(0), 2000),
                                       traj.states));
    }
    EXPECT_LE(worst, 1e-12) << to_string(kind);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", worst);
    RecordProperty("file_vs_closed_form_" + to_string(kind), buf);
  }
}

// The figure trajectories of the paper's systems: H(x0) = 0.5 and 0.75 J on
// the q axis (closed form: k q^2 / 2 + k3 q^4 / 4 = E), u = 0 or the middle
// of I_w, and the closed-form trajectory sub-sampled to sr_infer.
TEST(PhDatasetTest, PaperFigureTrajectoriesStartAtTheirEnergies) {
  DatasetOptions options;
  for (SystemKind kind : all_systems()) {
    const OscillatorOptions p = OscillatorOptions::defaults(kind);
    const auto system = make_system(to_string(kind));
    const PhInferenceSet figures = ph_figure_set(*system, options);
    ASSERT_EQ(figures.size(), 2u);
    const double u = kind == SystemKind::kSelfSustained
                         ? -0.5 * (Oscillator(p).self_oscillation_interval()[0] +
                                   Oscillator(p).self_oscillation_interval()[1])
                         : 0.0;
    for (std::size_t k = 0; k < 2; ++k) {
      const double e = k == 0 ? 0.5 : 0.75;
      const double b = 0.5 * p.stiffness, a = kind == SystemKind::kDuffing ? 0.25 * p.cubic_stiffness : 0.0;
      const double q0 = std::sqrt(2.0 * e / (b + std::sqrt(b * b + 4.0 * a * e)));
      EXPECT_NEAR(figures.states[k][0](0), q0, 2e-15 * q0) << to_string(kind);
      EXPECT_EQ(figures.states[k][0](1), 0.0);
      EXPECT_NEAR(figures.u[k](0), u, 1e-15);
      const auto ref = closed_form_trajectory(kind, options, figures.states[k][0], figures.u[k](0), 2000);
      std::vector<Vec2> sub;
      for (std::size_t n = 0; n < ref.size(); n += 4) sub.push_back(ref[n]);
      EXPECT_LE(max_diff(sub, figures.states[k]), 1e-12) << to_string(kind);
    }
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
  const std::string path =
      ::testing::TempDir() + std::to_string(::getpid()) + "_ph_dataset_roundtrip.h5";
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
  // A version this phnn does not know is named, not misread.
  h5::File::open(path, h5::Access::kReadWrite).set_attribute("/", "format_version", std::int64_t{3});
  EXPECT_THAT([&] { read_ph_dataset_file(path); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("format_version 3")));
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
  const std::string path =
      ::testing::TempDir() + std::to_string(::getpid()) + "_ph_dataset_damaged.h5";
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

// A stop asked between trajectories ends the generation (every 64th
// trajectory asks): the sweep's graceful stop during a long data set. Without
// a stop, or one that says no, the same data as ever.
TEST(PhDatasetTest, AStopEndsALongGenerationBetweenTrajectories) {
  const auto system = load_system_file(shipped("duffing"));
  DatasetOptions o;
  int asked = 0;
  const GenerationStop stop_at_third = [&asked] { return ++asked == 3; };
  EXPECT_THROW(make_ph_system_data(*system, o, 25, stop_at_third), GenerationStopped);
  EXPECT_EQ(asked, 3);
  const GenerationStop never = [] { return false; };
  const PhSystemData a = make_ph_system_data(*system, o, 25, never);
  const PhSystemData b = make_ph_system_data(*system, o, 25);
  EXPECT_EQ(a.validation.x, b.validation.x);
  EXPECT_EQ(a.inference.states, b.inference.states);
}

}  // namespace
}  // namespace phnn
