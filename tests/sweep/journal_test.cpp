// tests/sweep/journal_test.cpp
#include "phnn/store/journal.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <limits>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "sweep/sample_results.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using testing_util::expect_bit_equal;
using testing_util::sample_layout;
using testing_util::sample_result;
using testing_util::sample_runs;
using testing_util::tagged_nan;

class JournalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    results_path_ = ::testing::TempDir() + "phnn_journal_" + std::to_string(::getpid()) + "_" +
                    ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".h5";
    remove_journals(results_path_);
  }
  void TearDown() override { remove_journals(results_path_); }

  static std::string id(int row) { return sample_runs(row + 1)[row].id(); }

  std::string results_path_;
};

TEST_F(JournalTest, ReplayRoundTripsEveryFieldBitExactly) {
  {
    Journal journal(results_path_, 0);
    for (int row = 0; row < 8; ++row) journal.append(id(row), sample_result(row, sample_layout()));
  }
  int skipped = -1;
  const auto replayed = replay_journals(results_path_, &skipped);
  EXPECT_EQ(skipped, 0);
  ASSERT_EQ(replayed.size(), 8u);
  for (int row = 0; row < 8; ++row) {
    SCOPED_TRACE("row " + std::to_string(row));
    ASSERT_EQ(replayed.count(id(row)), 1u);
    expect_bit_equal(sample_result(row, sample_layout()), replayed.at(id(row)));
  }
}

TEST_F(JournalTest, WritesOneLineWithHexFloatsEscapedStringsAndAChecksum) {
  RunResult r;
  r.status = RunStatus::kFailed;
  r.mse = 1.5;
  r.best_validation_loss = tagged_nan(0x123);
  r.message = "100% bad\nnews";
  const std::string line = internal::encode_journal_record("00ff", r, /*time_ns=*/42);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_THAT(line, ::testing::StartsWith("run 00ff v=1 time=42 status=failed "));
  EXPECT_THAT(line, HasSubstr(" mse=0x1.8p+0 "));
  EXPECT_THAT(line, HasSubstr(" best_validation_loss=nan_7ff8000000000123 "));
  EXPECT_THAT(line, HasSubstr(" message=100%25%20bad%0Anews "));
  EXPECT_THAT(line, ::testing::MatchesRegex(".* fnv1a64=[0-9a-f]{16}"));
  std::string id;
  RunResult back;
  std::int64_t time_ns = 0;
  ASSERT_TRUE(internal::decode_journal_record(line, &id, &back, &time_ns));
  EXPECT_EQ(id, "00ff");
  EXPECT_EQ(time_ns, 42);
  expect_bit_equal(r, back);
  // One changed character fails the checksum.
  std::string corrupt = line;
  corrupt[corrupt.find("0x1.8p+0")] = '1';
  EXPECT_FALSE(internal::decode_journal_record(corrupt, &id, &back, &time_ns));
}

// Checkpoint MSEs and weights survive a crash between the journal record
// and the row write; a record without those fields reads as a run without.
TEST_F(JournalTest, CheckpointsAndWeightsRoundTripAndAreOptional) {
  RunResult r = sample_result(0, sample_layout());
  r.checkpoint_steps = {2500, 5000, 50000};
  r.checkpoint_mse = {0.125, std::numeric_limits<double>::infinity(), tagged_nan(0x7)};
  r.checkpoint_train_seconds = {1.0 / 3.0, 2.5, 40.0};
  r.weights = {0.1, -2.0, tagged_nan(0x9), 1e-300};
  const std::string line = internal::encode_journal_record("0a", r, /*time_ns=*/7);
  EXPECT_THAT(line, HasSubstr(" checkpoint_steps=2500,5000,50000 "));
  std::string id;
  RunResult back;
  std::int64_t time_ns = 0;
  ASSERT_TRUE(internal::decode_journal_record(line, &id, &back, &time_ns));
  expect_bit_equal(r, back);

  const RunResult plain = sample_result(1, sample_layout());
  const std::string plain_line = internal::encode_journal_record("0b", plain, /*time_ns=*/8);
  EXPECT_EQ(plain_line.find("checkpoint"), std::string::npos);
  EXPECT_EQ(plain_line.find("weights"), std::string::npos);
  ASSERT_TRUE(internal::decode_journal_record(plain_line, &id, &back, &time_ns));
  EXPECT_TRUE(back.checkpoint_steps.empty());
  expect_bit_equal(plain, back);
}

// The record of a failed run as the journal wrote it before train_seconds
// (2026-11-28), checksum by an independent FNV-1a 64: it reads with
// train_seconds unknown (NaN) and re-encodes to the same bytes, so checksum
// rule 1 (which hashes the re-encoded record) still holds for old files. A
// known train_seconds goes last.
TEST_F(JournalTest, ARecordOfBeforeAColumnWasAddedReencodesToTheSameBytes) {
  const std::string body =
      "run 00ff v=1 time=42 status=failed message=x mse=0x1.8p+0 trajectory_errors= "
      "diverged_rollouts=0 trace= best_step=0 best_validation_loss=0x0p+0 wall_time_s=0x0p+0 "
      "steps=0 parameter_count=0 newton_failures=0 figure_prediction_05= "
      "figure_prediction_075= figure_reference_05= figure_reference_075=";
  const std::string line = body + " fnv1a64=c347327e99065108";
  std::string id;
  RunResult back;
  std::int64_t time_ns = 0;
  ASSERT_TRUE(internal::decode_journal_record(line, &id, &back, &time_ns));
  EXPECT_TRUE(std::isnan(back.train_seconds));
  EXPECT_EQ(internal::encode_journal_record(id, back, time_ns), line);
  back.train_seconds = 3.0;
  EXPECT_EQ(internal::encode_journal_record(id, back, time_ns),
            body + " train_seconds=0x1.8p+1 fnv1a64=f0ac0e61e7b2a0d0");
}

TEST_F(JournalTest, SkipsAndCountsATornLastLine) {
  Journal(results_path_, 0).append(id(0), sample_result(0, sample_layout()));
  Journal(results_path_, 0).append(id(1), sample_result(1, sample_layout()));
  const std::string log = journal_directory(results_path_) + "/rank-0.log";
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Kill mid-record: the second line loses its tail.
  ASSERT_EQ(::truncate(log.c_str(), static_cast<off_t>(text.size() - 30)), 0);
  int skipped = 0;
  auto replayed = replay_journals(results_path_, &skipped);
  EXPECT_EQ(skipped, 1);
  ASSERT_EQ(replayed.size(), 1u);
  expect_bit_equal(sample_result(0, sample_layout()), replayed.at(id(0)));

  // The restarted rank appends after the torn fragment, not onto it.
  Journal(results_path_, 0).append(id(2), sample_result(2, sample_layout()));
  replayed = replay_journals(results_path_, &skipped);
  EXPECT_EQ(skipped, 1);
  ASSERT_EQ(replayed.size(), 2u);
  expect_bit_equal(sample_result(2, sample_layout()), replayed.at(id(2)));
}

TEST_F(JournalTest, MergesRecordsOfEveryRankAndRankCount) {
  // An earlier job with 3 ranks, then a resumed job with 2.
  Journal(results_path_, 0).append(id(0), sample_result(0, sample_layout()));
  Journal(results_path_, 2).append(id(2), sample_result(2, sample_layout()));
  Journal(results_path_, 1).append(id(1), sample_result(1, sample_layout()));
  Journal(results_path_, 1).append(id(3), sample_result(3, sample_layout()));
  Journal(results_path_, 10).append(id(4), sample_result(4, sample_layout()));
  int skipped = -1;
  const auto replayed = replay_journals(results_path_, &skipped);
  EXPECT_EQ(skipped, 0);
  ASSERT_EQ(replayed.size(), 5u);
  for (int row = 0; row < 5; ++row) {
    expect_bit_equal(sample_result(row, sample_layout()), replayed.at(id(row)));
  }
}

TEST_F(JournalTest, LaterRecordsOfARunWin) {
  Journal(results_path_, 1).append(id(0), sample_result(1, sample_layout()));
  Journal(results_path_, 0).append(id(0), sample_result(2, sample_layout()));
  Journal(results_path_, 1).append(id(0), sample_result(3, sample_layout()));
  const auto replayed = replay_journals(results_path_);
  ASSERT_EQ(replayed.size(), 1u);
  expect_bit_equal(sample_result(3, sample_layout()), replayed.at(id(0)));
}

TEST_F(JournalTest, MissingJournalIsEmpty) {
  int skipped = -1;
  EXPECT_TRUE(replay_journals(results_path_, &skipped).empty());
  EXPECT_EQ(skipped, 0);
}

TEST_F(JournalTest, ReportsAnUnwritableDirectoryWithRankAndPath) {
  EXPECT_THAT([] { Journal("/nonexistent/dir/r.h5", 3); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  HasSubstr("[rank 3] /nonexistent/dir/r.h5.journal/rank-3.log")));
}

// Files, not paths: a journal directory or log that is a symbolic link is
// refused, and what it points to is left as it was.
TEST_F(JournalTest, ASymlinkedJournalDirectoryIsRefusedAndItsTargetUntouched) {
  const std::string target = results_path_ + ".elsewhere";
  ::mkdir(target.c_str(), 0755);
  ASSERT_EQ(::symlink(target.c_str(), journal_directory(results_path_).c_str()), 0);
  EXPECT_THAT([&] { Journal(results_path_, 0); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr(
                  journal_directory(results_path_) + ": a symbolic link, but the journal")));
  EXPECT_THAT([&] { replay_journals(results_path_); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("a symbolic link")));
  EXPECT_NE(::rmdir(target.c_str()), -1) << "something was written into " << target;
  ::unlink(journal_directory(results_path_).c_str());
}

TEST_F(JournalTest, ASymlinkedLogIsNeitherWrittenNorReadThrough) {
  const std::string foreign = results_path_ + ".foreign.txt";
  std::ofstream(foreign) << "someone else's text\n";
  ::mkdir(journal_directory(results_path_).c_str(), 0755);
  const std::string log = journal_directory(results_path_) + "/rank-0.log";
  ASSERT_EQ(::symlink(foreign.c_str(), log.c_str()), 0);
  EXPECT_THAT([&] { Journal(results_path_, 0); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  HasSubstr(log + ": a symbolic link where this rank's journal must be")));
  EXPECT_THAT([&] { replay_journals(results_path_); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  HasSubstr(log + ": a symbolic link where a journal log must be")));
  EXPECT_EQ(testing_util::read_all(foreign), "someone else's text\n");
  std::remove(foreign.c_str());
}

}  // namespace
}  // namespace phnn
