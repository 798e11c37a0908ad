// tests/mpi/results_file_mpi_test.cpp — the parallel results file and the
// per-rank journals, run with mpiexec -n 1, 2 and 3 (ctest mpi_np1..3).
#include "phnn/store/results_file.h"

#include <mpi.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/store/journal.h"
#include "sweep/sample_results.h"

namespace phnn {
namespace {

using testing_util::expect_bit_equal;
using testing_util::sample_layout;
using testing_util::sample_result;
using testing_util::sample_runs;
using testing_util::sample_studies;

// 11 rows: not a multiple of 2 or 3, so ranks own different row counts.
constexpr int kNumRuns = 11;
constexpr int kPendingRow = 10;  // never written
constexpr char kSweepHash[] = "00c0ffee00c0ffee";

// MPI_COMM_WORLD's rank and size, and a results path under /tmp made by
// rank 0 and shared by all; rank 0 deletes the file and its journal.
class ResultsFileMpiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    char buffer[256] = {};
    if (rank_ == 0) {
      const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
      std::snprintf(buffer, sizeof buffer, "/tmp/phnn_results_mpi_%d_%lld_%s.h5",
                    static_cast<int>(::getpid()), static_cast<long long>(stamp),
                    ::testing::UnitTest::GetInstance()->current_test_info()->name());
    }
    MPI_Bcast(buffer, sizeof buffer, MPI_CHAR, 0, MPI_COMM_WORLD);
    path_ = buffer;
  }

  void TearDown() override {
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank_ == 0) {
      std::remove(path_.c_str());
      remove_journals(path_);
    }
    MPI_Barrier(MPI_COMM_WORLD);
  }

  ResultsFile create() const {
    return ResultsFile::create(path_, MPI_COMM_WORLD, sample_runs(kNumRuns),
                               sample_studies(kNumRuns), "mpi-demo", "seeds = 0..10\n",
                               kSweepHash, "phnn-sweep test", sample_layout());
  }

  bool mine(int row) const { return row % size_ == rank_; }

  // Rank 0, serially: every written row bit-exact, the pending row pending.
  void expect_every_row() const {
    if (rank_ != 0) return;
    const ResultsFile file = ResultsFile::open_read_only(path_);
    ASSERT_EQ(file.num_runs(), kNumRuns);
    const std::vector<RunStatus> statuses = file.read_statuses();
    const std::vector<RunConfig> runs = sample_runs(kNumRuns);
    const std::vector<std::string> ids = file.read_run_ids();
    for (int row = 0; row < kNumRuns; ++row) {
      SCOPED_TRACE("row " + std::to_string(row) + " of np " + std::to_string(size_));
      EXPECT_EQ(ids[row], runs[row].id());
      if (row == kPendingRow) {
        EXPECT_EQ(statuses[row], RunStatus::kPending);
        continue;
      }
      expect_bit_equal(sample_result(row, sample_layout()), file.read_run(row));
    }
  }

  int rank_ = 0;
  int size_ = 1;
  std::string path_;
};

TEST_F(ResultsFileMpiTest, EachRankWritesItsOwnRowsIndependently) {
  ResultsFile file = create();
  EXPECT_EQ(file.num_runs(), kNumRuns);
  for (int row = 0; row < kNumRuns; ++row) {
    if (mine(row) && row != kPendingRow) file.write_run(row, sample_result(row, sample_layout()));
  }
  file.close();
  MPI_Barrier(MPI_COMM_WORLD);
  expect_every_row();
}

TEST_F(ResultsFileMpiTest, ResumesCollectivelyAndAddsTheMissingRows) {
  {
    ResultsFile file = create();
    for (int row = 0; row < kNumRuns / 2; ++row) {
      if (mine(row)) file.write_run(row, sample_result(row, sample_layout()));
    }
  }  // collective close in the destructor
  ResultsFile file = ResultsFile::open(path_, MPI_COMM_WORLD, kSweepHash);
  EXPECT_EQ(file.sweep_name(), "mpi-demo");
  const std::vector<RunStatus> statuses = file.read_statuses();
  for (int row = 0; row < kNumRuns; ++row) {
    EXPECT_EQ(statuses[row] == RunStatus::kPending, row >= kNumRuns / 2) << "row " << row;
  }
  MPI_Barrier(MPI_COMM_WORLD);  // every rank has read before any writes
  for (int row = kNumRuns / 2; row < kNumRuns; ++row) {
    if (mine(row) && row != kPendingRow) {
      file.write_run(row, sample_result(row, sample_layout()));
    }
  }
  file.close();
  MPI_Barrier(MPI_COMM_WORLD);
  expect_every_row();
}

TEST_F(ResultsFileMpiTest, EveryRankRefusesAnotherSweepsFile) {
  create().close();
  // Policy 1: the same error on every rank, none left in a collective call.
  EXPECT_THAT([&] { ResultsFile::open(path_, MPI_COMM_WORLD, "ffffffffffffffff"); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  ::testing::HasSubstr("was written by sweep 'mpi-demo' (hash 00c0ffee00c0ffee)")));
}

TEST_F(ResultsFileMpiTest, IndependentErrorsNameTheRankAndTheFile) {
  ResultsFile file = create();
  const std::string expected =
      "[rank " + std::to_string(rank_) + "/" + std::to_string(size_) + "] " + path_ + ": ";
  EXPECT_THAT([&] { file.read_double_column("no_such_column"); },
              ::testing::ThrowsMessage<std::runtime_error>(::testing::StartsWith(expected)));
  EXPECT_THAT([&] { file.write_run(kNumRuns, sample_result(0, sample_layout())); },
              ::testing::ThrowsMessage<std::invalid_argument>(::testing::StartsWith(expected)));
}

TEST_F(ResultsFileMpiTest, StoresSystemDataCollectively) {
  DatasetOptions options;
  options.num_validation = 10;
  options.num_inference = 2;
  const PhSystemData data =
      make_ph_system_data(*builtin_system(OscillatorOptions::defaults(SystemKind::kHarmonic), options),
                          options, 25);
  ResultsFile file = create();
  file.store_system_data("harmonic", data);
  EXPECT_TRUE(file.has_system_data("harmonic"));
  EXPECT_FALSE(file.has_system_data("duffing"));
  file.close();
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank_ == 0) {
    const PhSystemData back = ResultsFile::open_read_only(path_).read_system_data("harmonic");
    ASSERT_EQ(back.train.size(), 25u);
    EXPECT_EQ(back.train.x_next[7], data.train.x_next[7]);
    EXPECT_EQ(back.inference.states[1][250], data.inference.states[1][250]);
  }
}

TEST_F(ResultsFileMpiTest, JournalsOfAllRanksReplayToEveryRow) {
  const std::vector<RunConfig> runs = sample_runs(kNumRuns);
  {
    ResultsFile file = create();
    Journal journal(path_, rank_);
    for (int row = 0; row < kNumRuns; ++row) {
      if (mine(row)) journal.append(runs[row].id(), sample_result(row, sample_layout()));
    }
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank_ == 0) {
    int skipped = -1;
    const auto replayed = replay_journals(path_, &skipped);
    EXPECT_EQ(skipped, 0);
    ASSERT_EQ(replayed.size(), static_cast<std::size_t>(kNumRuns));
    for (int row = 0; row < kNumRuns; ++row) {
      expect_bit_equal(sample_result(row, sample_layout()), replayed.at(runs[row].id()));
    }
  }
}

}  // namespace
}  // namespace phnn
