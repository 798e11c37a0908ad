// tests/apps/reduce_command_test.cpp — `phnn reduce` end to end on a small
// results file written without training (rows from tests/sweep/sample_results.h).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "sweep/sample_results.h"
#include "test_util.h"
#include "phnn/store/journal.h"
#include "phnn/sweep/grid.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

constexpr const char* kSweepText = R"(name = "reduce-test"
[grid]
systems = ["harmonic", "duffing"]
models = ["node-rk2", "phnn-s-dg"]
seeds = [0, 1, 2]
[study.a]
n_train = [25, 100]
)";

// RFC 4180 records (quoted fields may hold commas, quotes and line breaks).
std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows(1);
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') field += text[++i];
      else if (c == '"') quoted = false;
      else field += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',' || c == '\n') {
      rows.back().push_back(field);
      field.clear();
      if (c == '\n') rows.emplace_back();
    } else {
      field += c;
    }
  }
  rows.pop_back();  // after the last "\n"
  return rows;
}

class ReduceCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "phnn_reduce_" + std::to_string(::getpid()) + ".h5";
    grid_ = expand_grid(parse_sweep_text(kSweepText, "reduce-test.toml"));
    std::vector<std::string> studies;
    for (const auto& names : grid_.run_studies) {
      std::string joined;
      for (const std::string& n : names) joined += (joined.empty() ? "" : ",") + n;
      studies.push_back(joined);
    }
    const ResultsLayout layout = testing_util::sample_layout();
    ResultsFile file = ResultsFile::create(path_, MPI_COMM_NULL, grid_.runs, studies,
                                           "reduce-test", kSweepText, "hash", "test", layout);
    // The last row stays pending.
    for (int row = 0; row + 1 < static_cast<int>(grid_.runs.size()); ++row) {
      file.write_run(row, testing_util::sample_result(row, layout));
    }
    file.close();
  }
  void TearDown() override {
    std::remove(path_.c_str());
    remove_journals(path_);
  }

  int reduce(const std::string& args, std::string* output) const {
    return testing_util::run_shell(std::string(PHNN_BINARY) + " reduce " + path_ + " " + args,
                                   output);
  }

  std::string path_;
  Grid grid_;
};

TEST_F(ReduceCommandTest, PerRunCsvHasOneRowPerRunWithAxesAndExactValues) {
  std::string csv;
  ASSERT_EQ(reduce("--format csv --per-run", &csv), 0) << csv;
  const auto rows = parse_csv(csv);
  ASSERT_EQ(rows.size(), grid_.runs.size() + 1);  // header + one per run
  const std::vector<std::string>& header = rows[0];
  const auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<std::size_t>(it - header.begin());
  };
  for (const char* axis : {"system", "model", "integrator", "size", "n_train", "regularizer",
                           "seed", "cubic_stiffness", "damping", "steps", "learning_rate",
                           "energy_min", "num_validation", "newton_max_iterations"}) {
    column(axis);
  }
  for (std::size_t row = 0; row < grid_.runs.size(); ++row) {
    const std::vector<std::string>& fields = rows[row + 1];
    ASSERT_EQ(fields.size(), header.size()) << "row " << row;
    const RunConfig& run = grid_.runs[row];
    EXPECT_EQ(fields[column("run_id")], run.id());
    EXPECT_EQ(fields[column("system")], to_string(run.system));
    EXPECT_EQ(fields[column("model_label")], model_label(run.model, run.integrator));
    EXPECT_EQ(fields[column("n_train")], std::to_string(run.n_train));
    EXPECT_EQ(fields[column("seed")], std::to_string(run.seed));
    EXPECT_EQ(fields[column("studies")], "a");
    if (row + 1 == grid_.runs.size()) {
      EXPECT_EQ(fields[column("status")], "pending");
      EXPECT_EQ(fields[column("mse")], "nan");
      continue;
    }
    const RunResult expected = testing_util::sample_result(static_cast<int>(row),
                                                           testing_util::sample_layout());
    EXPECT_EQ(fields[column("status")], to_string(expected.status));
    EXPECT_EQ(fields[column("message")], expected.message);
    // strtod of "%.17g" gives the stored double back, bit for bit.
    const double mse = std::strtod(fields[column("mse")].c_str(), nullptr);
    if (std::isnan(expected.mse)) {
      EXPECT_EQ(fields[column("mse")], "nan");
    } else {
      EXPECT_EQ(testing_util::bits(mse), testing_util::bits(expected.mse)) << "row " << row;
    }
    EXPECT_EQ(testing_util::bits(std::strtod(fields[column("wall_time_s")].c_str(), nullptr)),
              testing_util::bits(expected.wall_time_s));
    EXPECT_EQ(testing_util::bits(std::strtod(fields[column("train_seconds")].c_str(), nullptr)),
              testing_util::bits(expected.train_seconds));
    EXPECT_EQ(fields[column("best_step")], std::to_string(expected.best_step));
    EXPECT_EQ(fields[column("steps_taken")], std::to_string(expected.steps));
    EXPECT_EQ(fields[column("newton_failures")], std::to_string(expected.newton_failures));
    EXPECT_EQ(fields[column("trace_points")], std::to_string(expected.trace.size()));
    const auto number = [&](const char* name) {
      return testing_util::bits(std::strtod(fields[column(name)].c_str(), nullptr));
    };
    if (expected.trace.empty()) {
      EXPECT_EQ(fields[column("initial_validation_loss")], "nan");
      EXPECT_EQ(fields[column("final_rho")], "nan");
      continue;
    }
    const TracePoint& first = expected.trace.front();
    const TracePoint& last = expected.trace.back();
    EXPECT_EQ(number("initial_validation_loss"), testing_util::bits(first.validation_loss));
    EXPECT_EQ(number("final_validation_loss"), testing_util::bits(last.validation_loss));
    EXPECT_EQ(number("final_kappa"), testing_util::bits(last.kappa));
    EXPECT_EQ(number("final_sigma_max"), testing_util::bits(last.sigma_max));
    EXPECT_EQ(number("final_rho"), testing_util::bits(last.rho));
    if (!std::isnan(last.train_loss)) {
      EXPECT_EQ(number("final_train_loss"), testing_util::bits(last.train_loss));
    }
  }
  EXPECT_THAT(csv, HasSubstr(",diverged,inf,"));
}

// A damaged row (here: one bit of its best_step, so its checksum fails)
// reads as pending with unknown results: none of its stored numbers, which
// are not to be trusted, reaches the per-run CSV.
TEST_F(ReduceCommandTest, ADamagedRowShowsNoneOfItsNumbers) {
  {
    h5::File raw = h5::File::open(path_, h5::Access::kReadWrite);
    std::int64_t step = raw.read_ints("/runs/best_step", 3, 1).at(0) ^ (std::int64_t{1} << 40);
    raw.write_rows("/runs/best_step", 3, 1, &step);
    raw.close();
  }
  std::string out;
  ASSERT_EQ(reduce("--per-run", &out), 0) << out;
  // stderr first (the damage is named there), then the CSV.
  ASSERT_NE(out.find("run_id,"), std::string::npos) << out;
  EXPECT_THAT(out.substr(0, out.find("run_id,")), HasSubstr("damaged"));
  const auto rows = parse_csv(out.substr(out.find("run_id,")));
  const std::vector<std::string>& header = rows.at(0);
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const std::vector<std::string>& damaged = rows.at(4);  // row 3
  EXPECT_EQ(damaged.at(column("run_id")), grid_.runs[3].id());
  EXPECT_EQ(damaged.at(column("status")), "pending");
  EXPECT_EQ(damaged.at(column("mse")), "nan");
  EXPECT_EQ(damaged.at(column("best_step")), "0");
  EXPECT_EQ(damaged.at(column("trace_points")), "0");
  EXPECT_THAT(damaged.at(column("message")), HasSubstr("damaged row"));
  EXPECT_EQ(rows.at(5).at(column("status")),
            to_string(testing_util::sample_result(4, testing_util::sample_layout()).status));
}

TEST_F(ReduceCommandTest, TablesShowIntervalsAndNeverNan) {
  std::string out;
  ASSERT_EQ(reduce("", &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("bootstrap 95 % interval of the median"));
  EXPECT_THAT(out, HasSubstr("### Study a — duffing (columns: n_train)"));
  EXPECT_THAT(out, Not(HasSubstr("nan")));
  ASSERT_EQ(reduce("--format csv", &out), 0) << out;
  EXPECT_THAT(out, StartsWith("study,system,model,axis,column,median,q25,q75,iqr,ci_low,ci_high,"));
  ASSERT_EQ(reduce("--seeds-summary", &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("below / above"));
  ASSERT_EQ(reduce("--seeds-summary --format csv", &out), 0) << out;
  EXPECT_THAT(out, StartsWith("study,system,model,axis,column,midpoint,below,above,"));
}

TEST_F(ReduceCommandTest, PerRunIsCsvAndExcludesSeedsSummary) {
  std::string out, csv;
  ASSERT_EQ(reduce("--per-run", &out), 0) << out;  // no --format csv needed
  ASSERT_EQ(reduce("--per-run --format csv", &csv), 0) << csv;
  EXPECT_EQ(out, csv);
  EXPECT_THAT(out, StartsWith("run_id,"));
  EXPECT_EQ(reduce("--per-run --format latex", &out), 2);
  EXPECT_THAT(out, HasSubstr("--per-run writes CSV only; drop --format latex"));
  EXPECT_EQ(reduce("--per-run --format csv --seeds-summary", &out), 2);
  EXPECT_THAT(out, HasSubstr("exclude each other"));
}

// --comparisons: the exported CSV, one line per pair of models in a column
// (2 systems x 2 columns x 1 pair) and per column against the first in a row
// (2 systems x 2 rows x 1 pair); --delta must exceed 1; exclusive with the
// other views.
TEST_F(ReduceCommandTest, ComparisonsAreOneCsvLinePerPairOfCells) {
  std::string out;
  ASSERT_EQ(reduce("--comparisons", &out), 0) << out;
  const auto rows = parse_csv(out);
  ASSERT_EQ(rows.size(), 1u + 8u) << out;
  EXPECT_EQ(rows[0][0], "a");
  EXPECT_EQ(rows[0].back(), "reading");
  EXPECT_EQ(rows[1][0], "a/harmonic/NODE-RK2/25");
  EXPECT_EQ(rows[1][1], "a/harmonic/PHNN-S-DG/25");
  for (std::size_t r = 1; r < rows.size(); ++r) {
    EXPECT_EQ(rows[r][15], "1.500000e+00");
    EXPECT_EQ(rows[r][16], "undecided") << "3 seeds are too few for a reading";
  }
  ASSERT_EQ(reduce("--comparisons --delta 2", &out), 0) << out;
  EXPECT_THAT(out, HasSubstr(",2.000000e+00,undecided"));
  EXPECT_EQ(reduce("--comparisons --delta 1", &out), 2);
  EXPECT_THAT(out, HasSubstr("--delta 1 must be greater than 1"));
  EXPECT_EQ(reduce("--comparisons --per-run", &out), 2);
  EXPECT_THAT(out, HasSubstr("exclude each other"));
}

// --stat: a checked set (median | iqm); iqm names the CSV column and the
// Markdown text "IQM"; the views without cell statistics refuse it.
TEST_F(ReduceCommandTest, StatIqmNamesItsStatisticAndIsACheckedSet) {
  std::string out;
  ASSERT_EQ(reduce("--format csv --stat iqm", &out), 0) << out;
  EXPECT_THAT(out, StartsWith("study,system,model,axis,column,iqm,q25,"));
  ASSERT_EQ(reduce("--format csv --stat median", &out), 0) << out;
  EXPECT_THAT(out, StartsWith("study,system,model,axis,column,median,q25,"));
  ASSERT_EQ(reduce("--stat iqm", &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("Cells: IQM (interquartile mean"));
  ASSERT_EQ(reduce("--format latex --stat iqm", &out), 0) << out;
  EXPECT_THAT(out, HasSubstr("IQM [IQR] (bootstrap 95~\\% interval of the IQM)"));
  EXPECT_EQ(reduce("--stat mean", &out), 2);
  EXPECT_THAT(out, HasSubstr("--stat: unknown statistic \"mean\" (did you mean \"median\"?); "
                             "expected one of: median, iqm"));
  EXPECT_EQ(reduce("--comparisons --stat iqm", &out), 2);
  EXPECT_THAT(out, HasSubstr("drop --stat"));
}

// --seed-lists: one block of comparisons per list, led by its number; the
// first list repeats the file's own seeds (the same comparisons as without
// it); a seed no run has, a token that is no seed, or no --comparisons are
// refused naming the place.
TEST_F(ReduceCommandTest, SeedListsPrintTheComparisonsOfEachList) {
  std::string plain, out;
  ASSERT_EQ(reduce("--comparisons", &plain), 0) << plain;
  const std::string lists = path_ + ".lists";
  std::ofstream(lists) << "# resamples\n0,1,2\n2,2,0\n";
  ASSERT_EQ(reduce("--comparisons --seed-lists " + lists, &out), 0) << out;
  const auto rows = parse_csv(out), own = parse_csv(plain);
  ASSERT_EQ(rows.size(), 1 + 2 * (own.size() - 1)) << out;
  EXPECT_EQ(rows[0][0], "list");
  for (std::size_t r = 1; r < own.size(); ++r) {
    EXPECT_EQ(rows[r][0], "1");
    EXPECT_EQ(std::vector<std::string>(rows[r].begin() + 1, rows[r].end()), own[r]);
    EXPECT_EQ(rows[r + own.size() - 1][0], "2");
  }
  std::ofstream(lists) << "0,1\n0,7\n";
  EXPECT_EQ(reduce("--comparisons --seed-lists " + lists, &out), 2);
  EXPECT_THAT(out, HasSubstr(lists + ":2: seed 7 has no run in the tables (their seeds: 0,1,2)"));
  std::ofstream(lists) << "0,x\n";
  EXPECT_EQ(reduce("--comparisons --seed-lists " + lists, &out), 2);
  EXPECT_THAT(out, HasSubstr(lists + ":1: \"x\" is not a seed"));
  EXPECT_EQ(reduce("--seed-lists " + lists, &out), 2);
  EXPECT_THAT(out, HasSubstr("--seed-lists needs --comparisons"));
  std::remove(lists.c_str());
}

// A sweep file given instead of its results file: named as such, and no
// advice to delete it or to pass an --out that reduce does not have.
TEST(ReduceCommandMissingFileTest, ASweepFileIsNamedWithoutDeleteAdvice) {
  std::string out;
  const std::string sweep = std::string(PHNN_SOURCE_DIR) + "/sweeps/tiny.toml";
  EXPECT_EQ(testing_util::run_shell(std::string(PHNN_BINARY) + " reduce " + sweep, &out), 1);
  EXPECT_THAT(out, HasSubstr("this looks like a sweep file: give the results file its sweep "
                             "wrote"));
  EXPECT_THAT(out, Not(HasSubstr("delete")));
  EXPECT_THAT(out, Not(HasSubstr("--out")));
}

// A missing file gets a reducer's hint, not the sweep's "start a new sweep
// instead of resuming".
TEST(ReduceCommandMissingFileTest, NamesThePathWithoutSweepAdvice) {
  std::string out;
  EXPECT_EQ(testing_util::run_shell(std::string(PHNN_BINARY) + " reduce /nonexistent-dir/r.h5",
                                    &out),
            1);
  EXPECT_THAT(out, HasSubstr("/nonexistent-dir/r.h5: no such results file; check the path"));
  EXPECT_THAT(out, Not(HasSubstr("start a new sweep")));
}

}  // namespace
}  // namespace phnn
