// tests/data/measured_test.cpp — recorded trajectories into data sets: a
// generated set written as CSV and read back is the same set bit for bit;
// the split keeps training, validation and inference trajectories apart;
// pair windows, shuffles and cuts; measurement noise. Malformed inputs:
// tests/data/trajectory_files_test.cpp.
#include "phnn/data/measured.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include "phnn/store/ph_dataset_file.h"
#include "phnn/store/trajectory_files.h"
#include "phnn/systems/system_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::unique_ptr<PhSystem> pendulum() { return testing_util::shipped_system("pendulum"); }

DatasetOptions small_options() {
  DatasetOptions o;
  o.num_train_max = 6;
  o.num_validation = 7;
  o.num_inference = 3;
  o.beta = 1.0;  // 100 inference steps
  return o;
}

void expect_same_pairs(const PhPairSet& a, const PhPairSet& b) {
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.x_next, b.x_next);
  EXPECT_EQ(a.u, b.u);
  EXPECT_EQ(a.trajectory, b.trajectory);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.step, b.step);
}

// The acceptance's round trip in memory: generate, write the trajectories
// as CSV, read them, split them: the same pairs and inference trajectories,
// bit for bit (the pair draws share their key; t = n / 100 gives h = 0.01).
TEST(MeasuredDataTest, AGeneratedSetWrittenAsCsvAndImportedIsTheSameSet) {
  for (const char* name : {"pendulum", "pendulum-forced"}) {
  const auto system = testing_util::shipped_system(name);
  const PhSystemData data = make_ph_system_data(*system, small_options(), 4);
  const std::string csv =
      ::testing::TempDir() + std::to_string(::getpid()) + "_phnn_measured_roundtrip.csv";
  const TrajectoryColumns columns{system->state_names(), system->input_names()};
  write_trajectory_csv(csv, columns, generated_trajectories(*system, data), "test");
  EXPECT_TRUE(is_phnn_trajectory_csv(csv));
  ImportOptions o;
  o.num_validation = 7;
  o.num_inference = 3;
  std::string summary;
  const PhSystemData back = split_measured_data(*system, read_trajectory_csv(csv, columns), o, &summary);
  EXPECT_THAT(summary, HasSubstr("sample rate 100 Hz (from t)"));
  expect_same_pairs(back.train, data.train);
  expect_same_pairs(back.validation, data.validation);
  EXPECT_EQ(back.inference.states, data.inference.states);
  EXPECT_EQ(back.inference.u, data.inference.u);
  EXPECT_EQ(back.inference.inputs, data.inference.inputs);  // the forced pendulum's per sample
  EXPECT_EQ(back.inference.inputs.empty(), std::string(name) == "pendulum");
  EXPECT_EQ(back.inference.trajectory, data.inference.trajectory);
  EXPECT_EQ(back.inference.step, data.inference.step);
  EXPECT_EQ(back.system_text, system->source_text());
  EXPECT_EQ(data_set_checksum(back), data_set_checksum(data)) << name;
  std::remove(csv.c_str());
  }
}

// Synthetic recordings: trajectory id k has `samples` samples at 50 Hz,
// q = k + t, p = -t, u = 0.1 k.
std::vector<MeasuredTrajectory> recordings(int count, int samples) {
  std::vector<MeasuredTrajectory> all;
  for (int k = count - 1; k >= 0; --k) {  // out of order: the split sorts by id
    MeasuredTrajectory m(/*n_x=*/2, /*n_u=*/1);
    m.id = 10 * k;
    m.source = "rec.csv";
    for (int n = 0; n < samples + k % 3; ++n) {
      const double t = n / 50.0;
      const double x[2] = {k + t, -t}, u = 0.1 * k;
      m.add(t, x, &u);
    }
    all.push_back(std::move(m));
  }
  return all;
}

std::set<std::int64_t> ids(const std::vector<std::int64_t>& v) { return {v.begin(), v.end()}; }

TEST(MeasuredDataTest, SplitKeepsTheRolesApartAndCutsInferenceToTheShortest) {
  const auto system = pendulum();
  ImportOptions o;
  o.num_validation = 4;
  o.num_inference = 3;
  for (std::int64_t split_seed : {-1, 0, 7}) {
    o.split_seed = split_seed;
    const PhSystemData d = split_measured_data(*system, recordings(12, 20), o);
    const auto train = ids(d.train.trajectory), val = ids(d.validation.trajectory),
               inf = ids(d.inference.trajectory);
    EXPECT_EQ(train.size() + val.size() + inf.size(), 12u);
    std::set<std::int64_t> all = train;
    all.insert(val.begin(), val.end());
    all.insert(inf.begin(), inf.end());
    EXPECT_EQ(all.size(), 12u) << "a trajectory serves two roles";
    std::size_t shortest = 1000;
    for (std::int64_t id : inf) shortest = std::min<std::size_t>(shortest, 20 + (id / 10) % 3);
    for (const auto& states : d.inference.states) EXPECT_EQ(states.size(), shortest);
    EXPECT_DOUBLE_EQ(d.train.step, 0.02);
    for (std::size_t i = 0; i < d.train.size(); ++i) {
      const double k = static_cast<double>(d.train.trajectory[i] / 10);
      const double t = d.train.position[i] / 50.0;  // x_n is the sample at its position
      EXPECT_DOUBLE_EQ(d.train.x[i](0), k + t);
      EXPECT_DOUBLE_EQ(d.train.x_next[i](1), -(d.train.position[i] + 1) / 50.0);
      EXPECT_DOUBLE_EQ(d.train.u[i](0), 0.1 * k);
    }
    if (split_seed < 0) {  // in id order: the last three ids infer
      EXPECT_EQ(inf, (std::set<std::int64_t>{90, 100, 110}));
      EXPECT_EQ(train, (std::set<std::int64_t>{0, 10, 20, 30, 40}));
    }
  }
  o.split_seed = 7;
  const PhSystemData a = split_measured_data(*system, recordings(12, 20), o);
  o.split_seed = 8;
  const PhSystemData b = split_measured_data(*system, recordings(12, 20), o);
  EXPECT_NE(ids(a.inference.trajectory), ids(b.inference.trajectory));  // 220 choices
}

TEST(MeasuredDataTest, PairWindowLimitsWherePairsAreDrawn) {
  const auto system = pendulum();
  ImportOptions o;
  o.num_validation = 2;
  o.num_inference = 1;
  o.pair_window = 0.1;  // t_n+1 <= 0.1 s at 50 Hz: n + 1 <= 5
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    o.data_seed = seed;
    const PhSystemData d = split_measured_data(*system, recordings(8, 40), o);
    for (int n : d.train.position) EXPECT_LE(n, 4);
    for (int n : d.validation.position) EXPECT_LE(n, 4);
  }
  o.pair_window = 0.01;  // shorter than one step
  EXPECT_THROW(
      {
        try {
          split_measured_data(*system, recordings(8, 40), o);
        } catch (const MeasuredDataError& e) {
          EXPECT_THAT(e.what(), HasSubstr("widen the window"));
          throw;
        }
      },
      MeasuredDataError);
}

// Measurement noise: N(0, sigma_j^2) on the pairs only, sigma_j = level x
// the clean pairs' spread of state j, each trajectory's draws its own.
TEST(MeasuredDataTest, NoiseIsGaussianWithTheAskedSigmaOnThePairsOnly) {
  const auto system = pendulum();
  DatasetOptions o = small_options();
  o.num_validation = 500;
  const PhSystemData clean = make_ph_system_data(*system, o, 6);
  PhSystemData noisy = clean;
  NoiseOptions noise;
  noise.levels = {0.01, 0.05};
  const std::vector<double> sigma = add_measurement_noise(&noisy, system->rng_id(), noise);
  ASSERT_EQ(sigma.size(), 2u);
  EXPECT_THAT(noisy.noise, AllOf(HasSubstr("relative levels 0.01 0.05"), HasSubstr("inference clean")));
  for (int j = 0; j < 2; ++j) {
    // The spread, independently: standard deviation of x_j over the validation pairs.
    std::vector<double> v;
    for (const VecX& x : clean.validation.x) v.push_back(x(j));
    double mean = 0, var = 0;
    for (double x : v) mean += x / static_cast<double>(v.size());
    for (double x : v) var += (x - mean) * (x - mean) / static_cast<double>(v.size() - 1);
    EXPECT_NEAR(sigma[static_cast<std::size_t>(j)], noise.levels[static_cast<std::size_t>(j)] * std::sqrt(var), 1e-12);
    // Standardized errors: mean ~ 0 (SE 0.03 for ~1000), std ~ 1 (SE 0.022).
    std::vector<double> z;
    for (int split = 0; split < 2; ++split) {
      const PhPairSet& c = split ? clean.validation : clean.train;
      const PhPairSet& n = split ? noisy.validation : noisy.train;
      for (std::size_t i = 0; i < c.size(); ++i) {
        z.push_back((n.x[i](j) - c.x[i](j)) / sigma[static_cast<std::size_t>(j)]);
        z.push_back((n.x_next[i](j) - c.x_next[i](j)) / sigma[static_cast<std::size_t>(j)]);
      }
    }
    double zm = 0, zv = 0;
    for (double x : z) zm += x / static_cast<double>(z.size());
    for (double x : z) zv += (x - zm) * (x - zm) / static_cast<double>(z.size() - 1);
    EXPECT_LT(std::abs(zm), 0.15) << "state " << j;
    EXPECT_NEAR(std::sqrt(zv), 1.0, 0.1) << "state " << j;
  }
  EXPECT_EQ(noisy.inference.states, clean.inference.states);
  // A trajectory's noise depends on its index only: fewer training pairs
  // keep the same noisy pairs.
  PhSystemData fewer = make_ph_system_data(*system, o, 3);
  add_measurement_noise(&fewer, system->rng_id(), noise);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(fewer.train.x[i], noisy.train.x[i]);
  EXPECT_EQ(fewer.validation.x_next, noisy.validation.x_next);
  EXPECT_NE(data_set_checksum(noisy), data_set_checksum(clean));
  NoiseOptions wrong;
  wrong.levels = {0.1};
  EXPECT_THROW(add_measurement_noise(&fewer, system->rng_id(), wrong), std::invalid_argument);
}

}  // namespace
}  // namespace phnn
