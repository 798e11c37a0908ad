// tests/sweep/writer_lock_test.cpp — the single-writer guard of a results
// file: a second holder is refused, a stale one taken over, release frees it.
#include "phnn/sweep/writer_lock.h"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace phnn {
namespace {

using ::testing::HasSubstr;

class WriterLockTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "phnn_lock_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::system(("rm -rf " + dir_ + " && mkdir -p " + dir_).c_str());
    results_ = dir_ + "/out.h5";
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  std::string lock_text() const {
    std::ifstream in(WriterLock::lock_path(results_));
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }

  std::string dir_, results_;
};

bool exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

// A pid that was this host's and is certainly gone now.
long dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST_F(WriterLockTest, HolderWritesHostPidStartAndSweepHash) {
  WriterLock lock;
  const LockOutcome outcome = lock.acquire(results_, "00ff00ff00ff00ff");
  ASSERT_TRUE(outcome.acquired) << outcome.message;
  EXPECT_EQ(outcome.message, "");
  const LockHolder holder = parse_lock_text(lock_text());
  EXPECT_EQ(holder.host, host_name());
  EXPECT_EQ(holder.pid, static_cast<long>(::getpid()));
  EXPECT_EQ(holder.sweep_hash, "00ff00ff00ff00ff");
  EXPECT_EQ(holder.started.size(), 20u) << holder.started;  // 2024-05-01T12:00:00Z
}

// flock conflicts between open files, even in one process: a second
// WriterLock stands for a second `phnn sweep`.
TEST_F(WriterLockTest, SecondWriterIsRefusedAtOnceNamingTheHolder) {
  WriterLock first, second;
  ASSERT_TRUE(first.acquire(results_, "aaaa").acquired);
  const LockOutcome outcome = second.acquire(results_, "bbbb");
  EXPECT_FALSE(outcome.acquired);
  EXPECT_FALSE(second.held());
  EXPECT_THAT(outcome.message, HasSubstr(results_ + " is being written by another phnn sweep: pid " +
                                         std::to_string(::getpid()) + " on host " + host_name()));
  EXPECT_THAT(outcome.message, HasSubstr("(sweep hash aaaa)"));
  EXPECT_THAT(outcome.message, HasSubstr("pass another --out path"));
  EXPECT_EQ(parse_lock_text(lock_text()).sweep_hash, "aaaa") << "the refused writer changed the lock";
}

TEST_F(WriterLockTest, ReleaseDeletesTheLockFileAndLetsTheNextWriterIn) {
  WriterLock first;
  ASSERT_TRUE(first.acquire(results_, "aaaa").acquired);
  first.release();
  EXPECT_FALSE(exists(WriterLock::lock_path(results_)));
  WriterLock second;
  const LockOutcome outcome = second.acquire(results_, "bbbb");
  EXPECT_TRUE(outcome.acquired);
  EXPECT_EQ(outcome.message, "") << "a released lock is not stale";
}

TEST_F(WriterLockTest, StaleLockOfAProcessGoneFromThisHostIsTakenOverWithANote) {
  const long gone = dead_pid();
  std::ofstream(WriterLock::lock_path(results_))
      << "host = " << host_name() << "\npid = " << gone
      << "\nstarted = 2024-05-01T12:00:00Z\nsweep_hash = cccc\n";
  WriterLock lock;
  const LockOutcome outcome = lock.acquire(results_, "dddd");
  ASSERT_TRUE(outcome.acquired) << outcome.message;
  EXPECT_THAT(outcome.message, HasSubstr("taking over a stale lock of pid " + std::to_string(gone)));
  EXPECT_THAT(outcome.message, HasSubstr("its process is gone"));
  EXPECT_EQ(parse_lock_text(lock_text()).pid, static_cast<long>(::getpid()));
}

TEST_F(WriterLockTest, ALockFileThatIsNotARegularFileIsAnError) {
  ASSERT_EQ(::mkdir(WriterLock::lock_path(results_).c_str(), 0755), 0);
  WriterLock lock;
  EXPECT_THROW(lock.acquire(results_, "aaaa"), std::runtime_error);
}

TEST(LockHolderTest, ParsesItsOwnTextAndIgnoresJunk) {
  const LockHolder holder =
      parse_lock_text("junk\nhost = node07\npid = 1234\nstarted = S\nsweep_hash = H\n");
  EXPECT_EQ(holder.host, "node07");
  EXPECT_EQ(holder.pid, 1234);
  EXPECT_EQ(holder.describe(), "pid 1234 on host node07 since S (sweep hash H)");
  EXPECT_EQ(parse_lock_text("").pid, 0);
}

// A directory where the lock file goes is named as such (not blamed on the
// results directory's permissions).
TEST_F(WriterLockTest, ADirectoryAtTheLockPathIsNamed) {
  ASSERT_EQ(::mkdir((results_ + ".lock").c_str(), 0755), 0);
  WriterLock lock;
  try {
    lock.acquire(results_, "1a2b3c4d5e6f7081");
    FAIL() << "a directory was taken for the lock";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("taken by a directory; move it away"));
    EXPECT_THAT(e.what(), ::testing::Not(::testing::HasSubstr("must be writable")));
  }
}

}  // namespace
}  // namespace phnn
