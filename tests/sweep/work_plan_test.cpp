// tests/sweep/work_plan_test.cpp
#include "phnn/sweep/work_plan.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace phnn {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

const std::string kSweeps = std::string(PHNN_SOURCE_DIR) + "/sweeps/";

// Plan costs are sums of at most 1200 cell costs: relative rounding ~1e-13.
constexpr double kCostTolerance = 1e-9;

Grid paper_grid() { return expand_grid(parse_sweep_file(kSweeps + "paper.toml")); }

// A grid of cells with hand-set costs cost_s(E) = fixed + E * member, each
// with `runs` runs (configurations do not matter to the planner).
struct CellCost {
  double fixed, member;
  int runs;
};
Grid hand_grid(const std::vector<CellCost>& costs) {
  Grid grid;
  for (const CellCost& c : costs) {
    Cell cell;
    cell.key = "cell" + std::to_string(grid.cells.size());
    cell.fixed_cost_s = c.fixed;
    cell.member_cost_s = c.member;
    for (int r = 0; r < c.runs; ++r) {
      cell.runs.push_back(static_cast<int>(grid.runs.size()));
      grid.runs.emplace_back();
    }
    cell.estimated_cost_s = cell.cost_s(c.runs);
    grid.cells.push_back(cell);
  }
  return grid;
}

// Every run of `pending` is in exactly one item, items are contiguous pieces
// of their cell's pending list, costs match the cell's, largest first.
void expect_partition(const Grid& grid, const std::vector<std::vector<int>>& pending,
                      const WorkPlan& plan) {
  std::map<int, int> seen;  // run -> items containing it
  for (std::size_t i = 0; i < plan.items.size(); ++i) {
    const WorkItem& item = plan.items[i];
    ASSERT_FALSE(item.runs.empty());
    const std::vector<int>& cell = pending[static_cast<std::size_t>(item.cell)];
    const auto start = std::find(cell.begin(), cell.end(), item.runs.front());
    ASSERT_NE(start, cell.end());
    EXPECT_TRUE(std::equal(item.runs.begin(), item.runs.end(), start)) << "item " << i;
    for (int run : item.runs) ++seen[run];
    EXPECT_DOUBLE_EQ(item.estimated_cost_s,
                     grid.cells[item.cell].cost_s(static_cast<int>(item.runs.size())));
    if (i > 0) {
      EXPECT_GE(plan.items[i - 1].estimated_cost_s, item.estimated_cost_s);
    }
  }
  std::size_t expected = 0;
  for (const auto& runs : pending) {
    expected += runs.size();
    for (int run : runs) EXPECT_EQ(seen[run], 1) << "run " << run;
  }
  EXPECT_EQ(seen.size(), expected);
}

std::vector<std::vector<int>> all_runs(const Grid& grid) {
  std::vector<std::vector<int>> pending;
  for (const Cell& cell : grid.cells) pending.push_back(cell.runs);
  return pending;
}

// Closed form: 2 ranks, cell A = 1 + 2E with 4 runs (9 s), cell B = 1 + E
// with 2 runs (3 s). Whole: A | B, makespan 9. Any split costs 1 s per extra
// group, so a makespan of 7 needs exactly 14 s of items split evenly: A in
// two (5, 5) and B in two (2, 2), LPT 5 + 2 | 5 + 2 = 7, the optimum (A in
// two with B whole: 8; A in three (5, 3, 3) with B split: 15 s > 2 x 7). A
// uniform cost target cannot find it (it never cuts B, which fits under
// any target >= 5); the class-wise refinement does. Efficiency 12 / (2 x 7).
TEST(WorkPlanTest, SimulatedScheduleMatchesAHandCheckedExample) {
  const Grid grid = hand_grid({{1.0, 2.0, 4}, {1.0, 1.0, 2}});
  const WorkPlan plan = plan_work(grid, /*ranks=*/2);
  ASSERT_EQ(plan.items.size(), 4u);
  EXPECT_THAT(plan.items[0].runs, ElementsAre(0, 1));
  EXPECT_THAT(plan.items[1].runs, ElementsAre(2, 3));
  EXPECT_THAT(plan.items[2].runs, ElementsAre(4));
  EXPECT_THAT(plan.items[3].runs, ElementsAre(5));
  EXPECT_DOUBLE_EQ(plan.makespan_s, 7.0);
  EXPECT_DOUBLE_EQ(plan.unsplit_cost_s, 12.0);
  EXPECT_DOUBLE_EQ(plan.cost_s, 14.0);  // two extra groups: + 2 s fixed cost
  EXPECT_DOUBLE_EQ(plan.efficiency(), 12.0 / 14.0);
  EXPECT_EQ(plan.split_cells, 2);
  SplitOptions off;
  off.mode = SplitOptions::Mode::kOff;
  EXPECT_DOUBLE_EQ(plan_work(grid, 2, off).makespan_s, 9.0);
}

// A split that cannot shorten the schedule is not taken: 2 ranks, a single
// run of 10 s (cannot be split) and a cell of 4 runs costing 1 + E (5 s).
// The makespan is 10 however the second cell is cut, so it stays whole (the
// cheapest of the equally short plans).
TEST(WorkPlanTest, NoSplitWhereItCannotShortenTheSchedule) {
  const Grid grid = hand_grid({{0.0, 10.0, 1}, {1.0, 1.0, 4}});
  const WorkPlan plan = plan_work(grid, /*ranks=*/2);
  EXPECT_EQ(plan.items.size(), 2u);
  EXPECT_EQ(plan.split_cells, 0);
  EXPECT_DOUBLE_EQ(plan.makespan_s, 10.0);
  EXPECT_DOUBLE_EQ(plan.cost_s, plan.unsplit_cost_s);
}

// Closed form: one cell of n = 12 runs, cost f + E m, on N = 4 ranks. The
// shortest LPT schedule is 4 groups of 3: makespan f + 3m = 7 (3 groups of
// 4: 9; 6 groups of 2 take two rounds: 10; 12 single runs: 3 rounds, 9),
// efficiency (f + 12m) / (4 (f + 3m)).
TEST(WorkPlanTest, OneCellOnFourRanksIsSplitIntoFourEqualGroups) {
  const double f = 1.0, m = 2.0;
  const Grid grid = hand_grid({{f, m, 12}});
  const WorkPlan plan = plan_work(grid, /*ranks=*/4);
  ASSERT_EQ(plan.items.size(), 4u);
  for (const WorkItem& item : plan.items) EXPECT_EQ(item.runs.size(), 3u);
  EXPECT_DOUBLE_EQ(plan.makespan_s, f + 3 * m);
  EXPECT_DOUBLE_EQ(plan.efficiency(), (f + 12 * m) / (4 * (f + 3 * m)));
  expect_partition(grid, all_runs(grid), plan);
}

TEST(WorkPlanTest, PlanIsDeterministicAndCoversEverySeedOnce) {
  const Grid grid = paper_grid();
  for (int ranks : {1, 2, 16, 64, 128, 1200}) {
    SCOPED_TRACE(std::to_string(ranks) + " ranks");
    const WorkPlan a = plan_work(grid, ranks), b = plan_work(grid, ranks);
    ASSERT_EQ(a.items.size(), b.items.size());
    for (std::size_t i = 0; i < a.items.size(); ++i) {
      EXPECT_EQ(a.items[i].cell, b.items[i].cell);
      EXPECT_EQ(a.items[i].runs, b.items[i].runs);
    }
    EXPECT_EQ(a.makespan_s, b.makespan_s);
    expect_partition(grid, all_runs(grid), a);
    EXPECT_NEAR(a.unsplit_cost_s, grid.estimated_cost_s, kCostTolerance * grid.estimated_cost_s);
    EXPECT_GE(a.cost_s, a.unsplit_cost_s * (1 - kCostTolerance));
  }
}

TEST(WorkPlanTest, PaperGridIsNotSplitOnFewRanks) {
  const Grid grid = paper_grid();
  for (int ranks : {1, 2}) {
    const WorkPlan plan = plan_work(grid, ranks);
    EXPECT_EQ(plan.items.size(), 120u) << ranks;
    EXPECT_EQ(plan.split_cells, 0) << ranks;
    EXPECT_EQ(plan.cost_s, plan.unsplit_cost_s) << "no core-hours wasted";
  }
}

// Efficiency of the simulated schedule under the default cost model (the
// refit of docs/BENCHMARKS.md): the speed issue's target is >= 90 % at 128
// ranks (91.4 % with this model). A refit that moves it below says so here.
TEST(WorkPlanTest, PaperGridEfficiencyBySimulation) {
  const Grid grid = paper_grid();
  SplitOptions off;
  off.mode = SplitOptions::Mode::kOff;
  EXPECT_GE(plan_work(grid, 16).efficiency(), 0.95);
  EXPECT_GE(plan_work(grid, 64).efficiency(), 0.92);
  const WorkPlan plan = plan_work(grid, 128);
  EXPECT_GE(plan.efficiency(), 0.90);
  EXPECT_LT(plan_work(grid, 128, off).efficiency(), 0.3);
}

TEST(WorkPlanTest, PartiallyFinishedCellsPlanOnlyTheirMissingRuns) {
  const Grid grid = hand_grid({{1.0, 2.0, 10}, {1.0, 1.0, 4}, {5.0, 1.0, 3}});
  // Cell 0 misses seeds 1, 2, 5, 9; cell 1 is done; cell 2 misses all.
  const std::vector<std::vector<int>> pending = {{1, 2, 5, 9}, {}, {14, 15, 16}};
  for (int ranks : {1, 2, 3, 8}) {
    const WorkPlan plan = plan_work(grid, pending, ranks);
    expect_partition(grid, pending, plan);
    EXPECT_EQ(plan.cells, 2);
    EXPECT_DOUBLE_EQ(plan.unsplit_cost_s, (1.0 + 4 * 2.0) + (5.0 + 3 * 1.0));
  }
  EXPECT_THROW(plan_work(grid, {{0}}, 2), std::invalid_argument);           // one list per cell
  EXPECT_THROW(plan_work(grid, {{0}, {0}, {}}, 2), std::invalid_argument);  // 0 is not in cell 1
}

TEST(WorkPlanTest, MaxGroupSizeCapsEveryItem) {
  const Grid grid = paper_grid();
  SplitOptions options;
  options.max_group_size = 3;
  const WorkPlan plan = plan_work(grid, /*ranks=*/2, options);
  for (const WorkItem& item : plan.items) EXPECT_LE(item.runs.size(), 3u);
  EXPECT_EQ(plan.items.size(), 480u);  // 10 seeds -> 4 groups (3, 3, 2, 2), 120 cells
  expect_partition(grid, all_runs(grid), plan);
}

TEST(WorkPlanTest, SplitOptionsRejectContradictionsAndNamesTheField) {
  SplitOptions options;
  options.max_group_size = -1;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<std::invalid_argument>(HasSubstr("max_group_size = -1")));
  options.max_group_size = 2;
  options.mode = SplitOptions::Mode::kOff;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<std::invalid_argument>(HasSubstr("needs mode auto")));
  EXPECT_EQ(parse_split_mode("off"), SplitOptions::Mode::kOff);
  EXPECT_EQ(to_string(parse_split_mode("auto")), "auto");
  EXPECT_THROW(parse_split_mode("sometimes"), std::invalid_argument);
  EXPECT_THROW(plan_work(paper_grid(), 0), std::invalid_argument);
}

TEST(WorkPlanTest, DryRunSummaryPrintsOneScheduleLinePerRankCount) {
  const Grid grid = paper_grid();
  const std::string summary = dry_run_summary(grid, {2, 128});
  EXPECT_THAT(summary, HasSubstr("core-hours unsplit"));
  EXPECT_THAT(summary, HasSubstr("\n  2 ranks: 120 items (120 whole cells), makespan "));
  EXPECT_THAT(summary, HasSubstr("\n  128 ranks: "));
  EXPECT_THAT(summary, HasSubstr("efficiency"));
  EXPECT_THAT(summary, HasSubstr("Impact of the model size"));
  EXPECT_EQ(summary.find("\n  128 ranks: 120 items"), std::string::npos) << "split at 128 ranks";
  EXPECT_THROW(dry_run_summary(grid, {0}), std::invalid_argument);
  EXPECT_THROW(dry_run_summary(grid, {}), std::invalid_argument);
}

// One CSV line per item in plan order; the lines list every run once.
TEST(WorkPlanTest, PlanItemsCsvListsTheItemsInPlanOrder) {
  const Grid grid = paper_grid();
  const WorkPlan plan = plan_work(grid, /*ranks=*/128);
  std::istringstream csv(plan_items_csv(grid, plan));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "item,cell,runs,estimated_s,run_ids");
  std::multiset<std::string> ids;
  std::size_t item = 0;
  for (; std::getline(csv, line); ++item) {
    std::vector<std::string> fields;
    std::istringstream row(line);
    for (std::string f; std::getline(row, f, ',');) fields.push_back(f);
    ASSERT_EQ(fields.size(), 5u) << line;
    ASSERT_LT(item, plan.items.size());
    EXPECT_EQ(std::stoul(fields[0]), item);
    EXPECT_EQ(std::stoi(fields[1]), plan.items[item].cell);
    EXPECT_EQ(std::stoul(fields[2]), plan.items[item].runs.size());
    EXPECT_NEAR(std::stod(fields[3]), plan.items[item].estimated_cost_s,
                1e-5 * plan.items[item].estimated_cost_s);
    std::istringstream run_ids(fields[4]);
    std::size_t k = 0;
    for (std::string id; run_ids >> id; ++k) {
      ASSERT_LT(k, plan.items[item].runs.size());
      EXPECT_EQ(id, grid.runs[plan.items[item].runs[k]].id());
      ids.insert(id);
    }
    EXPECT_EQ(k, plan.items[item].runs.size());
  }
  EXPECT_EQ(item, plan.items.size());
  EXPECT_EQ(ids.size(), grid.runs.size());
  for (const RunConfig& run : grid.runs) EXPECT_EQ(ids.count(run.id()), 1u) << run.id();
}

// One CSV line per cell, largest first, whose estimates add up to the grid's
// and whose run ids are exactly the grid's runs.
TEST(WorkPlanTest, CellCostsCsvListsEveryCellAndRun) {
  const Grid grid = paper_grid();
  std::istringstream csv(cell_costs_csv(grid));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line,
            "cell,system,model,size,n_train,regularizer,members,fixed_s,member_s,"
            "estimated_s,run_ids");
  double total = 0.0, previous = 1e300;
  std::set<std::string> ids;
  std::size_t cells = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> fields;
    std::istringstream row(line);
    for (std::string f; std::getline(row, f, ',');) fields.push_back(f);
    ASSERT_EQ(fields.size(), 11u) << line;
    const double estimated = std::stod(fields[9]);
    EXPECT_LE(estimated, previous) << "largest first: " << line;
    EXPECT_NEAR(estimated, std::stod(fields[7]) + std::stoi(fields[6]) * std::stod(fields[8]),
                1e-5 * estimated);
    previous = estimated;
    total += estimated;
    std::istringstream run_ids(fields[10]);
    int members = 0;
    for (std::string id; run_ids >> id; ++members) ids.insert(id);
    EXPECT_EQ(members, std::stoi(fields[6]));
    ++cells;
  }
  EXPECT_EQ(cells, grid.cells.size());
  EXPECT_NEAR(total, grid.estimated_cost_s, 1e-5 * grid.estimated_cost_s);
  std::set<std::string> expected;
  for (const RunConfig& run : grid.runs) expected.insert(run.id());
  EXPECT_EQ(ids, expected);
}

}  // namespace
}  // namespace phnn
