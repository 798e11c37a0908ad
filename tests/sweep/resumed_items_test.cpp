// tests/sweep/resumed_items_test.cpp — item state files
// (phnn/store/cell_checkpoint.h): bytes round-trip, a torn or damaged file
// is reported and never read as a state; saved states of pending runs become
// items of exactly their runs, stale ones are deleted
// (phnn/sweep/resumed_items.h).
#include "phnn/sweep/resumed_items.h"

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/store/cell_checkpoint.h"
#include "phnn/store/journal.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;

class ResumedItemsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = ::testing::TempDir() + "phnn_resumed_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".h5";
    clean();
  }
  void TearDown() override { clean(); }
  void clean() const {
    for (const auto& p : list_cell_checkpoints(out_)) remove_cell_checkpoint(p);
    ::rmdir(journal_directory(out_).c_str());
  }
  static std::string read(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  static void write(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
  }
  std::string out_;
};

TEST_F(ResumedItemsTest, StatesRoundTripAndDamageIsNeverRead) {
  const std::string state("\0a\nb\xff\nfnv1a64 0\n", 17);  // bytes our layout uses too
  const std::string path = cell_checkpoint_path(out_, "k");
  CellCheckpoint got;
  std::string problem;
  EXPECT_FALSE(read_cell_checkpoint(path, &got, &problem));  // none yet
  EXPECT_EQ(problem, "");
  write_cell_checkpoint(path, CellCheckpoint{"k\nids", state, 42});
  write_cell_checkpoint(path, CellCheckpoint{"k\nids", state + "2", 43});  // replaces
  ASSERT_TRUE(read_cell_checkpoint(path, &got, &problem));
  EXPECT_EQ(got.key, "k\nids");
  EXPECT_EQ(got.state, state + "2");
  EXPECT_EQ(got.step, 43);
  EXPECT_EQ(list_cell_checkpoints(out_), std::vector<std::string>{path});
  const std::string good = read(path);
  // Every truncation and every single-byte change is refused as damaged.
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (const std::string& bad : {good.substr(0, i), good.substr(0, i) + char(good[i] ^ 0x20) +
                                                          good.substr(i + 1)}) {
      write(path, bad);
      problem.clear();
      EXPECT_FALSE(read_cell_checkpoint(path, &got, &problem)) << i;
      EXPECT_THAT(problem, HasSubstr("damaged or torn")) << i;
    }
  }
}

// A 2-cell sweep: 3 seeds of each of 2 models.
SweepSpec two_cells() {
  return parse_sweep_text(
      "name = \"t\"\n[grid]\nsystems = [\"harmonic\"]\nmodels = [\"node-rk2\", \"phnn-s-rk2\"]\n"
      "seeds = \"0-2\"\n",
      "t.toml");
}

TEST_F(ResumedItemsTest, StatesOfPendingRunsBecomeTheirItemsAndStaleOnesGo) {
  const SweepSpec spec = two_cells();
  const Grid grid = expand_grid(spec);
  ASSERT_EQ(grid.cells.size(), 2u);
  const auto& a = grid.cells[0].runs;
  const auto& b = grid.cells[1].runs;
  std::vector<std::vector<int>> pending = {a, {b[0], b[1]}};  // b[2] finished
  auto save = [&](const std::vector<int>& runs, const std::string& hash) {
    const std::string key = item_key(grid, runs, hash);
    write_cell_checkpoint(cell_checkpoint_path(out_, key), CellCheckpoint{key, "s", 1});
  };
  save({a[1], a[2]}, spec.text_hash);     // resumed
  save({b[1], b[2]}, spec.text_hash);     // b[2] is finished: stale
  save({a[0]}, "0123456789abcdef");       // another sweep's: stale
  write(journal_directory(out_) + "/cell-0000000000000000.state", "torn");  // damaged
  const auto groups = resumed_groups(grid, &pending, out_, spec.text_hash);
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_EQ(groups[0], (std::vector<int>{a[1], a[2]}));
  EXPECT_EQ(pending[0], (std::vector<int>{a[0]}));
  EXPECT_EQ(pending[1], (std::vector<int>{b[0], b[1]}));
  EXPECT_EQ(list_cell_checkpoints(out_).size(), 1u);  // the stale and damaged ones deleted
  const auto items = with_resumed(grid, groups, plan_work(grid, pending, 2).items);
  ASSERT_GE(items.size(), 3u);
  EXPECT_EQ(items[0].runs, groups[0]);
  EXPECT_EQ(items[0].cell, 0);
  EXPECT_EQ(items[0].estimated_cost_s, grid.cells[0].cost_s(2));
  std::size_t runs = 0;
  for (const auto& item : items) runs += item.runs.size();
  EXPECT_EQ(runs, 5u);  // every pending run exactly once
}

// States of runs trained ahead of the round in progress (not pending, in
// `keep`) stay for a later round; without `keep` they go like any other.
TEST_F(ResumedItemsTest, StatesOfRunsTrainedAheadStayUntilNoRoundCanAskForThem) {
  const SweepSpec spec = two_cells();
  const Grid grid = expand_grid(spec);
  const auto& a = grid.cells[0].runs;
  const auto& b = grid.cells[1].runs;
  const std::string key = item_key(grid, {b[1], b[2]}, spec.text_hash);
  write_cell_checkpoint(cell_checkpoint_path(out_, key), CellCheckpoint{key, "s", 1});
  std::vector<std::vector<int>> pending = {a, {}};
  const std::vector<std::vector<int>> keep = {{}, {b[1], b[2]}};
  EXPECT_TRUE(resumed_groups(grid, &pending, out_, spec.text_hash, keep).empty());
  EXPECT_EQ(list_cell_checkpoints(out_).size(), 1u);  // kept, not resumed
  EXPECT_EQ(pending[0], a);
  const std::vector<std::vector<int>> other = {{}, {b[2]}};  // not all of its runs
  resumed_groups(grid, &pending, out_, spec.text_hash, other);
  EXPECT_TRUE(list_cell_checkpoints(out_).empty());
}

}  // namespace
}  // namespace phnn
