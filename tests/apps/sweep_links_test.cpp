// tests/apps/sweep_links_test.cpp — `phnn sweep` writes files, not paths: a
// symbolic or hard link to a results file in use is refused, a link as
// --out writes the file it names, and journals are never written through a
// link. Each launch under `timeout`, so a hang fails the test.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "phnn/store/journal.h"
#include "phnn/sweep/writer_lock.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing_util::read_all;

// 2 runs of 30 steps: a sweep that finishes in a few seconds.
const char* kTinySweep = R"(name = "tiny"
[data]
num_validation = 40
num_inference = 3
[training]
steps = 30
eval_every = 10
batch_size = 16
[grid]
systems = ["harmonic"]
models = ["node-rk2"]
n_train = [25]
seeds = [0, 1]
)";

class SweepLinksTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "phnn_links_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::system(("rm -rf " + dir_ + " && mkdir -p " + dir_).c_str());
    sweep_ = dir_ + "/tiny.toml";
    std::ofstream(sweep_) << kTinySweep;
    out_ = dir_ + "/out.h5";
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  // `phnn sweep` of the tiny sweep into `out` on 2 ranks; its status.
  int sweep(const std::string& out, std::string* log) const {
    return testing_util::run_shell("timeout -k 5 120 " + std::string(PHNN_MPIEXEC) + " -n 2 " +
                                       PHNN_MPIEXEC_PREFLAGS + " " + PHNN_BINARY + " sweep " +
                                       sweep_ + " --quiet --out " + out,
                                   log);
  }
  static bool is_link(const std::string& path) {
    struct stat st;
    return ::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode);
  }
  static bool exists(const std::string& path) {
    struct stat st;
    return ::lstat(path.c_str(), &st) == 0;
  }

  std::string dir_, sweep_, out_;
};

TEST_F(SweepLinksTest, SymlinkToAResultsFileInUseIsRefusedAndOtherwiseWritesItsTarget) {
  std::string log;
  ASSERT_EQ(sweep(out_, &log), 0) << log;
  const std::string link = dir_ + "/link.h5";
  ASSERT_EQ(::symlink("out.h5", link.c_str()), 0);
  {
    WriterLock holder;  // this test process stands for a sweep on out.h5
    ASSERT_TRUE(holder.acquire(out_, "0123456789abcdef").acquired);
    EXPECT_NE(sweep(link, &log), 0) << log;
    EXPECT_THAT(log, HasSubstr("is being written by another phnn sweep"));
  }
  EXPECT_EQ(sweep(link, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr(link + " is a symbolic link; writing the file it names"));
  EXPECT_TRUE(is_link(link)) << "the link was replaced by a copy";
  EXPECT_FALSE(exists(journal_directory(link))) << "journals started beside the link";
  EXPECT_FALSE(exists(WriterLock::lock_path(link)));
}

TEST_F(SweepLinksTest, HardLinkToAResultsFileIsRefusedUntouched) {
  std::string log;
  ASSERT_EQ(sweep(out_, &log), 0) << log;
  const std::string other = dir_ + "/other.h5";
  ASSERT_EQ(::link(out_.c_str(), other.c_str()), 0);
  const std::string before = read_all(out_);
  WriterLock holder;  // in use through its first name
  ASSERT_TRUE(holder.acquire(out_, "0123456789abcdef").acquired);
  EXPECT_EQ(sweep(other, &log), 2) << log;
  EXPECT_THAT(log, HasSubstr(other + ": has 2 names (hard links)"));
  holder.release();
  EXPECT_EQ(sweep(out_, &log), 2) << log;
  EXPECT_EQ(read_all(other), before);
  EXPECT_FALSE(exists(journal_directory(other)));
}

TEST_F(SweepLinksTest, SymlinkedJournalDirectoryIsRefusedAndItsTargetUnchanged) {
  const std::string target = dir_ + "/etc";
  ::mkdir(target.c_str(), 0755);
  ASSERT_EQ(::symlink(target.c_str(), journal_directory(out_).c_str()), 0);
  std::string log;
  EXPECT_EQ(sweep(out_, &log), 2) << log;
  EXPECT_THAT(log, HasSubstr(journal_directory(out_) + ": a symbolic link"));
  EXPECT_FALSE(exists(target + "/rank-0.log"));
  EXPECT_FALSE(exists(out_));
}

TEST_F(SweepLinksTest, SymlinkedJournalLogIsRefusedAndItsTargetUnchanged) {
  std::string log;
  ASSERT_EQ(sweep(out_, &log), 0) << log;
  const std::string foreign = dir_ + "/notes.txt";
  std::ofstream(foreign) << "someone else's text\n";
  const std::string rank1 = journal_directory(out_) + "/rank-1.log";
  ASSERT_EQ(std::rename(rank1.c_str(), (rank1 + ".moved").c_str()), 0);
  ASSERT_EQ(::symlink(foreign.c_str(), rank1.c_str()), 0);
  EXPECT_NE(sweep(out_, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr(rank1 + ": a symbolic link where"));
  EXPECT_THAT(log, Not(HasSubstr("MPI_ABORT")));
  EXPECT_EQ(read_all(foreign), "someone else's text\n");
}

}  // namespace
}  // namespace phnn
