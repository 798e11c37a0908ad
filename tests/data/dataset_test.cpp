// tests/data/dataset_test.cpp
#include "phnn/data/dataset.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace phnn {
namespace {

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

TEST(DatasetTest, InitialEnergiesLieInTheSpecifiedInterval) {
  const DatasetOptions o;
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    for (std::int64_t i = 0; i < 2000; ++i) {
      const double e0 = osc.hamiltonian(trajectory_spec(osc, o, i).x0);
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
    double lowest = 1.0;
    for (std::int64_t i = 0; i < 2000; ++i) {
      const TrajectorySpec a = trajectory_spec(osc, DatasetOptions(), i);
      const TrajectorySpec d = trajectory_spec(osc, direct, i);
      EXPECT_EQ(d.u, a.u);
      const double h_a = osc.hamiltonian(a.x0), h_d = osc.hamiltonian(d.x0);
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
    int negative = 0;
    for (std::int64_t i = 0; i < 2000; ++i) {
      const double u = trajectory_spec(osc, o, i).u;
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
  const auto iw = osc.self_oscillation_interval();
  for (std::int64_t i = 0; i < 1000; ++i) {
    const double w_star = -trajectory_spec(osc, o, i).u;
    ASSERT_GT(w_star, iw[0]);
    ASSERT_LT(w_star, iw[1]);
    EXPECT_LT(osc.dissipation_derivative(w_star), 0.0);
  }
}

TEST(DatasetTest, TrajectoryIsBitIdenticalAloneOrAmongOthers) {
  const DatasetOptions o;
  for (SystemKind kind : all_systems()) {
    const Oscillator osc(OscillatorOptions::defaults(kind));
    const Trajectory alone = generate_trajectory(osc, o, 7, 200);
    const PairSet among = make_pairs(osc, o, 0, 20);
    const Trajectory again = generate_trajectory(osc, o, 7, 200);
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
    const PairSet fewer = make_pairs(osc, o, 7, 1);
    EXPECT_EQ(fewer.x[0], among.x[7]);
  }
}

TEST(DatasetTest, DataSeedChangesTheData) {
  DatasetOptions a, b;
  b.data_seed = 1;
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kDuffing));
  EXPECT_NE(trajectory_spec(osc, a, 3).x0, trajectory_spec(osc, b, 3).x0);
}

TEST(DatasetTest, PairsRespectTrainingHorizonAndCoverIt) {
  const DatasetOptions o;
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kHarmonic));
  const PairSet pairs = training_pairs(osc, o, 400);
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
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kHarmonic));
  const PairSet train = training_pairs(osc, o, 25);
  const PairSet val = validation_pairs(osc, o);
  const InferenceSet inf = inference_set(osc, o);
  std::set<std::int64_t> ids(train.trajectory.begin(), train.trajectory.end());
  for (auto i : val.trajectory) EXPECT_TRUE(ids.insert(i).second);
  for (auto i : inf.trajectory) EXPECT_TRUE(ids.insert(i).second);
  EXPECT_EQ(val.trajectory.front(), 400);
  EXPECT_EQ(inf.trajectory.front(), 430);
  ASSERT_EQ(inf.states.size(), 3u);
  EXPECT_EQ(inf.states[0].size(), 501u);
}

TEST(DatasetTest, InferenceTrajectoriesAreSubsampledGeneratorOutput) {
  DatasetOptions o;
  o.num_inference = 2;
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kDuffing));
  const InferenceSet inf = inference_set(osc, o);
  const Trajectory full = generate_trajectory(osc, o, inf.trajectory[1], 2000);
  for (int n = 0; n <= 500; n += 50) {
    EXPECT_EQ(inf.states[1][static_cast<std::size_t>(n)], full.states[static_cast<std::size_t>(4 * n)]);
  }
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
  const Oscillator osc(OscillatorOptions::defaults(SystemKind::kHarmonic));
  EXPECT_THAT([&] { training_pairs(osc, DatasetOptions{}, 401); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("n_train = 401")));
  EXPECT_THAT([&] { generate_trajectory(osc, DatasetOptions{}, 0, -5); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("num_steps = -5")));
}

}  // namespace
}  // namespace phnn
