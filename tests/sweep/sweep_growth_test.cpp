// tests/sweep/sweep_growth_test.cpp — a results file's identity is its set
// of runs: added runs grow it (finished runs kept bitwise), text-only edits
// rewrite it, changed runs and dropped results are refused; a damaged row is
// repaired from the journal or left to train again, never copied.
#include "phnn/sweep/sweep_growth.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "sample_results.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// 4 runs: node-rk2 seeds 0, 1 (rows 0, 1), phnn-s-dg seeds 0, 1 (rows 2, 3).
const char* kSweep = R"(name = "grow"
[training]
steps = 30
eval_every = 10
[grid]
systems = ["duffing"]
models = ["node-rk2", "phnn-s-dg"]
n_train = [25]
seeds = [0, 1]
)";

std::string edited(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

Grid grid_of(const std::string& text) { return expand_grid(parse_sweep_text(text, "sweep.toml")); }

std::vector<RunStatus> statuses(std::initializer_list<RunStatus> list) { return list; }

std::vector<std::string> canonical_of(const Grid& grid) {
  std::vector<std::string> out;
  for (const RunConfig& run : grid.runs) out.push_back(run.canonical());
  return out;
}

constexpr RunStatus kPending = RunStatus::kPending, kDone = RunStatus::kDone;

TEST(CompareRunSetsTest, TheSameRunsInOrderDifferOnlyInText) {
  const Grid grid = grid_of(kSweep);
  const RunSetComparison cmp = compare_run_sets(
      canonical_of(grid), statuses({kDone, kDone, kPending, kDone}),
      grid_of(edited(kSweep, "[grid]", "# a comment\n[grid]  # and another")).runs);
  EXPECT_TRUE(cmp.same_runs_in_order());
  EXPECT_FALSE(cmp.refused());
  EXPECT_THAT(cmp.file_row_of_run, ElementsAre(0, 1, 2, 3));
}

TEST(CompareRunSetsTest, MoreSeedsAreAddedAndMappedToTheirOldRows) {
  const Grid grid = grid_of(kSweep);
  const RunSetComparison cmp =
      compare_run_sets(canonical_of(grid), statuses({kDone, kDone, kDone, kDone}),
                       grid_of(edited(kSweep, "seeds = [0, 1]", "seeds = [0, 1, 2]")).runs);
  EXPECT_EQ(cmp.added, 2);
  EXPECT_FALSE(cmp.refused());
  EXPECT_FALSE(cmp.same_runs_in_order());
  // New order: node 0, 1, 2, phnn-s 0, 1, 2 (seed fastest).
  EXPECT_THAT(cmp.file_row_of_run, ElementsAre(0, 1, -1, 2, 3, -1));
}

TEST(CompareRunSetsTest, AChangedSettingIsReportedOnceWithItsCount) {
  const Grid grid = grid_of(kSweep);
  const RunSetComparison cmp =
      compare_run_sets(canonical_of(grid), statuses({kDone, kPending, kPending, kPending}),
                       grid_of(edited(kSweep, "steps = 30", "steps = 40")).runs);
  EXPECT_TRUE(cmp.refused());
  EXPECT_EQ(cmp.added, 4);
  ASSERT_EQ(cmp.changes.size(), 1u);
  EXPECT_THAT(cmp.changes[0], HasSubstr("steps: 30 -> 40 (4 runs, e.g. duffing node-rk2 small "
                                        "n_train=25 none seed=0)"));
  EXPECT_TRUE(cmp.removed_result_rows.empty());  // changed, not removed
}

TEST(CompareRunSetsTest, ARemovedRunWithAResultIsRefusedAPendingOneDropped) {
  const Grid grid = grid_of(kSweep);
  const Grid node_only = grid_of(edited(kSweep, R"("node-rk2", "phnn-s-dg")", R"("node-rk2")"));
  const RunSetComparison pending =
      compare_run_sets(canonical_of(grid), statuses({kDone, kDone, kPending, kPending}),
                       node_only.runs);
  EXPECT_FALSE(pending.refused());
  EXPECT_THAT(pending.dropped_pending_rows, ElementsAre(2, 3));
  const RunSetComparison finished =
      compare_run_sets(canonical_of(grid), statuses({kDone, kDone, kPending, RunStatus::kFailed}),
                       node_only.runs);
  EXPECT_TRUE(finished.refused());
  EXPECT_THAT(finished.removed_result_rows, ElementsAre(3));
  EXPECT_THAT(finished.dropped_pending_rows, ElementsAre(2));
}

class WriteGrownResultsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "phnn_grow_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::system(("rm -rf " + dir_ + " && mkdir -p " + dir_).c_str());
    out_ = dir_ + "/out.h5";
  }
  void TearDown() override { std::system(("rm -rf " + dir_).c_str()); }

  // The file of kSweep with results in rows 0 (done), 1 (diverged), 3 (done).
  void create_original() {
    const SweepSpec spec = parse_sweep_text(kSweep, "sweep.toml");
    const Grid grid = expand_grid(spec);
    ResultsFile file = ResultsFile::create(out_, MPI_COMM_NULL, grid.runs,
                                           {"grid", "grid", "grid", "grid"}, spec.name, spec.text,
                                           spec.text_hash, "v1", ResultsLayout::for_runs(grid.runs));
    file.begin_session({{"command_line", "phnn sweep a"}, {"started", "t0"}});
    file.end_session("t1");
    for (int row : {0, 1, 3}) {
      RunResult result = testing_util::sample_result(row, file.layout());
      result.started_utc = "s" + std::to_string(row);
      result.finished_utc = "f" + std::to_string(row);
      original_[grid.runs[row].canonical()] = result;
      file.write_run(row, result);
    }
    file.close();
  }

  std::string dir_, out_;
  std::map<std::string, RunResult> original_;  // canonical -> result written
};

TEST_F(WriteGrownResultsTest, GrownFileKeepsEveryResultBitwiseInItsNewRow) {
  create_original();
  const SweepSpec grown = parse_sweep_text(
      edited(kSweep, "seeds = [0, 1]", "seeds = [0, 1, 2]  # one more"), "sweep.toml");
  const Grid grid = expand_grid(grown);
  const std::string message = write_grown_results(out_, grown, grid, "v2");
  EXPECT_THAT(message, HasSubstr("grew by 2 runs"));
  EXPECT_THAT(message, HasSubstr("3 runs with results kept bitwise"));
  const ResultsFile file = ResultsFile::open_read_only(out_);
  EXPECT_EQ(file.sweep_text(), grown.text);
  EXPECT_EQ(file.sweep_hash(), grown.text_hash);
  ASSERT_EQ(file.num_runs(), 6);
  const auto status = file.read_statuses();
  int kept = 0;
  for (int run = 0; run < 6; ++run) {
    auto it = original_.find(grid.runs[run].canonical());
    if (it == original_.end()) {
      EXPECT_EQ(status[run], RunStatus::kPending) << run;
      continue;
    }
    ++kept;
    testing_util::expect_bit_equal(it->second, file.read_run(run));
    EXPECT_EQ(file.read_run(run).started_utc[0], 's');
  }
  EXPECT_EQ(kept, 3);
  const auto sessions = file.read_sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_THAT(sessions[0], ::testing::Contains(std::make_pair(std::string("finished"),
                                                              std::string("t1"))));
  EXPECT_THAT(sessions[0], ::testing::Contains(std::make_pair(std::string("command_line"),
                                                              std::string("phnn sweep a"))));
}

TEST_F(WriteGrownResultsTest, TextOnlyEditIsSaidSo) {
  create_original();
  const SweepSpec commented = parse_sweep_text(std::string("# notes\n") + kSweep, "sweep.toml");
  const std::string message = write_grown_results(out_, commented, expand_grid(commented), "v2");
  EXPECT_THAT(message, HasSubstr("text changed, not its runs"));
  EXPECT_EQ(ResultsFile::open_read_only(out_).sweep_hash(), commented.text_hash);
}

TEST_F(WriteGrownResultsTest, ChangedRunsAreRefusedAndTheFileIsUntouched) {
  create_original();
  const std::string before = ResultsFile::open_read_only(out_).sweep_hash();
  const SweepSpec changed = parse_sweep_text(edited(kSweep, "steps = 30", "steps = 40"), "s.toml");
  try {
    write_grown_results(out_, changed, expand_grid(changed), "v2");
    FAIL() << "a changed run was accepted";
  } catch (const RunSetRefused& e) {
    EXPECT_THAT(e.what(), HasSubstr(out_ + ": this sweep file does not only add runs"));
    EXPECT_THAT(e.what(), HasSubstr("steps: 30 -> 40 (4 runs"));
    EXPECT_THAT(e.what(), HasSubstr("--out"));
  }
  EXPECT_EQ(ResultsFile::open_read_only(out_).sweep_hash(), before);
  const SweepSpec fewer = parse_sweep_text(edited(kSweep, "seeds = [0, 1]", "seeds = [0]"), "s");
  try {
    write_grown_results(out_, fewer, expand_grid(fewer), "v2");
    FAIL() << "dropping runs with results was accepted";
  } catch (const RunSetRefused& e) {
    EXPECT_THAT(e.what(), HasSubstr("2 runs with results are no longer in it"));
    EXPECT_THAT(e.what(), HasSubstr("duffing phnn-s-dg small n_train=25 none seed=1"));
  }
  EXPECT_EQ(ResultsFile::open_read_only(out_).sweep_hash(), before);
}

// The defect this guards against: a row whose MSE was altered was copied as
// it stood and got a valid checksum in the new version ("kept bitwise").
TEST_F(WriteGrownResultsTest, DamagedRowsAreRepairedFromTheJournalOrLeftToTrainAgain) {
  create_original();
  const Grid old_grid = grid_of(kSweep);
  {
    Journal journal(out_, /*rank=*/0);  // holds row 0's run, not row 3's
    journal.append(old_grid.runs[0].id(), original_[old_grid.runs[0].canonical()]);
  }
  for (int row : {0, 3}) {
    const double mse = ResultsFile::open_read_only(out_).read_run(row).mse * 1.5;
    h5::File file = h5::File::open(out_, h5::Access::kReadWrite);
    file.write_rows("/runs/mse", static_cast<std::uint64_t>(row), 1, &mse);
  }
  ASSERT_THAT(ResultsFile::open_read_only(out_).damaged_rows(), ElementsAre(0, 3));
  const SweepSpec grown =
      parse_sweep_text(edited(kSweep, "seeds = [0, 1]", "seeds = [0, 1, 2]"), "sweep.toml");
  const Grid grid = expand_grid(grown);
  const std::string message = write_grown_results(out_, grown, grid, "v2");
  EXPECT_THAT(message, HasSubstr("1 runs with results kept bitwise"));
  EXPECT_THAT(message, HasSubstr("1 damaged rows (checksum mismatch) repaired from the journals: " +
                                 old_grid.runs[0].id()));
  EXPECT_THAT(message, HasSubstr("1 damaged rows (checksum mismatch) not in the journals, left "
                                 "pending to train again: " + old_grid.runs[3].id()));
  const ResultsFile file = ResultsFile::open_read_only(out_);
  EXPECT_TRUE(file.damaged_rows().empty());
  const auto status = file.read_statuses();
  for (int run = 0; run < file.num_runs(); ++run) {
    const std::string canonical = grid.runs[run].canonical();
    if (canonical == old_grid.runs[0].canonical() || canonical == old_grid.runs[1].canonical()) {
      testing_util::expect_bit_equal(original_[canonical], file.read_run(run));
    } else {
      EXPECT_EQ(status[run], RunStatus::kPending) << run;  // new, or row 3 to train again
    }
  }
}


// A damaged /runs/canonical cell must not read as a changed or dropped run
// (refused with a misleading list) nor be copied: the column is checked
// against the runs of the file's own sweep text, the row compared by its
// run from the text and repaired from the journal (2026-11-28).
TEST_F(WriteGrownResultsTest, ADamagedCanonicalCellIsNamedAndItsRowRepaired) {
  create_original();
  const Grid old_grid = grid_of(kSweep);
  {
    Journal journal(out_, /*rank=*/0);
    journal.append(old_grid.runs[0].id(), original_[old_grid.runs[0].canonical()]);
  }
  {
    std::string text = old_grid.runs[0].canonical();
    text[text.find("steps=30") + 6] = '7';  // steps=70: a "changed" run
    h5::File file = h5::File::open(out_, h5::Access::kReadWrite);
    file.write_string_rows("/runs/canonical", 0, {text});
  }
  const SweepSpec grown =
      parse_sweep_text(edited(kSweep, "seeds = [0, 1]", "seeds = [0, 1, 2]"), "sweep.toml");
  const Grid grid = expand_grid(grown);
  const std::string message = write_grown_results(out_, grown, grid, "v2");
  EXPECT_THAT(message, HasSubstr("/runs/canonical[0] is damaged"));
  EXPECT_THAT(message, HasSubstr("2 runs with results kept bitwise"));
  EXPECT_THAT(message, HasSubstr("repaired from the journals: " + old_grid.runs[0].id()));
  const ResultsFile file = ResultsFile::open_read_only(out_);
  EXPECT_TRUE(file.damaged_rows().empty());
  EXPECT_TRUE(file.file_damage().empty());
  for (int run = 0; run < file.num_runs(); ++run) {
    const auto it = original_.find(grid.runs[run].canonical());
    if (it != original_.end()) testing_util::expect_bit_equal(it->second, file.read_run(run));
  }
}

// With the stored sweep text damaged as well, nothing tells the row's run:
// refused naming both, the file untouched.
TEST_F(WriteGrownResultsTest, ADamagedCanonicalCellWithADamagedSweepTextIsRefused) {
  create_original();
  {
    h5::File file = h5::File::open(out_, h5::Access::kReadWrite);
    std::string text = file.string_attribute("/", "sweep_text");
    text[text.find("steps = 30") + 8] = '7';
    file.set_attribute("/", "sweep_text", text);
    std::string canonical = grid_of(kSweep).runs[1].canonical();
    canonical[canonical.find("steps=30") + 6] = '7';
    file.write_string_rows("/runs/canonical", 1, {canonical});
  }
  const std::string before = testing_util::read_all(out_);
  const SweepSpec grown =
      parse_sweep_text(edited(kSweep, "seeds = [0, 1]", "seeds = [0, 1, 2]"), "sweep.toml");
  try {
    write_grown_results(out_, grown, expand_grid(grown), "v2");
    FAIL() << "a damaged canonical column was used";
  } catch (const std::exception& e) {
    EXPECT_THAT(e.what(), HasSubstr("/runs/canonical"));
    EXPECT_THAT(e.what(), HasSubstr("@sweep_text"));
    EXPECT_THAT(e.what(), HasSubstr("move the file aside"));
  }
  EXPECT_EQ(testing_util::read_all(out_), before);
}

}  // namespace
}  // namespace phnn
