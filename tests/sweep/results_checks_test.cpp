// tests/sweep/results_checks_test.cpp — the checks of a results file by its
// checksum rule: integers range-checked when a row is read (before they size
// anything), bytes rule 1 could not see found by rule 2, the file digest
// naming a damaged configuration column and rewrite_configuration
// restoring it, and rewrite_problem telling which journal records fit a row.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "h5/h5file.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "sweep/sample_results.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;
using testing_util::sample_layout;
using testing_util::sample_result;
using testing_util::sample_runs;
using testing_util::sample_studies;

constexpr int kRuns = 4;

ResultsLayout layout() {
  ResultsLayout l = sample_layout();
  l.weights = true;  // /weights and /runs/weights_offset
  return l;
}
constexpr char kText[] = "name = demo\n";
constexpr char kHash[] = "1a2b3c4d5e6f7081";

class ResultsChecksTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "phnn_checks_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".h5";
    ResultsFile file =
        ResultsFile::create(path_, MPI_COMM_NULL, sample_runs(kRuns), sample_studies(kRuns), "demo",
                            kText, kHash, "v", layout());
    for (int row = 0; row < kRuns; ++row) file.write_run(row, sample_result(row, layout()));
  }
  void TearDown() override { std::remove(path_.c_str()); }

  void put(const std::string& dataset, int row, std::int64_t value) const {
    h5::File file = h5::File::open(path_, h5::Access::kReadWrite);
    file.write_rows(dataset, static_cast<std::uint64_t>(row), 1, &value);
  }

  std::string path_;
};

// n_x = 55554 would size a figure of 28 million doubles; a negative or huge
// weights offset would read outside /weights: refused, naming dataset and
// row, and the row counts as damaged.
TEST_F(ResultsChecksTest, IntegersOutOfRangeAreRefusedNamingDatasetAndRow) {
  put("/runs/n_x", 3, 55554);
  put("/runs/weights_offset", 0, -5);
  put("/runs/best_step", 2, std::int64_t{1} << 40);
  {
    const ResultsFile file = ResultsFile::open_read_only(path_);
    EXPECT_THAT([&] { file.read_run(3); },
                ThrowsMessage<std::runtime_error>(HasSubstr("/runs/n_x[3] = 55554, outside 1..2")));
    EXPECT_THAT(
        [&] { file.read_run(0); },
        ThrowsMessage<std::runtime_error>(HasSubstr("/runs/weights_offset[0] = -5, outside 0..")));
    EXPECT_THAT([&] { file.read_run(2); },
                ThrowsMessage<std::runtime_error>(
                    HasSubstr("/runs/best_step[2] = 1099511627776, outside 0..2147483647")));
    EXPECT_THAT(file.row_damage(3), HasSubstr("/runs/n_x[3] = 55554"));
    EXPECT_EQ(file.damaged_rows(), (std::vector<int>{0, 2, 3}));
  }
  put("/runs/weights_offset", 0, std::int64_t{1} << 62);
  EXPECT_THAT([&] { ResultsFile::open_read_only(path_).read_run(0); },
              ThrowsMessage<std::runtime_error>(
                  HasSubstr("/runs/weights_offset[0] = 4611686018427387904")));
}

// A byte after the end of a string: invisible to rule 1 (what read_run
// returns), found by rule 2 (every stored byte).
TEST_F(ResultsChecksTest, RuleTwoSeesEveryStoredByte) {
  const std::string rule_one = path_ + ".rule1.h5";
  std::system(("cp " + path_ + " " + rule_one).c_str());
  {
    h5::File raw = h5::File::open(rule_one, h5::Access::kReadWrite);
    raw.remove_attribute("/", "checksum_version");
  }
  {
    ResultsFile file = ResultsFile::open(rule_one, MPI_COMM_NULL, kHash);
    for (int row = 0; row < kRuns; ++row) file.write_run(row, file.read_run(row));
  }
  for (const std::string& path : {path_, rule_one}) {
    h5::File raw = h5::File::open(path, h5::Access::kReadWrite);
    raw.write_string_rows("/runs/message", 0, {std::string("\0x", 2)});  // after the NUL
  }
  const ResultsFile file = ResultsFile::open_read_only(path_),
                    old = ResultsFile::open_read_only(rule_one);
  EXPECT_EQ(file.checksum_version(), 2);
  EXPECT_EQ(old.checksum_version(), 1);
  EXPECT_EQ(file.read_run(0).message, "");
  EXPECT_EQ(file.row_damage(0), "checksum mismatch");
  EXPECT_EQ(file.damaged_rows(), std::vector<int>{0});
  EXPECT_TRUE(old.damaged_rows().empty());  // why rule 2
  std::remove(rule_one.c_str());
}

// The configuration of every row is under the file digest, pending rows
// too: a damaged column is named with its rows and rewritten from the runs.
TEST_F(ResultsChecksTest, TheFileDigestNamesADamagedConfigurationColumnAndItsRepairRestoresIt) {
  const std::string before =
      h5::File::open(path_, h5::Access::kReadOnly).read_row_bytes("/runs/model");
  {
    h5::File raw = h5::File::open(path_, h5::Access::kReadWrite);
    raw.write_string_rows("/runs/model", 1, {"phnn-sx"});
  }
  {
    const ResultsFile file = ResultsFile::open_read_only(path_);
    const auto damage = file.file_damage();
    ASSERT_EQ(damage.size(), 1u);
    EXPECT_EQ(damage[0].object, "/runs/model");
    const auto rows = file.configuration_differences(sample_runs(kRuns), sample_studies(kRuns));
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_EQ(rows[0].what, "row 1 differs from the sweep file's runs");
  }
  ResultsFile file = ResultsFile::open(path_, MPI_COMM_NULL, kHash);
  EXPECT_EQ(
      file.repair_configuration(sample_runs(kRuns), sample_studies(kRuns), "demo", kText, kHash),
      std::vector<std::string>{"/runs/model"});
  EXPECT_TRUE(file.file_damage().empty());
  EXPECT_TRUE(file.damaged_rows().empty());
  file.close();
  EXPECT_EQ(h5::File::open(path_, h5::Access::kReadOnly).read_row_bytes("/runs/model"), before);
}

// What cannot be rewritten from a record is said before anything is
// written: verify and the resume ask the same question.
TEST_F(ResultsChecksTest, RewriteProblemTellsWhichRecordsFitTheRow) {
  const ResultsFile file = ResultsFile::open_read_only(path_);
  RunResult record = sample_result(0, layout());
  EXPECT_EQ(file.rewrite_problem(0, record), "");
  record.trace.resize(7);
  EXPECT_THAT(file.rewrite_problem(0, record), HasSubstr("trace has 7 points, the file holds 6"));
  record = sample_result(0, layout());
  record.weights.assign(100000, 0.5);
  EXPECT_THAT(file.rewrite_problem(0, record), HasSubstr("has 100000 weights"));
}

}  // namespace
}  // namespace phnn
