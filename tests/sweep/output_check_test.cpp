// tests/sweep/output_check_test.cpp — what a sweep may do with what is at its
// output path: resume, create, move a damaged file of ours aside, or refuse.
#include "phnn/sweep/output_check.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/ph_system.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "sample_results.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr char kHash[] = "1a2b3c4d5e6f7081";

class OutputCheckTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "phnn_output_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::system(("rm -rf " + dir_ + " && mkdir -p " + dir_).c_str());
    out_ = dir_ + "/out.h5";
    sweep_ = dir_ + "/sweep.toml";
    std::ofstream(sweep_) << "name = \"x\"\n";
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  void create_results(const std::string& hash = kHash) const {
    ResultsFile file = ResultsFile::create(out_, MPI_COMM_NULL, testing_util::sample_runs(3),
                                           testing_util::sample_studies(3), "demo", "text", hash,
                                           "phnn-sweep 0.1.0", testing_util::sample_layout());
    file.close();
  }
  OutputCheck check() const { return inspect_output(out_, sweep_, kHash); }

  std::string dir_, out_, sweep_;
};

TEST_F(OutputCheckTest, NothingThereMeansCreate) {
  EXPECT_EQ(check().state, OutputState::kMissing);
}

TEST_F(OutputCheckTest, OurResultsFileOfThisSweepIsResumed) {
  create_results();
  EXPECT_EQ(check().state, OutputState::kResumable) << check().message;
}

TEST_F(OutputCheckTest, RefusesADirectoryAFifoAndTheSweepFileItself) {
  ASSERT_EQ(::mkdir(out_.c_str(), 0755), 0);
  EXPECT_EQ(check().state, OutputState::kRefused);
  EXPECT_THAT(check().message, HasSubstr("not a regular file (a directory)"));
  ASSERT_EQ(::rmdir(out_.c_str()), 0);
  ASSERT_EQ(::mkfifo(out_.c_str(), 0644), 0);
  EXPECT_EQ(check().state, OutputState::kRefused);
  EXPECT_THAT(check().message, HasSubstr("FIFO"));
  const OutputCheck itself = inspect_output(sweep_, sweep_, kHash);
  EXPECT_EQ(itself.state, OutputState::kRefused);
  EXPECT_THAT(itself.message, HasSubstr("is the sweep file itself"));
}

TEST_F(OutputCheckTest, RefusesATextFileAndAnotherProgramsHdf5File) {
  std::ofstream(out_) << "my thesis\n";
  EXPECT_EQ(check().state, OutputState::kRefused);
  EXPECT_THAT(check().message, HasSubstr("not an HDF5 file"));
  std::remove(out_.c_str());
  write_ph_dataset_file(out_, make_ph_system_data(*make_system("harmonic"), DatasetOptions{}, 2));
  EXPECT_EQ(check().state, OutputState::kRefused);
  EXPECT_THAT(check().message, HasSubstr("not a phnn results file"));
}

// Whether its runs may grow is decided by comparing the runs (sweep_growth).
TEST_F(OutputCheckTest, ResultsOfAnotherSweepTextAreComparedNotRefused) {
  create_results("ffffffffffffffff");
  EXPECT_EQ(check().state, OutputState::kOtherText);
}

TEST_F(OutputCheckTest, EmptyFileIsMovedAsideNotRefused) {
  std::ofstream{out_};
  EXPECT_EQ(check().state, OutputState::kEmpty);
}

TEST_F(OutputCheckTest, TruncatedResultsFileIsDamaged) {
  create_results();
  struct stat st;
  ASSERT_EQ(::stat(out_.c_str(), &st), 0);
  ASSERT_EQ(::truncate(out_.c_str(), st.st_size / 2), 0);
  const OutputCheck c = check();
  EXPECT_EQ(c.state, OutputState::kDamaged) << c.message;
}

// A file failing its structural checks is damaged (moved aside and rebuilt
// from the journals), never resumed: an impossible status, an empty or a
// repeated run id.
TEST_F(OutputCheckTest, ImpossibleStatusOrBrokenIdsMakeTheFileDamagedNamingTheRow) {
  create_results();
  {
    h5::File file = h5::File::open(out_, h5::Access::kReadWrite);
    const std::int64_t bad = 7;
    file.write_rows("/runs/status", 1, 1, &bad);
  }
  OutputCheck c = check();
  EXPECT_EQ(c.state, OutputState::kDamaged);
  EXPECT_THAT(c.message, HasSubstr("/runs/status[1] = 7"));
  create_results();
  {
    h5::File file = h5::File::open(out_, h5::Access::kReadWrite);
    file.write_string_rows("/runs/id", 2, {""});
  }
  c = check();
  EXPECT_EQ(c.state, OutputState::kDamaged);
  EXPECT_THAT(c.message, HasSubstr("row 2 has no run id"));
}

TEST_F(OutputCheckTest, RefusesAJournalPathThatIsNotADirectory) {
  std::ofstream(journal_directory(out_)) << "not a journal\n";
  const OutputCheck c = check();
  EXPECT_EQ(c.state, OutputState::kRefused);
  EXPECT_THAT(c.message, StartsWith(journal_directory(out_) + ": not a directory"));
}

// Files, not paths: a second name of the results file would escape the
// writer lock (it keys on the name) and be split off by the next rename.
TEST_F(OutputCheckTest, RefusesAResultsFileWithASecondName) {
  create_results();
  const std::string other = dir_ + "/other.h5";
  ASSERT_EQ(::link(out_.c_str(), other.c_str()), 0);
  for (const std::string& name : {out_, other}) {
    const OutputCheck c = inspect_output(name, sweep_, kHash);
    EXPECT_EQ(c.state, OutputState::kRefused);
    EXPECT_THAT(c.message, HasSubstr(name + ": has 2 names (hard links)"));
  }
}

TEST_F(OutputCheckTest, RefusesASymlinkedJournalDirectory) {
  ASSERT_EQ(::symlink(dir_.c_str(), journal_directory(out_).c_str()), 0);
  const OutputCheck c = check();
  EXPECT_EQ(c.state, OutputState::kRefused);
  EXPECT_THAT(c.message, HasSubstr(journal_directory(out_) + ": a symbolic link"));
}

TEST_F(OutputCheckTest, ALinkAsOutputNamesItsTargetAndADanglingOneIsRefused) {
  create_results();
  const std::string link = dir_ + "/link.h5";
  ASSERT_EQ(::symlink("out.h5", link.c_str()), 0);
  std::string resolved;
  EXPECT_EQ(resolve_output_link(link, &resolved), "");
  struct stat a, b;
  ASSERT_EQ(::stat(resolved.c_str(), &a), 0);
  ASSERT_EQ(::stat(out_.c_str(), &b), 0);
  EXPECT_EQ(a.st_ino, b.st_ino);
  EXPECT_EQ(resolve_output_link(out_, &resolved), "");
  EXPECT_EQ(resolved, out_);
  const std::string dangling = dir_ + "/dangling.h5";
  ASSERT_EQ(::symlink("nowhere.h5", dangling.c_str()), 0);
  EXPECT_THAT(resolve_output_link(dangling, &resolved),
              HasSubstr(dangling + ": a symbolic link that names no file"));
  EXPECT_EQ(inspect_output(link, sweep_, kHash).state, OutputState::kRefused);
}

TEST_F(OutputCheckTest, MoveAsidePicksAFreeNameAndKeepsTheBytes) {
  std::ofstream(out_) << "a";
  const std::string first = move_aside(out_, "damaged");
  std::ofstream(out_) << "b";
  const std::string second = move_aside(out_, "damaged");
  EXPECT_NE(first, second);
  EXPECT_THAT(first, StartsWith(out_ + ".damaged-"));
  std::ifstream a(first), b(second);
  EXPECT_EQ(a.get(), 'a');
  EXPECT_EQ(b.get(), 'b');
}

TEST(SanitizeFileNameTest, KeepsOneComponentInsideTheDirectory) {
  EXPECT_EQ(sanitize_file_name("paper"), "paper");
  EXPECT_EQ(sanitize_file_name("run-1.2_b+c"), "run-1.2_b+c");
  EXPECT_EQ(sanitize_file_name("../../x"), "_._.._x");
  EXPECT_EQ(sanitize_file_name(".."), "_.");
  EXPECT_EQ(sanitize_file_name("/etc/passwd"), "_etc_passwd");
  EXPECT_EQ(sanitize_file_name("a b\n"), "a_b_");
  EXPECT_EQ(sanitize_file_name(""), "unnamed");
}

}  // namespace
}  // namespace phnn

namespace phnn {
namespace {

// A name the file system cannot hold with the lock, journal and scratch
// suffixes is refused up front (also by --dry-run), not after training.
TEST(OutputNameTest, NamesTooLongForTheFileSystemAreRefusedUpFront) {
  const std::string dir = ::testing::TempDir();
  EXPECT_EQ(output_name_problem(dir + "/results.h5"), "");
  EXPECT_EQ(output_name_problem(std::string(255 - kLongestSuffix - 3, 'x') + ".h5"), "");
  EXPECT_THAT(output_name_problem(dir + "/" + std::string(250, 'x') + ".h5"),
              HasSubstr("choose a shorter `output` or --out"));
  EXPECT_THAT(output_name_problem(std::string(59000, 'y')), HasSubstr("bytes"));
  EXPECT_THAT(output_name_problem(""), HasSubstr("the output path \"\" names no file"));
  EXPECT_THAT(output_name_problem(dir + "/"), HasSubstr("names no file"));
  std::string log;
  const std::string sweep = std::string(PHNN_SOURCE_DIR) + "/sweeps/tiny.toml";
  EXPECT_EQ(testing_util::run_shell(std::string(PHNN_BINARY) + " sweep " + sweep +
                                        " --dry-run --out " + dir + "/" + std::string(250, 'x'),
                                    &log),
            2)
      << log;
  EXPECT_THAT(log, HasSubstr("choose a shorter"));
}

}  // namespace
}  // namespace phnn
