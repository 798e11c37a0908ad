// tests/apps/output_rule_test.cpp — every command's output follows one rule
// (phnn/store/output_path.h): never the command's own input, never a file
// phnn did not write; a file of the same kind phnn wrote may be replaced
// (data sets, eval CSVs; never results files). One test per command; each
// checks the refused file is left byte for byte as it was.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;

using testing_util::read_all;

class OutputRuleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "phnn_out_rule_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    ASSERT_EQ(std::system(("rm -rf " + dir_ + " && mkdir -p " + dir_).c_str()), 0);
    notes_ = dir_ + "/notes.txt";
    std::ofstream(notes_) << "a researcher's notes, not phnn's\n";
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  // phnn ARGS: the exit status; *log: its output.
  int phnn(const std::string& args, std::string* log) {
    return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, log);
  }
  // Expects `args` refused with status 2 naming `reason`, `victim` unchanged.
  void expect_refused(const std::string& args, const std::string& victim,
                      const std::string& reason) {
    const std::string before = read_all(victim);
    std::string log;
    EXPECT_EQ(phnn(args, &log), 2) << log;
    EXPECT_THAT(log, HasSubstr(reason));
    EXPECT_EQ(read_all(victim), before) << victim << " was changed";
  }
  std::string train_results(const std::string& name) {
    const std::string out = dir_ + "/" + name;
    std::string log;
    EXPECT_EQ(phnn("train --system harmonic --model node-rk2 --n-train 25 --seeds 0 --steps 20 "
                   "--eval-every 10 --quiet --out " + out, &log), 0) << log;
    return out;
  }

  std::string dir_, notes_;
};

TEST_F(OutputRuleTest, DataReplacesOnlyItsOwnDataSets) {
  const std::string data = dir_ + "/d.h5", args = "data --system harmonic --n-train 25 --out ";
  std::string log;
  ASSERT_EQ(phnn(args + data, &log), 0) << log;
  EXPECT_EQ(phnn(args + data, &log), 0) << "a data set of phnn data is replaced: " << log;
  expect_refused(args + notes_, notes_, "never overwrites other files");
  const std::string system = std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/pendulum.toml";
  const std::string copy = dir_ + "/pendulum.toml";
  std::ofstream(copy) << read_all(system);
  expect_refused("data --system " + copy + " --n-train 25 --out " + copy, copy, "is the input");
}

TEST_F(OutputRuleTest, TrainNeverReplacesAFile) {
  const std::string results = train_results("r.h5");
  const std::string args = "train --system harmonic --model node-rk2 --n-train 25 --seeds 0 "
                           "--steps 20 --quiet --out ";
  expect_refused(args + results, results, "writes a new results file");
  expect_refused(args + notes_, notes_, "never overwrites other files");
}

TEST_F(OutputRuleTest, EvalNeverWritesOverItsResultsFileOrOtherFiles) {
  const std::string results = train_results("r.h5");
  std::string ids;
  ASSERT_EQ(phnn("reduce --per-run --format csv " + results + " | cut -d, -f1 | sed -n 2p", &ids), 0);
  const std::string run = ids.substr(0, ids.find('\n'));
  const std::string args = "eval " + results + " --run " + run + " --out ";
  expect_refused(args + results, results, "is the input");
  expect_refused(args + notes_, notes_, "only replaces CSV files it wrote");
  const std::string csv = dir_ + "/e.csv";
  std::string log;
  ASSERT_EQ(phnn(args + csv, &log), 0) << log;
  EXPECT_EQ(phnn(args + csv, &log), 0) << "an eval CSV is replaced: " << log;
  EXPECT_THAT(read_all(csv), HasSubstr("h0,t,"));
}

TEST_F(OutputRuleTest, MergeNeverReplacesAFileNorAShard) {
  const std::string shard = train_results("r.h5");
  expect_refused("merge " + shard + " " + shard, shard, "is the input");
  expect_refused("merge " + notes_ + " " + shard, notes_, "never overwrites other files");
}

// An empty --out (or merge output) is refused by every command that writes,
// with status 2 and a message saying the path is empty, and nothing appears
// in the working directory (no ".creating" file, no journal).
TEST_F(OutputRuleTest, AnEmptyOutputPathIsRefusedAndWritesNothing) {
  const std::string results = train_results("r.h5");
  std::string ids;
  ASSERT_EQ(phnn("reduce --per-run --format csv " + results + " | cut -d, -f1 | sed -n 2p", &ids), 0);
  const std::string run = ids.substr(0, ids.find('\n'));
  const std::string sweep = dir_ + "/s.toml";
  std::ofstream(sweep) << "name = \"s\"\n[training]\nsteps = 2\n[grid]\nsystems = "
                          "[\"harmonic\"]\nmodels = [\"node-rk2\"]\nseeds = [0]\n";
  const std::string work = dir_ + "/cwd";
  ASSERT_EQ(std::system(("mkdir -p " + work).c_str()), 0);
  const std::vector<std::string> commands = {
      "sweep " + sweep + " --out ''", "train --system harmonic --model node-rk2 --out ''",
      "data --system harmonic --out ''", "merge '' " + results,
      "eval " + results + " --run " + run + " --out ''"};
  for (const std::string& args : commands) {
    std::string log;
    EXPECT_EQ(testing_util::run_shell("cd " + work + " && " + std::string(PHNN_BINARY) + " " +
                                          args,
                                      &log),
              2)
        << args << ": " << log;
    EXPECT_THAT(log, ::testing::AnyOf(HasSubstr("empty path"), HasSubstr("names no file")))
        << args;
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << "one line, before any work: " << log;
    std::string listing;
    ASSERT_EQ(testing_util::run_shell("ls -A " + work, &listing), 0);
    EXPECT_EQ(listing, "") << args << " left files behind";
  }
}

}  // namespace
}  // namespace phnn
