// tests/sweep/merge_test.cpp — shards of one sweep merged into one results
// file: every result kept bitwise, conflicts and foreign files refused, a
// damaged shard row replaced by a good copy or named, never copied; damaged
// data or sweep text taken from an intact shard.
#include "phnn/sweep/merge.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/data/ph_dataset.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "sample_results.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;

TEST(ShardTest, ParsesIndexOverCountAndRefusesEverythingElse) {
  const Shard shard = Shard::parse("2/8");
  EXPECT_EQ(shard.index, 2);
  EXPECT_EQ(shard.count, 8);
  EXPECT_TRUE(shard.owns_cell(10));
  EXPECT_FALSE(shard.owns_cell(11));
  for (const char* bad : {"8/8", "-1/8", "1/0", "1", "a/b", "1/8x", "", "/", "1/100001"}) {
    EXPECT_THROW(Shard::parse(bad), std::invalid_argument) << bad;
  }
  try {
    Shard::parse("3/2");
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("0 <= I < N"));
    EXPECT_THAT(e.what(), HasSubstr("SLURM_ARRAY_TASK_ID"));
  }
}

TEST(ShardTest, OutputPathNamesTheShard) {
  EXPECT_EQ(Shard::parse("0/4").output_path("results/paper.h5"), "results/paper.shard-0-of-4.h5");
  EXPECT_EQ(Shard::parse("3/4").output_path("out"), "out.shard-3-of-4.h5");
}

const char* kSweep = R"(name = "merge"
[training]
steps = 30
eval_every = 10
[grid]
systems = ["duffing"]
models = ["node-rk2", "phnn-s-dg"]
n_train = [25]
seeds = [0, 1]
)";

class MergeShardsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "phnn_merge_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::system(("rm -rf " + dir_ + " && mkdir -p " + dir_).c_str());
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  // A shard file of `text` holding sample results in `rows` (salted by
  // `salt` so that two shards can disagree).
  std::string shard(const std::string& name, const std::vector<int>& rows, int salt = 0,
                    const std::string& text = kSweep) {
    const SweepSpec spec = parse_sweep_text(text, "sweep.toml");
    const Grid grid = expand_grid(spec);
    const std::string path = dir_ + "/" + name;
    ResultsFile file = ResultsFile::create(path, MPI_COMM_NULL, grid.runs,
                                           std::vector<std::string>(grid.runs.size(), "grid"),
                                           spec.name, spec.text, spec.text_hash, "v1",
                                           ResultsLayout::for_runs(grid.runs));
    file.begin_session({{"command_line", name}});
    for (int row : rows) file.write_run(row, testing_util::sample_result(row + salt, file.layout()));
    file.close();
    return path;
  }

  // Multiplies the stored MSE of `row` of `path` by 1.5 behind the file's
  // back: the row's checksum no longer matches.
  static void alter_mse(const std::string& path, int row) {
    const double mse = ResultsFile::open_read_only(path).read_run(row).mse * 1.5;
    h5::File file = h5::File::open(path, h5::Access::kReadWrite);
    file.write_rows("/runs/mse", static_cast<std::uint64_t>(row), 1, &mse);
  }

  std::string dir_;
};

TEST_F(MergeShardsTest, EveryShardsResultsLandBitwiseInTheirRows) {
  const std::string a = shard("a.h5", {0, 3}), b = shard("b.h5", {1, 3});  // row 3 in both
  const std::string out = dir_ + "/merged.h5";
  const std::string summary = merge_shards({a, b}, out, "v2");
  EXPECT_THAT(summary, HasSubstr("2 shards merged: 3 of 4 runs with results"));
  EXPECT_THAT(summary, HasSubstr("1 pending"));
  const ResultsFile merged = ResultsFile::open_read_only(out);
  const ResultsFile fa = ResultsFile::open_read_only(a), fb = ResultsFile::open_read_only(b);
  testing_util::expect_bit_equal(fa.read_run(0), merged.read_run(0));
  testing_util::expect_bit_equal(fb.read_run(1), merged.read_run(1));
  testing_util::expect_bit_equal(fa.read_run(3), merged.read_run(3));
  EXPECT_EQ(merged.read_statuses()[2], RunStatus::kPending);
  EXPECT_EQ(merged.sweep_hash(), fa.sweep_hash());
  EXPECT_EQ(merged.read_sessions().size(), 2u);
  struct stat st;
  EXPECT_NE(::stat((out + ".partial").c_str(), &st), 0) << "scratch file left behind";
}

TEST_F(MergeShardsTest, ConflictingResultsForeignSweepsAndExistingOutputAreRefused) {
  const std::string a = shard("a.h5", {0}), b = shard("b.h5", {0}, /*salt=*/4);
  const std::string out = dir_ + "/merged.h5";
  try {
    merge_shards({a, b}, out, "v2");
    FAIL() << "conflicting results were merged";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("run 0 differs between " + a + " and " + b));
  }
  struct stat st;
  EXPECT_NE(::stat(out.c_str(), &st), 0);
  const std::string other = shard("other.h5", {1}, 0, std::string("# other\n") + kSweep);
  EXPECT_THROW(merge_shards({a, other}, out, "v2"), std::invalid_argument);
  EXPECT_THROW(merge_shards({a}, a, "v2"), std::invalid_argument);
  EXPECT_THROW(merge_shards({}, out, "v2"), std::invalid_argument);
  merge_shards({a}, out, "v2");
  try {
    merge_shards({a}, out, "v2");
    FAIL() << "an existing output was replaced";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr(out + ": exists"));
  }
}

// Two trainings of the same run differ in their clocks only: merged, and a
// shard whose results all came before is named.
TEST_F(MergeShardsTest, ResultsDifferingOnlyInWallTimesMergeAndADuplicateShardIsNamed) {
  const std::string a = shard("a.h5", {0, 1});
  const std::string b = dir_ + "/b.h5";
  {
    const SweepSpec spec = parse_sweep_text(kSweep, "sweep.toml");
    const Grid grid = expand_grid(spec);
    ResultsFile file = ResultsFile::create(b, MPI_COMM_NULL, grid.runs,
                                           std::vector<std::string>(grid.runs.size(), "grid"),
                                           spec.name, spec.text, spec.text_hash, "v1",
                                           ResultsLayout::for_runs(grid.runs));
    for (int row : {0, 1}) {
      RunResult r = testing_util::sample_result(row, file.layout());
      r.wall_time_s += 17.0;
      for (TracePoint& p : r.trace) p.elapsed_s += 3.0;
      for (double& t : r.checkpoint_train_seconds) t += 5.0;
      file.write_run(row, r);
    }
  }
  const std::string summary = merge_shards({a, b}, dir_ + "/merged.h5", "v2");
  EXPECT_THAT(summary, HasSubstr("2 of 4 runs with results"));
  EXPECT_THAT(summary, HasSubstr(b + " adds nothing: its 2 results are all in the shards before it"));
  const std::string twice = merge_shards({a, a}, dir_ + "/twice.h5", "v2");
  EXPECT_THAT(twice, HasSubstr(a + " adds nothing"));
  const std::string distinct = merge_shards({a, shard("c.h5", {2})}, dir_ + "/distinct.h5", "v2");
  EXPECT_THAT(distinct, ::testing::Not(HasSubstr("adds nothing")));
}

// A damaged row is never a source: the good copy in another shard is taken,
// whichever shard comes first, and the damage is named.
TEST_F(MergeShardsTest, ADamagedShardRowTakesTheGoodCopyInAnotherShard) {
  const std::string a = shard("a.h5", {0, 3}), b = shard("b.h5", {1, 3});
  const RunResult good = ResultsFile::open_read_only(b).read_run(3);
  for (const std::string& damaged : {a, b}) {
    const std::string other = damaged == a ? b : a;
    const std::string copy = dir_ + "/damaged-" + std::to_string(damaged == a) + ".h5";
    std::system(("cp " + damaged + " " + copy).c_str());
    alter_mse(copy, 3);
    ASSERT_EQ(ResultsFile::open_read_only(copy).damaged_rows(), std::vector<int>{3});
    const std::string out = dir_ + "/merged-" + std::to_string(damaged == a) + ".h5";
    const std::vector<std::string> order =
        damaged == a ? std::vector<std::string>{copy, other}
                     : std::vector<std::string>{other, copy};
    const std::string summary = merge_shards(order, out, "v2");
    EXPECT_THAT(summary, HasSubstr("shard " + copy + " row 3 (run "));
    EXPECT_THAT(summary, HasSubstr("checksum mismatch; took the good copy in " + other));
    const ResultsFile merged = ResultsFile::open_read_only(out);
    testing_util::expect_bit_equal(good, merged.read_run(3));
    EXPECT_TRUE(merged.damaged_rows().empty());
  }
}

TEST_F(MergeShardsTest, ADamagedShardRowWithoutAGoodCopyIsNamedAndNothingIsWritten) {
  const std::string a = shard("a.h5", {0, 3}), b = shard("b.h5", {1});
  alter_mse(a, 3);
  const std::string out = dir_ + "/merged.h5";
  try {
    merge_shards({a, b}, out, "v2");
    FAIL() << "a damaged row was merged";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("shard " + a + " row 3 (run "));
    EXPECT_THAT(e.what(), HasSubstr("checksum mismatch, and no other shard holds the run"));
    EXPECT_THAT(e.what(), HasSubstr("last written by `a.h5`"));  // its session's command line
    EXPECT_THAT(e.what(), HasSubstr("nothing written: repair each damaged shard"));
    EXPECT_THAT(e.what(), HasSubstr("or leave the shard out of the merge"));
  }
  struct stat st;
  EXPECT_NE(::stat(out.c_str(), &st), 0) << "a merged file was left behind";
  EXPECT_NE(::stat((out + ".partial").c_str(), &st), 0) << "scratch file left behind";
}

// Checksum rule 2: a shard whose /data group or sweep text is damaged (its
// digest differs) is not their source; another shard's intact copy is
// taken, and with none the merge is refused naming the group.
TEST_F(MergeShardsTest, DamagedDataOrSweepTextComesFromAnIntactShardOrIsRefused) {
  DatasetOptions options;
  options.num_train_max = 4;
  options.num_validation = 4;
  options.num_inference = 1;
  const PhSystemData data =
      make_ph_system_data(*builtin_system(OscillatorOptions::defaults(SystemKind::kDuffing), options),
                          options, 4);
  auto with_data = [&](const std::string& name, int row) {
    const std::string path = shard(name, {row});
    const std::string hash = parse_sweep_text(kSweep, "sweep.toml").text_hash;
    ResultsFile(ResultsFile::open(path, MPI_COMM_NULL, hash)).store_system_data("duffing", data);
    return path;
  };
  auto damage = [](const std::string& path) {
    h5::File file = h5::File::open(path, h5::Access::kReadWrite);
    const double wrong = 42.0;
    file.write_rows("/data/duffing/train/u", 1, 1, &wrong);
    file.set_attribute("/", "sweep_text", std::string("name = \"damaged\"\n"));
  };
  const std::string a = with_data("a.h5", 0), b = with_data("b.h5", 1);
  damage(a);
  ASSERT_EQ(ResultsFile::open_read_only(a).file_damage().size(), 2u);
  const std::string out = dir_ + "/merged.h5";
  merge_shards({a, b}, out, "v2");
  const ResultsFile merged = ResultsFile::open_read_only(out);
  EXPECT_TRUE(merged.file_damage().empty());
  EXPECT_EQ(merged.sweep_text(), kSweep);
  EXPECT_EQ(merged.read_system_data("duffing").train.u, data.train.u);
  damage(b);
  try {
    merge_shards({a, b}, dir_ + "/none.h5", "v2");
    FAIL() << "damaged data were merged";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("the stored sweep text is damaged"));
  }
  h5::File::open(b, h5::Access::kReadWrite).set_attribute("/", "sweep_text", std::string(kSweep));
  try {
    merge_shards({a, b}, dir_ + "/none.h5", "v2");
    FAIL() << "damaged data were merged";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("/data/duffing is damaged in " + a + ", " + b));
  }
}

}  // namespace
}  // namespace phnn
