// tests/data/dataset_test.cpp — the data-set options, the paper's three
// systems' data (Algorithms 1-4, splits, counter-based draws) against the
// closed forms of the Oscillator class, and the built-in alias table.
#include "phnn/data/dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

#include "phnn/data/ph_dataset.h"
#include "phnn/systems/system_file.h"
#include "reference/oscillator.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(DatasetOptionsTest, DerivedCountsFollowSpec) {
  const DatasetOptions o;
  EXPECT_EQ(o.stride(), 4);                // 400 Hz -> 100 Hz
  EXPECT_EQ(o.num_pair_positions(), 31);   // t_{n+1} = (n+1)/100 <= 0.31
  EXPECT_EQ(o.num_inference_steps(), 500); // 5 s at 100 Hz
  EXPECT_EQ(o.validation_begin(), 400);
  EXPECT_EQ(o.inference_begin(), 2900);
}

// The paper's three systems (their shipped files), checked against the
// closed forms of the Oscillator class.
std::unique_ptr<PhSystem> paper_system(SystemKind kind, const DatasetOptions& o = {}) {
  return builtin_system(OscillatorOptions::defaults(kind), o);
}
Vec2 v2(const VecX& x) { return Vec2(x(0), x(1)); }

TEST(DatasetTest, InitialEnergiesLieInTheSpecifiedInterval) {
  const DatasetOptions o;
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    const auto system = paper_system(kind);
    for (std::int64_t i = 0; i < 2000; ++i) {
      const double e0 = osc.hamiltonian(v2(ph_trajectory_spec(*system, o, i).x0));
      ASSERT_GE(e0, 0.1) << to_string(kind) << " #" << i;
      ASSERT_LE(e0, 1.0) << to_string(kind) << " #" << i;
      if (kind != SystemKind::kDuffing) {
        // Algorithm 1 as written: E0 = sqrt(r) >= sqrt(0.1).
        ASSERT_GE(e0, std::sqrt(0.1) - 1e-12);
      }
    }
  }
}

// energy_sampling = direct takes E0 = r instead of sqrt(r) from the same draw
// r (same stream, same theta): H(x0) is then the square of Algorithm 1's and
// spans I_E0 = [0.1, 1]; Duffing (Algorithm 2) is unchanged, as are the inputs.
TEST(DatasetTest, DirectEnergySamplingSquaresAlgorithmOnesInitialEnergy) {
  DatasetOptions direct;
  direct.energy_sampling = EnergySampling::kDirect;
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    const auto system = paper_system(kind);
    double lowest = 1.0;
    for (std::int64_t i = 0; i < 2000; ++i) {
      const PhTrajectorySpec a = ph_trajectory_spec(*system, DatasetOptions(), i);
      const PhTrajectorySpec d = ph_trajectory_spec(*system, direct, i);
      EXPECT_EQ(d.u, a.u);
      const double h_a = osc.hamiltonian(v2(a.x0)), h_d = osc.hamiltonian(v2(d.x0));
      if (kind == SystemKind::kDuffing) {
        ASSERT_EQ(d.x0, a.x0) << i;
        continue;
      }
      ASSERT_NEAR(h_d, h_a * h_a, 1e-14) << to_string(kind) << " #" << i;
      ASSERT_GE(h_d, 0.1 - 1e-14);
      ASSERT_LE(h_d, 1.0 + 1e-14);
      // Same angle: x0 is scaled by sqrt(E0_direct / E0_alg1) = r^(1/4).
      EXPECT_NEAR(d.x0(0) * a.x0(1), d.x0(1) * a.x0(0), 1e-14);
      lowest = std::min(lowest, h_d);
    }
    if (kind != SystemKind::kDuffing) {
      EXPECT_LT(lowest, std::sqrt(0.1)) << to_string(kind);
    }
  }
}

TEST(DatasetTest, ControlledEquilibriaHaveEnergyInInterval) {
  const DatasetOptions o;
  for (SystemKind kind : {SystemKind::kHarmonic, SystemKind::kDuffing}) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    const auto system = paper_system(kind);
    int negative = 0;
    for (std::int64_t i = 0; i < 2000; ++i) {
      const double u = ph_trajectory_spec(*system, o, i).u(0);
      const Vec2 xs = osc.equilibrium(u);
      EXPECT_LT(osc.vector_field(xs, u).norm(), 1e-10);
      const double e = osc.hamiltonian(xs);
      ASSERT_GE(e, 0.1 - 1e-12);
      ASSERT_LE(e, 1.0 + 1e-12);
      negative += xs(0) < 0;
    }
    // Sign of q* drawn +-1 with equal probability: 1000 +- 5 sigma (~112).
    EXPECT_NEAR(negative, 1000, 112);
  }
}

TEST(DatasetTest, SelfSustainedControlsPutEquilibriumInSelfOscillationRange) {
  const DatasetOptions o;
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kSelfSustained));
  const auto system = paper_system(SystemKind::kSelfSustained);
  const auto iw = osc.self_oscillation_interval();
  for (std::int64_t i = 0; i < 1000; ++i) {
    const double w_star = -ph_trajectory_spec(*system, o, i).u(0);
    ASSERT_GT(w_star, iw[0]);
    ASSERT_LT(w_star, iw[1]);
    EXPECT_LT(osc.dissipation_derivative(w_star), 0.0);
  }
}

TEST(DatasetTest, TrajectoryIsBitIdenticalAloneOrAmongOthers) {
  const DatasetOptions o;
  for (SystemKind kind : all_systems()) {
    const auto system = paper_system(kind);
    const PhTrajectory alone = ph_generate_trajectory(*system, o, 7, 200);
    const PhPairSet among = ph_make_pairs(*system, o, 0, 20);
    const PhTrajectory again = ph_generate_trajectory(*system, o, 7, 200);
    ASSERT_EQ(alone.states.size(), again.states.size());
    for (std::size_t n = 0; n < alone.states.size(); ++n) {
      ASSERT_EQ(alone.states[n], again.states[n]);
    }
    // Pair 7 of the batch is a sample of the lone trajectory, bit for bit.
    const int pos = among.position[7];
    EXPECT_EQ(among.x[7], alone.states[static_cast<std::size_t>(4 * pos)]);
    EXPECT_EQ(among.x_next[7], alone.states[static_cast<std::size_t>(4 * pos + 4)]);
    EXPECT_EQ(among.u[7], alone.u);
    // And does not depend on how many pairs are drawn.
    const PhPairSet fewer = ph_make_pairs(*system, o, 7, 1);
    EXPECT_EQ(fewer.x[0], among.x[7]);
  }
}

TEST(DatasetTest, DataSeedChangesTheData) {
  DatasetOptions a, b;
  b.data_seed = 1;
  const auto system = paper_system(SystemKind::kDuffing);
  EXPECT_NE(ph_trajectory_spec(*system, a, 3).x0, ph_trajectory_spec(*system, b, 3).x0);
}

TEST(DatasetTest, PairsRespectTrainingHorizonAndCoverIt) {
  const DatasetOptions o;
  const PhPairSet pairs = ph_make_pairs(*paper_system(SystemKind::kHarmonic), o, 0, 400);
  ASSERT_EQ(pairs.size(), 400u);
  std::set<int> seen;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    EXPECT_LE((pairs.position[i] + 1) * pairs.step, o.alpha * o.period + 1e-12);
    EXPECT_EQ(pairs.trajectory[i], static_cast<std::int64_t>(i));
    seen.insert(pairs.position[i]);
  }
  EXPECT_EQ(*seen.begin(), 0);
  EXPECT_EQ(*seen.rbegin(), 30);
  EXPECT_DOUBLE_EQ(pairs.step, 0.01);
}

TEST(DatasetTest, SplitsAreDisjointAndSized) {
  DatasetOptions o;
  o.num_validation = 30;  // keep the test quick; the index ranges are what matter
  o.num_inference = 3;
  const PhSystemData data = make_ph_system_data(*paper_system(SystemKind::kHarmonic), o, 25);
  std::set<std::int64_t> ids(data.train.trajectory.begin(), data.train.trajectory.end());
  for (auto i : data.validation.trajectory) EXPECT_TRUE(ids.insert(i).second);
  for (auto i : data.inference.trajectory) EXPECT_TRUE(ids.insert(i).second);
  EXPECT_EQ(data.validation.trajectory.front(), 400);
  EXPECT_EQ(data.inference.trajectory.front(), 430);
  ASSERT_EQ(data.inference.states.size(), 3u);
  EXPECT_EQ(data.inference.states[0].size(), 501u);
}

TEST(DatasetTest, InferenceTrajectoriesAreSubsampledGeneratorOutput) {
  DatasetOptions o;
  o.num_inference = 2;
  const auto system = paper_system(SystemKind::kDuffing);
  const PhInferenceSet inf = ph_inference_set(*system, o);
  const PhTrajectory full = ph_generate_trajectory(*system, o, inf.trajectory[1], 2000);
  for (int n = 0; n <= 500; n += 50) {
    EXPECT_EQ(inf.states[1][static_cast<std::size_t>(n)], full.states[static_cast<std::size_t>(4 * n)]);
  }
}

// [physics.*] values and [data] energies are written into the shipped file's
// text by the alias table, and read back from it; the defaults give the
// shipped text byte for byte.
TEST(BuiltinSystemsTest, AliasTableWritesAndReadsEveryParameter) {
  for (SystemKind kind : all_systems()) {
    const OscillatorOptions defaults = OscillatorOptions::defaults(kind);
    const std::string shipped = shipped_systems_dir() + "/" + to_string(kind) + ".toml";
    EXPECT_EQ(builtin_system_text(defaults, BuiltinEnergies{}), read_system_file_text(shipped));
    OscillatorOptions p = defaults;
    p.mass = 0.2;
    p.stiffness = 7.5;
    p.cubic_stiffness = 300.0;
    p.damping = 0.9;
    p.z_coefficients = {2.5, -3.5, 1.25};
    BuiltinEnergies e;
    e.initial = {0.2, 0.8};
    e.equilibrium = {0.3, 0.6};
    const std::string text = builtin_system_text(p, e);
    const OscillatorOptions back = builtin_physics(text, "test");
    for (const BuiltinAlias& a : builtin_aliases(kind)) {
      const double want = a.field ? p.*a.field : p.z_coefficients[static_cast<std::size_t>(a.z_index)];
      const double got = a.field ? back.*a.field : back.z_coefficients[static_cast<std::size_t>(a.z_index)];
      EXPECT_EQ(got, want) << to_string(kind) << " " << a.physics_key << " -> " << a.parameter;
    }
    const auto system = compile_system(text, "test");
    EXPECT_EQ(system->initial_design().energy_min, 0.2);
    EXPECT_EQ(system->initial_design().energy_max, 0.8);
    if (kind != SystemKind::kSelfSustained) {
      EXPECT_EQ(system->control_design().equilibrium_energy_min, 0.3);
      EXPECT_EQ(system->control_design().equilibrium_energy_max, 0.6);
    }
    // The compiled system is the Oscillator of those parameters.
    const Oscillator osc(p);
    VecX x(2);
    x << 0.3, -0.2;
    EXPECT_NEAR(system->hamiltonian(x), osc.hamiltonian(v2(x)), 1e-15);
    EXPECT_NEAR((system->vector_field(x, VecX::Constant(1, 0.1)) - VecX(osc.vector_field(v2(x), 0.1))).norm(),
                0.0, 1e-13);
  }
}

// A shipped file that no longer defines the paper's system is refused,
// naming the file and the fix; the user's copy under another name is fine.
TEST(BuiltinSystemsTest, AChangedShippedFileIsRefused) {
  const std::string dir =
      ::testing::TempDir() + std::to_string(::getpid()) + "_phnn_shipped_changed";
  std::filesystem::create_directories(dir);
  std::string text = read_system_file_text(shipped_systems_dir() + "/duffing.toml");
  text.replace(text.find("k3*q^4/4"), 8, "k3*q^6/6");
  std::ofstream(dir + "/duffing.toml") << text;
  ::setenv("PHNN_SYSTEMS_DIR", dir.c_str(), 1);
  EXPECT_THAT([] { make_system("duffing"); },
              ThrowsMessage<SystemFileError>(AllOf(HasSubstr(dir + "/duffing.toml"), HasSubstr("H or z"),
                                                   HasSubstr("restore it"))));
  // A file without the key a sweep's value goes to: refused, not written
  // over another line.
  text = read_system_file_text(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/duffing.toml");
  const std::string control_energy = "design = \"energy-shaping\"\nenergy = [0.1, 1.0]";
  ASSERT_NE(text.find(control_energy), std::string::npos);
  text.replace(text.find(control_energy), control_energy.size(), "design = \"energy-shaping\"");
  std::ofstream(dir + "/duffing.toml") << text;
  BuiltinEnergies e;
  e.equilibrium = {0.3, 0.6};
  EXPECT_THAT([&] { builtin_system(OscillatorOptions::defaults(SystemKind::kDuffing), e); },
              ThrowsMessage<SystemFileError>(AllOf(HasSubstr("no control.energy"), HasSubstr("restore it"))));
  ::unsetenv("PHNN_SYSTEMS_DIR");
  std::filesystem::remove_all(dir);
}

TEST(DatasetOptionsTest, RejectsBadOptionsNamingTheField) {
  DatasetOptions o;
  o.generation_step = -1.0;
  EXPECT_THAT([&] { o.validate(); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("generation_step = -1")));
  DatasetOptions p;
  p.sample_rate = 150.0;  // 400 / 150 is not an integer
  EXPECT_THAT([&] { p.validate(); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("not a positive integer")));
  const auto system = paper_system(SystemKind::kHarmonic);
  EXPECT_THAT([&] { make_ph_system_data(*system, DatasetOptions{}, 401); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("n_train = 401")));
  EXPECT_THAT([&] { ph_generate_trajectory(*system, DatasetOptions{}, 0, -5); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("num_steps = -5")));
}

}  // namespace
}  // namespace phnn
