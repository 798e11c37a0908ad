// tests/apps/verify_command_test.cpp — damaged bytes in a finished results
// file are found (phnn verify, phnn reduce) and repaired by the next `phnn
// sweep`: from the journal when it holds the run, else by training it again;
// also when the sweep grew (a new version of the file), and in files of the
// old checksum rule. Every column class: tests/faults/damage_matrix_test.cpp.
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/store/results_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

class VerifyCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "phnn_verify_" + std::to_string(::getpid());
    ASSERT_EQ(std::system(("rm -rf " + dir_ + " && mkdir -p " + dir_).c_str()), 0);
    out_ = dir_ + "/r.h5";
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  int sweep(std::string* log) {
    return testing_util::run_shell(testing_util::mpiexec_phnn(2) + " sweep " + PHNN_SOURCE_DIR +
                                       "/sweeps/tiny.toml --quiet --out " + out_,
                                   log);
  }
  int phnn(const std::string& args, std::string* log) {
    return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, log);
  }
  // Flips one mantissa bit of run `row`'s stored MSE where its 8 bytes sit
  // in the file (found by value: the test does not rely on HDF5's layout).
  void flip_mse(int row) {
    const double mse = ResultsFile::open_read_only(out_).read_run(row).mse;
    std::string bytes = testing_util::read_all(out_);
    const std::string pattern(reinterpret_cast<const char*>(&mse), sizeof mse);
    const std::size_t at = bytes.find(pattern);
    ASSERT_NE(at, std::string::npos);
    ASSERT_EQ(bytes.find(pattern, at + 1), std::string::npos) << "the MSE's bytes are not unique";
    bytes[at + 2] = static_cast<char>(bytes[at + 2] ^ 0x10);
    std::ofstream(out_, std::ios::binary | std::ios::trunc) << bytes;
  }
  double mse(int row) { return ResultsFile::open_read_only(out_).read_run(row).mse; }

  std::string dir_, out_;
};

TEST_F(VerifyCommandTest, DamagedRowsAreFoundThenRepairedFromTheJournalOrTrainedAgain) {
  std::string log;
  ASSERT_EQ(sweep(&log), 0) << log;
  ASSERT_EQ(phnn("verify " + out_, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("configuration: ok"));
  EXPECT_THAT(log, HasSubstr("6 finished rows checked, 0 damaged"));
  const std::string id = ResultsFile::open_read_only(out_).read_run_ids()[1];
  const double original = mse(1);

  flip_mse(1);
  EXPECT_NE(mse(1), original);
  EXPECT_EQ(phnn("verify " + out_, &log), 1) << log;
  EXPECT_THAT(log,
              HasSubstr("damaged: run " + id + " (row 1): checksum mismatch; the journal holds it"));
  EXPECT_EQ(phnn("reduce " + out_, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("1 damaged rows left out, counted as pending: " + id + " (row 1)"));
  ASSERT_EQ(sweep(&log), 0) << log;
  EXPECT_THAT(log, HasSubstr("1 damaged rows (checksum mismatch) repaired from the journals: " + id));
  const double repaired = mse(1);
  EXPECT_EQ(std::memcmp(&original, &repaired, sizeof original), 0);
  EXPECT_EQ(phnn("verify " + out_, &log), 0) << log;

  // Without the journal the run is trained again: the same bits (a result
  // depends only on its configuration and seed).
  flip_mse(1);
  ASSERT_EQ(std::system(("rm -rf " + out_ + ".journal").c_str()), 0);
  EXPECT_EQ(phnn("verify " + out_, &log), 1);
  EXPECT_THAT(log, HasSubstr("not in the journals"));
  ASSERT_EQ(sweep(&log), 0) << log;
  EXPECT_THAT(log, HasSubstr("damaged rows not in the journals, trained again: " + id));
  EXPECT_THAT(log, HasSubstr("1 runs trained"));
  const double retrained = mse(1);
  EXPECT_EQ(std::memcmp(&original, &retrained, sizeof original), 0);
  EXPECT_EQ(phnn("verify " + out_, &log), 0) << log;
  EXPECT_THAT(log, Not(HasSubstr("damaged:")));
}

// A sweep resumed with more seeds writes a new version of the file: a
// damaged row is repaired from the journal, or trained again without it,
// never copied as it stands (it used to be, with a fresh valid checksum).
TEST_F(VerifyCommandTest, GrowingASweepRepairsDamagedRowsInsteadOfCopyingThem) {
  std::string log;
  ASSERT_EQ(sweep(&log), 0) << log;
  const std::string id = ResultsFile::open_read_only(out_).read_run_ids()[1];
  const double original = mse(1);
  auto grow = [&](const std::string& seeds, std::string* grow_log) {
    std::string text = testing_util::read_all(std::string(PHNN_SOURCE_DIR) + "/sweeps/tiny.toml");
    text.replace(text.find("seeds = [0, 1, 2]"), 17, "seeds = " + seeds);
    const std::string path = dir_ + "/grown.toml";
    std::ofstream(path) << text;
    return testing_util::run_shell(testing_util::mpiexec_phnn(2) + " sweep " + path +
                                       " --quiet --out " + out_,
                                   grow_log);
  };
  auto mse_of = [&](const std::string& run) {
    const ResultsFile file = ResultsFile::open_read_only(out_);
    const std::vector<std::string> ids = file.read_run_ids();
    const auto row = std::find(ids.begin(), ids.end(), run) - ids.begin();
    return file.read_run(static_cast<int>(row)).mse;
  };

  flip_mse(1);
  ASSERT_EQ(grow("[0, 1, 2, 3]", &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("(checksum mismatch) repaired from the journals: " + id));
  const double repaired = mse_of(id);
  EXPECT_EQ(std::memcmp(&original, &repaired, sizeof original), 0);
  EXPECT_EQ(phnn("verify " + out_, &log), 0) << log;

  const std::vector<std::string> ids = ResultsFile::open_read_only(out_).read_run_ids();
  flip_mse(static_cast<int>(std::find(ids.begin(), ids.end(), id) - ids.begin()));
  ASSERT_EQ(std::system(("rm -rf " + out_ + ".journal").c_str()), 0);
  ASSERT_EQ(grow("[0, 1, 2, 3, 4]", &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("not in the journals, left pending to train again: " + id));
  const double retrained = mse_of(id);
  EXPECT_EQ(std::memcmp(&original, &retrained, sizeof original), 0);
  EXPECT_EQ(phnn("verify " + out_, &log), 0) << log;
}

// Files written before 2026-11-28 keep checksum rule 1 (what read_run
// returns, with id, canonical and seed; no digests): made here from a new
// file by dropping the rule's attributes and rewriting each row under rule
// 1, as the build of that time wrote it. They verify, a damaged row is
// found and repaired under rule 1 (the file keeps its rule), and they reduce
// and merge (the merged file is a new one, of rule 2).
TEST_F(VerifyCommandTest, AFileOfTheOldChecksumRuleVerifiesResumesReducesAndMerges) {
  std::string log;
  ASSERT_EQ(sweep(&log), 0) << log;
  {
    h5::File raw = h5::File::open(out_, h5::Access::kReadWrite);
    for (const std::string& group : raw.link_names("/data")) {
      raw.remove_attribute("/data/" + group, "digest");
    }
    raw.remove_attribute("/", "digest");
    raw.remove_attribute("/", "checksum_version");
  }
  {
    const std::string hash = ResultsFile::open_read_only(out_).sweep_hash();
    ResultsFile file = ResultsFile::open(out_, MPI_COMM_NULL, hash);
    ASSERT_EQ(file.checksum_version(), 1);
    for (int row = 0; row < file.num_runs(); ++row) file.write_run(row, file.read_run(row));
  }
  ASSERT_EQ(phnn("verify " + out_, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("checksums (rule 1): 6 finished rows checked, 0 damaged"));
  EXPECT_THAT(log, Not(HasSubstr("digests")));
  const std::string id = ResultsFile::open_read_only(out_).read_run_ids()[1];
  const double original = mse(1);
  flip_mse(1);
  EXPECT_EQ(phnn("verify " + out_, &log), 1) << log;
  EXPECT_THAT(log,
              HasSubstr("damaged: run " + id + " (row 1): checksum mismatch; the journal holds it"));
  ASSERT_EQ(sweep(&log), 0) << log;
  EXPECT_THAT(log, HasSubstr("repaired from the journals: " + id));
  const double repaired = mse(1);
  EXPECT_EQ(std::memcmp(&original, &repaired, sizeof original), 0);
  EXPECT_EQ(ResultsFile::open_read_only(out_).checksum_version(), 1);
  EXPECT_EQ(phnn("verify " + out_, &log), 0) << log;
  EXPECT_EQ(phnn("reduce " + out_, &log), 0) << log;
  const std::string merged = dir_ + "/merged.h5";
  ASSERT_EQ(phnn("merge " + merged + " " + out_, &log), 0) << log;
  EXPECT_EQ(ResultsFile::open_read_only(merged).checksum_version(), 2);
  EXPECT_EQ(phnn("verify " + merged, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("checksums (rule 2): 6 finished rows checked, 0 damaged"));
}

// The file of the 2026-11-25 build (tests/fixtures) verifies under rule 1.
TEST_F(VerifyCommandTest, TheFixtureOfTheOldRuleVerifies) {
  std::string log;
  EXPECT_EQ(phnn("verify " + std::string(PHNN_SOURCE_DIR) + "/tests/fixtures/results-2026-11-25.h5",
                 &log),
            0)
      << log;
  EXPECT_THAT(log, HasSubstr("checksums (rule 1): 4 finished rows checked, 0 damaged"));
}


// A damaged stored sweep text or sweep_hash is named as damage by verify,
// reduce and the resume, which repairs it; never "written by another phnn
// version", nor advice to pass --mix-kernels (2026-11-28).
TEST_F(VerifyCommandTest, ADamagedSweepTextOrHashIsNamedAsDamageAndRepaired) {
  std::string log;
  ASSERT_EQ(sweep(&log), 0) << log;
  const std::string original = testing_util::read_all(out_);
  const std::string hash = ResultsFile::open_read_only(out_).sweep_hash();
  struct Damage {
    std::string object, text;
    std::size_t offset;
    char to;
  };
  for (const Damage& d : {Damage{"@sweep_text", "seeds = [0, 1, 2]", 12, '3'},
                          Damage{"@sweep_hash", hash, 3, hash[3] == '7' ? '8' : '7'}}) {
    SCOPED_TRACE(d.object);
    std::string bytes = original;
    std::size_t at = std::string::npos;  // the attribute: the last copy in the file
    for (std::size_t k = bytes.find(d.text); k != std::string::npos; k = bytes.find(d.text, k + 1)) {
      if (k == 0 || (bytes[k - 1] != '"' && bytes[k - 1] != ' ')) at = k;
    }
    ASSERT_NE(at, std::string::npos);
    bytes[at + d.offset] = d.to;
    std::ofstream(out_, std::ios::binary | std::ios::trunc) << bytes;
    EXPECT_EQ(phnn("verify " + out_, &log), 1) << log;
    EXPECT_THAT(log, HasSubstr("damaged: " + d.object + ":"));
    const int reduced = phnn("reduce " + out_, &log);
    if (d.object == "@sweep_text") {
      EXPECT_EQ(reduced, 1) << log;
      EXPECT_THAT(log, HasSubstr(out_ + ": damaged: @sweep_text:"));
    }
    EXPECT_THAT(log, Not(HasSubstr("another phnn version")));
    ASSERT_EQ(sweep(&log), 0) << log;
    EXPECT_THAT(log, HasSubstr(d.object));
    EXPECT_THAT(log, Not(HasSubstr("text changed")));
    EXPECT_THAT(log, Not(HasSubstr("--mix-kernels")));
    EXPECT_THAT(log, Not(HasSubstr("another phnn version")));
    EXPECT_EQ(phnn("verify " + out_, &log), 0) << log;
  }
}

}  // namespace
}  // namespace phnn
