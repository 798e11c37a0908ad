// tests/data/recording_split_test.cpp — long recordings split in time blocks
// (split_in_blocks, include/phnn/data/measured.h): every pair of a block
// once, no sample in two roles, windows inside the inference block, draws
// that depend on the data seed only, errors that name the recording, and
// the data-set file keeping the windows' starts.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <set>
#include <string>
#include <utility>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/data/measured.h"
#include "phnn/store/ph_dataset_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// A recording of n samples at 100 Hz whose sample k is recognisable:
// q = id + k / 1e6, p = -k, u = k (an input that changes every sample).
MeasuredTrajectory recording(std::int64_t id, std::size_t n) {
  MeasuredTrajectory m(2, 1);
  m.id = id;
  m.source = "rec.csv";
  for (std::size_t k = 0; k < n; ++k) {
    const double kd = static_cast<double>(k);
    const double x[2] = {static_cast<double>(id) + kd * 1e-6, -kd};
    const double u[1] = {kd};
    m.add(kd / 100.0, x, u);
  }
  return m;
}

// The sample a state came from: k = -p.
std::size_t sample_of(const VecX& x) { return static_cast<std::size_t>(-x(1)); }

ImportOptions blocks(double window = 0.0) {
  ImportOptions o;
  o.split = ImportSplit::kBlocks;
  o.window = window;
  return o;
}

// One recording of 1 000 samples, blocks 0.6 / 0.2: training samples [0,
// 600), validation [600, 800), inference [800, 1000). Every pair inside a
// block appears once, carries its samples and its input, and no sample
// serves two roles.
TEST(RecordingSplitTest, EveryPairOfABlockOnceAndNoSampleInTwoRoles) {
  const auto system = testing_util::shipped_system("pendulum");
  const PhSystemData d = split_in_blocks(*system, {recording(7, 1000)}, blocks(0.5));
  ASSERT_EQ(d.train.size(), 599u);       // n = 0 .. 598
  ASSERT_EQ(d.validation.size(), 199u);  // n = 600 .. 798
  std::set<std::size_t> train_samples, validation_samples, inference_samples, positions;
  for (std::size_t i = 0; i < d.train.size(); ++i) {
    const std::size_t n = sample_of(d.train.x[i]);
    EXPECT_EQ(static_cast<std::size_t>(d.train.position[i]), n);
    EXPECT_EQ(sample_of(d.train.x_next[i]), n + 1);
    EXPECT_EQ(d.train.u[i](0), static_cast<double>(n));
    EXPECT_EQ(d.train.trajectory[i], 7);
    positions.insert(n);
    train_samples.insert({n, n + 1});
  }
  EXPECT_EQ(positions.size(), 599u);  // each once
  EXPECT_EQ(*train_samples.rbegin(), 599u);
  for (std::size_t i = 0; i < d.validation.size(); ++i) {
    const std::size_t n = sample_of(d.validation.x[i]);
    EXPECT_EQ(sample_of(d.validation.x_next[i]), n + 1);
    validation_samples.insert({n, n + 1});
  }
  EXPECT_EQ(*validation_samples.begin(), 600u);
  EXPECT_EQ(*validation_samples.rbegin(), 799u);
  // Windows of 0.5 s = 51 samples from sample 800: 800, 851, 902 (953 + 51 > 1000).
  ASSERT_EQ(d.inference.size(), 3u);
  EXPECT_EQ(d.inference.position, (std::vector<std::int64_t>{800, 851, 902}));
  for (std::size_t w = 0; w < d.inference.size(); ++w) {
    ASSERT_EQ(d.inference.states[w].size(), 51u);
    ASSERT_EQ(d.inference.inputs[w].size(), 51u);  // u changes: replayed per sample
    for (std::size_t k = 0; k < 51; ++k) {
      const std::size_t n = sample_of(d.inference.states[w][k]);
      EXPECT_EQ(n, static_cast<std::size_t>(d.inference.position[w]) + k);
      EXPECT_EQ(d.inference.inputs[w][k](0), static_cast<double>(n));
      EXPECT_TRUE(inference_samples.insert(n).second) << "sample " << n << " in two windows";
    }
  }
  for (std::size_t n : inference_samples) {
    EXPECT_TRUE(train_samples.count(n) == 0 && validation_samples.count(n) == 0) << n;
  }
  for (std::size_t n : validation_samples) EXPECT_EQ(train_samples.count(n), 0u) << n;
  EXPECT_EQ(d.options.num_train_max, 599);
  EXPECT_EQ(d.options.num_inference, 3);
  EXPECT_DOUBLE_EQ(d.options.beta, 0.5);
  EXPECT_THAT(d.split, HasSubstr("blocks: train 0.6, validation 0.2, inference 0.2"));
}

// The training order is a draw of the data seed (a run's first n_train
// pairs are a uniform draw, nested in n_train), the same on every call;
// another seed draws another order of the same pairs.
TEST(RecordingSplitTest, TrainingOrderDependsOnTheDataSeedOnly) {
  const auto system = testing_util::shipped_system("pendulum");
  const PhSystemData a = split_in_blocks(*system, {recording(1, 500)}, blocks());
  const PhSystemData again = split_in_blocks(*system, {recording(1, 500)}, blocks());
  ImportOptions other = blocks();
  other.data_seed = 3;
  const PhSystemData b = split_in_blocks(*system, {recording(1, 500)}, other);
  EXPECT_EQ(a.train.position, again.train.position);
  EXPECT_EQ(a.train.x, again.train.x);
  EXPECT_NE(a.train.position, b.train.position);
  std::vector<int> sorted_a = a.train.position, sorted_b = b.train.position;
  std::sort(sorted_a.begin(), sorted_a.end());
  std::sort(sorted_b.begin(), sorted_b.end());
  EXPECT_EQ(sorted_a, sorted_b);
  EXPECT_FALSE(std::is_sorted(a.train.position.begin(), a.train.position.end()));
  // The first 25 pairs spread over the block, not its first quarter-second.
  const int late = static_cast<int>(std::count_if(a.train.position.begin(), a.train.position.begin() + 25,
                                                  [](int n) { return n >= 150; }));
  EXPECT_GE(late, 10);
}

// Two recordings (ids 2 and 5, 1 000 and 400 samples): windows are taken
// round-robin (window k of each before window k + 1 of any) up to
// num_inference; more validation pairs than num_validation are a draw, in
// time order; window 0 is the shortest inference block.
TEST(RecordingSplitTest, TwoRecordingsRoundRobinWindowsAndAValidationDraw) {
  const auto system = testing_util::shipped_system("pendulum");
  ImportOptions o = blocks(0.2);  // 21 samples
  o.num_inference = 5;
  o.num_validation = 50;
  const PhSystemData d = split_in_blocks(*system, {recording(5, 400), recording(2, 1000)}, o);
  EXPECT_EQ(d.train.size(), 599u + 239u);
  EXPECT_EQ(d.inference.trajectory, (std::vector<std::int64_t>{2, 5, 2, 5, 2}));
  EXPECT_EQ(d.inference.position, (std::vector<std::int64_t>{800, 320, 821, 341, 842}));
  ASSERT_EQ(d.validation.size(), 50u);
  std::vector<std::pair<std::int64_t, int>> keys;
  for (std::size_t i = 0; i < d.validation.size(); ++i) {
    keys.emplace_back(d.validation.trajectory[i], d.validation.position[i]);
    const int n = d.validation.position[i];
    EXPECT_TRUE(d.validation.trajectory[i] == 2 ? (n >= 600 && n + 1 < 800) : (n >= 240 && n + 1 < 320))
        << d.validation.trajectory[i] << " " << n;
  }
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  const std::set<std::pair<std::int64_t, int>> distinct(keys.begin(), keys.end());
  EXPECT_EQ(distinct.size(), 50u);

  const PhSystemData whole = split_in_blocks(*system, {recording(5, 400), recording(2, 1000)}, blocks());
  ASSERT_EQ(whole.inference.size(), 3u);  // 80 samples: 2 windows of recording 2, 1 of recording 5
  EXPECT_EQ(whole.inference.states[0].size(), 80u);
}

TEST(RecordingSplitTest, ErrorsNameTheRecordingAndTheFix) {
  const auto system = testing_util::shipped_system("pendulum");
  EXPECT_THAT([&] { split_in_blocks(*system, {recording(3, 1000), recording(4, 6)}, blocks()); },
              ::testing::ThrowsMessage<MeasuredDataError>(
                  AllOf(HasSubstr("rec.csv: trajectory 4 has 6 samples"),
                        HasSubstr("every block needs at least 2"), HasSubstr("--blocks"))));
  EXPECT_THAT([&] { split_in_blocks(*system, {recording(3, 1000)}, blocks(5.0)); },
              ::testing::ThrowsMessage<MeasuredDataError>(
                  AllOf(HasSubstr("--window 5 s (501 samples)"), HasSubstr("the longest holds 200"))));
  ImportOptions bad = blocks();
  bad.train_fraction = 0.9;
  bad.validation_fraction = 0.1;
  EXPECT_THROW(split_measured_data(*system, {recording(3, 1000)}, bad), std::invalid_argument);
  bad = blocks();
  bad.pair_window = 0.3;
  EXPECT_THROW(split_measured_data(*system, {recording(3, 1000)}, bad), std::invalid_argument);
}

// The data-set file keeps the windows' starts and the split's description;
// the file of a split by trajectories has neither.
TEST(RecordingSplitTest, TheDataSetFileKeepsTheStartsAndTheSplit) {
  const auto system = testing_util::shipped_system("pendulum");
  const PhSystemData d = split_measured_data(*system, {recording(7, 1000)}, blocks(0.5));
  const std::string path = ::testing::TempDir() + "phnn_recording_split_" + std::to_string(::getpid()) + ".h5";
  write_ph_dataset_file(path, d);
  const PhSystemData back = read_ph_dataset_file(path);
  std::remove(path.c_str());
  EXPECT_EQ(back.inference.position, d.inference.position);
  EXPECT_EQ(back.split, d.split);
  EXPECT_EQ(back.inference.states, d.inference.states);
  EXPECT_EQ(back.train.position, d.train.position);
  EXPECT_EQ(data_set_checksum(back), data_set_checksum(d));
}

}  // namespace
}  // namespace phnn
