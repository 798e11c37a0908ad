// tests/sweep/sweep_command_test.cpp — `phnn sweep` end to end under mpiexec:
// rank-count independence, kill-and-resume, rejection of bad sweep files.
// Size: one test file per command; each end-to-end scenario needs its setup.
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/store/journal.h"
#include "h5/h5file.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

std::string temp_dir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "phnn_sweep_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str());
  return dir;
}

std::string mpiexec(int ranks) { return testing_util::mpiexec_phnn(ranks); }

int shell(const std::string& command, std::string* output = nullptr) {
  return testing_util::run_shell(command, output);
}

// Three cells, one with the DG integrator (Newton at inference), N_train >
// batch so per-member reshuffling is exercised.
const char* kSweep = R"(name = "rank-test"
[data]
num_validation = 40
num_inference = 3
[training]
steps = 30
eval_every = 10
batch_size = 16
[grid]
systems = ["duffing"]
models = ["phnn-s-dg", "phnn-jr-rk2", "node-rk2"]
n_train = [25]
seeds = [0, 1, 2]
)";

std::string write_sweep(const std::string& dir, const std::string& text) {
  const std::string path = dir + "/sweep.toml";
  std::ofstream(path) << text;
  return path;
}

// kSweep with 18 runs in 9 cells of `steps` steps: long enough to interrupt.
std::string write_long_sweep(const std::string& dir, int steps) {
  std::string text = kSweep;
  text.replace(text.find("steps = 30"), 10, "steps = " + std::to_string(steps));
  text.replace(text.find("seeds = [0, 1, 2]"), 17, "seeds = [0, 1]\nn_train = [25, 26, 27]");
  text.replace(text.find("n_train = [25]\n"), 15, "");
  return write_sweep(dir, text);
}

// Waits until a first run is journaled (true) or `limit` passes (false).
bool wait_for_first_journal(const std::string& out, std::chrono::seconds limit) {
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < limit) {
    if (!replay_journals(out).empty()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

void expect_same_run(const RunResult& a, const RunResult& b, int row) {
  SCOPED_TRACE("row " + std::to_string(row));
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.mse, b.mse);  // bitwise: == on doubles
  EXPECT_EQ(a.trajectory_errors, b.trajectory_errors);
  EXPECT_EQ(a.best_step, b.best_step);
  EXPECT_EQ(a.best_validation_loss, b.best_validation_loss);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.parameter_count, b.parameter_count);
  EXPECT_EQ(a.newton_failures, b.newton_failures);
  EXPECT_EQ(a.figure_prediction_05, b.figure_prediction_05);
  EXPECT_EQ(a.figure_prediction_075, b.figure_prediction_075);
  ASSERT_EQ(a.trace.size(), b.trace.size());
  for (std::size_t k = 0; k < a.trace.size(); ++k) {  // every column but the time
    EXPECT_EQ(a.trace[k].step, b.trace[k].step);
    EXPECT_EQ(a.trace[k].train_loss, b.trace[k].train_loss);
    EXPECT_EQ(a.trace[k].validation_loss, b.trace[k].validation_loss);
    EXPECT_EQ(a.trace[k].kappa, b.trace[k].kappa);
    EXPECT_EQ(a.trace[k].sigma_max, b.trace[k].sigma_max);
    EXPECT_EQ(a.trace[k].rho, b.trace[k].rho);
  }
}

TEST(SweepCommandTest, ResultsDoNotDependOnTheNumberOfRanksOrScheduling) {
  const std::string dir = temp_dir("ranks");
  const std::string sweep = write_sweep(dir, kSweep);
  const std::string runs[] = {"1 dynamic", "2 dynamic", "3 dynamic", "2 static"};
  std::vector<ResultsFile> files;
  for (const std::string& r : runs) {
    const int ranks = r[0] - '0';
    const bool is_static = r.find("static") != std::string::npos;
    const std::string out = dir + "/np" + r.substr(0, 1) + (is_static ? "s" : "d") + ".h5";
    std::string log;
    ASSERT_EQ(shell(mpiexec(ranks) + " sweep " + sweep + " --quiet --out " + out +
                        (is_static ? " --static" : ""),
                    &log),
              0)
        << log;
    EXPECT_THAT(log, HasSubstr(is_static ? "static scheduling" : "dynamic scheduling"));
    EXPECT_THAT(log, Not(HasSubstr("[progress]")));  // --quiet means quiet
    files.push_back(ResultsFile::open_read_only(out));
  }
  const auto statuses = files[0].read_statuses();
  ASSERT_EQ(statuses.size(), 9u);
  for (RunStatus s : statuses) EXPECT_EQ(s, RunStatus::kDone);
  for (std::size_t f = 1; f < files.size(); ++f) {
    EXPECT_EQ(files[f].read_run_ids(), files[0].read_run_ids());
    for (int row = 0; row < files[0].num_runs(); ++row) {
      expect_same_run(files[f].read_run(row), files[0].read_run(row), row);
    }
  }
}

// Under --static rank 0 sees only its own items: its progress line counts
// that share and says so (it used to report its items against the total).
TEST(SweepCommandTest, StaticProgressCountsRankZerosShare) {
  const std::string dir = temp_dir("progress");
  const std::string sweep = write_sweep(dir, kSweep);
  std::string log;
  ASSERT_EQ(shell(mpiexec(2) + " sweep " + sweep + " --static --out " + dir + "/s.h5", &log), 0)
      << log;
  EXPECT_THAT(log, HasSubstr("(rank 0's share, static scheduling)"));
  EXPECT_THAT(log, HasSubstr("Z)\n"));  // the UTC time ends the line
}

TEST(SweepCommandTest, KilledRankThenRerunCompletesEveryRunOnce) {
  const std::string dir = temp_dir("kill");
  const std::string sweep = write_long_sweep(dir, 1500);
  const std::string out = dir + "/killed.h5";
  const std::string command = mpiexec(2) + " sweep " + sweep + " --quiet --out " + out;
  // Start in the background; kill one rank once a first run is journaled.
  ASSERT_EQ(std::system((command + " > " + dir + "/first.log 2>&1 & echo $! > " + dir + "/pid").c_str()), 0);
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(wait_for_first_journal(out, std::chrono::seconds(240)))
      << "no run finished within 240 s";
  ASSERT_EQ(shell("pkill -KILL -n -f '[p]hnn sweep " + sweep + "'"), 0);
  std::ifstream pid_file(dir + "/pid");
  pid_t pid = 0;
  pid_file >> pid;
  while (::kill(pid, 0) == 0 && std::chrono::steady_clock::now() - start < std::chrono::seconds(300)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const auto finished_before = replay_journals(out).size();
  ASSERT_LT(finished_before, 18u) << "the sweep finished before the kill";
  std::string log;
  ASSERT_EQ(shell(command, &log), 0) << log;
  const ResultsFile file = ResultsFile::open_read_only(out);
  const auto ids = file.read_run_ids();
  EXPECT_EQ(std::set<std::string>(ids.begin(), ids.end()).size(), 18u);
  const Grid grid = expand_grid(parse_sweep_file(sweep));
  ASSERT_EQ(ids.size(), grid.runs.size());
  for (RunStatus s : file.read_statuses()) EXPECT_EQ(s, RunStatus::kDone);
  // Each run recorded once in the journals, before or after the kill.
  EXPECT_EQ(replay_journals(out).size(), 18u);
  EXPECT_EQ(shell("h5dump -H " + out), 0);
  RecordProperty("runs_finished_before_kill", static_cast<int>(finished_before));
}

// Slurm's --signal=USR1@T: every rank finishes its cell, takes no new one,
// the file is closed, exit status 75; the same command then completes.
TEST(SweepCommandTest, StopsCleanlyOnSignalThenResumes) {
  const std::string dir = temp_dir("signal");
  const std::string sweep = write_long_sweep(dir, 4000);
  const std::string out = dir + "/stopped.h5";
  const std::string command = mpiexec(2) + " sweep " + sweep + " --out " + out;
  ASSERT_EQ(std::system(("(" + command + " > " + dir + "/first.log 2>&1; echo $? > " + dir +
                         "/status) &").c_str()),
            0);
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(wait_for_first_journal(out, std::chrono::seconds(240)))
      << "no run finished within 240 s";
  // The ranks only (mpirun would forward it to them anyway).
  std::string ps;
  shell("ps -eo args | grep '[p]hnn sweep'", &ps);
  ASSERT_EQ(shell("pkill -USR1 -f '^" + std::string(PHNN_BINARY) + " sweep " + sweep + "'"), 0)
      << ps;
  int status = -1;
  while (std::chrono::steady_clock::now() - start < std::chrono::seconds(300)) {
    std::ifstream in(dir + "/status");
    if (in >> status) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::ifstream first_log(dir + "/first.log");
  const std::string log((std::istreambuf_iterator<char>(first_log)), std::istreambuf_iterator<char>());
  EXPECT_EQ(status, 75) << log;
  EXPECT_THAT(log, HasSubstr("stopped on a signal"));
  const auto finished = replay_journals(out).size();
  EXPECT_LT(finished, 18u);
  {
    const ResultsFile file = ResultsFile::open_read_only(out);  // closed cleanly
    int done = 0;
    for (RunStatus s : file.read_statuses()) done += s == RunStatus::kDone;
    EXPECT_EQ(static_cast<std::size_t>(done), finished);
  }
  std::string rerun;
  ASSERT_EQ(shell(command + " --quiet", &rerun), 0) << rerun;
  EXPECT_THAT(rerun, HasSubstr(std::to_string(finished) + " finished before"));
  const ResultsFile file = ResultsFile::open_read_only(out);
  for (RunStatus s : file.read_statuses()) EXPECT_EQ(s, RunStatus::kDone);
}

// Runs `phnn sweep` of `sweep` into `out` on `ranks` ranks with extra flags;
// returns the log (the test fails if the exit status is not 0).
std::string run_sweep(const std::string& sweep, const std::string& out, int ranks,
                      const std::string& flags) {
  std::string log;
  EXPECT_EQ(shell(mpiexec(ranks) + " sweep " + sweep + " --quiet --out " + out + " " + flags, &log),
            0)
      << log;
  return log;
}

void expect_same_file(const ResultsFile& a, const ResultsFile& b) {
  ASSERT_EQ(a.read_run_ids(), b.read_run_ids());
  for (int row = 0; row < a.num_runs(); ++row) expect_same_run(a.read_run(row), b.read_run(row), row);
}

// Under Slurm a session records which job, array task and restart wrote it
// (one rank, as in an array task of one task).
TEST(SweepCommandTest, ProvenanceNamesTheSlurmJobArrayTaskAndRestart) {
  const std::string dir = temp_dir("slurm_ids");
  const std::string sweep = write_sweep(dir, kSweep);
  const std::string out = dir + "/r.h5";
  std::string log;
  ASSERT_EQ(shell("SLURM_JOB_ID=4242 SLURM_ARRAY_JOB_ID=4240 SLURM_ARRAY_TASK_ID=2 "
                  "SLURM_RESTART_COUNT=1 SLURM_NTASKS=1 " + std::string(PHNN_BINARY) +
                      " sweep " + sweep + " --quiet --out " + out + " --shard 0/2",
                  &log),
            0)
      << log;
  const h5::File raw = h5::File::open(out, h5::Access::kReadOnly);
  EXPECT_EQ(raw.string_attribute("/provenance/session_0", "slurm_job"), "4242");
  EXPECT_EQ(raw.string_attribute("/provenance/session_0", "slurm_array"), "4240_2");
  EXPECT_EQ(raw.string_attribute("/provenance/session_0", "slurm_restarts"), "1");
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + sweep + " --quiet --out " + out +
                      " --shard 0/2",
                  &log),
            0)
      << log;
  const h5::File again = h5::File::open(out, h5::Access::kReadOnly);
  EXPECT_FALSE(again.has_attribute("/provenance/session_1", "slurm_job"));  // not under Slurm
}

// Stacking is exact: member groups of 1 or 2 seeds give bitwise the results
// of whole cells, on 1 and 2 ranks.
TEST(SweepCommandTest, SplitCellsGiveBitwiseTheResultsOfWholeCells) {
  const std::string dir = temp_dir("split");
  const std::string sweep = write_sweep(dir, kSweep);
  const std::string whole = dir + "/whole.h5";
  EXPECT_THAT(run_sweep(sweep, whole, 1, "--split off"), HasSubstr("to run in 3 items (3 cells, 0 split)"));
  const ResultsFile reference = ResultsFile::open_read_only(whole);
  for (RunStatus s : reference.read_statuses()) EXPECT_EQ(s, RunStatus::kDone);
  const std::pair<int, int> cases[] = {{1, 1}, {2, 2}, {2, 1}, {3, 1}};  // ranks, max group size
  for (const auto& [ranks, group] : cases) {
    SCOPED_TRACE(std::to_string(ranks) + " ranks, groups of " + std::to_string(group));
    const std::string out = dir + "/split" + std::to_string(ranks) + std::to_string(group) + ".h5";
    const std::string log = run_sweep(sweep, out, ranks, "--max-group-size " + std::to_string(group));
    // Groups of at most 2 of 3 seeds: 6 items, or 9 if auto splits further.
    EXPECT_THAT(log, HasSubstr(group == 1 ? "to run in 9 items (3 cells, 3 split)" : "(3 cells, 3 split)"));
    expect_same_file(ResultsFile::open_read_only(out), reference);
  }
}

// A split sweep missing runs of two cells (rows reset to pending, journals
// gone): the rerun trains only those, split, and completes the file.
TEST(SweepCommandTest, ResumeOfAPartiallyFinishedSplitSweepCompletesIt) {
  const std::string dir = temp_dir("split_resume");
  const std::string sweep = write_sweep(dir, kSweep);
  const std::string whole = dir + "/whole.h5", out = dir + "/split.h5";
  run_sweep(sweep, whole, 1, "--split off");
  run_sweep(sweep, out, 2, "--max-group-size 2");
  const Grid grid = expand_grid(parse_sweep_file(sweep));
  std::vector<int> reset = {grid.cells[0].runs[1], grid.cells[0].runs[2], grid.cells[1].runs[0]};
  {
    ResultsFile file = ResultsFile::open(out, MPI_COMM_NULL, parse_sweep_file(sweep).text_hash);
    for (int row : reset) file.write_run(row, RunResult{});  // status pending
    file.close();
  }
  ASSERT_EQ(shell("rm -rf " + journal_directory(out)), 0);
  const std::string log = run_sweep(sweep, out, 2, "--max-group-size 1");
  EXPECT_THAT(log, HasSubstr("6 finished before, 3 to run in 3 items (2 cells, 1 split)"));
  const ResultsFile resumed = ResultsFile::open_read_only(out);
  for (RunStatus s : resumed.read_statuses()) EXPECT_EQ(s, RunStatus::kDone);
  expect_same_file(resumed, ResultsFile::open_read_only(whole));
}

TEST(SweepCommandTest, BadSweepFilesExitTwoBeforeWritingAnything) {
  const std::string dir = temp_dir("bad");
  const std::pair<const char*, const char*> cases[] = {
      {"name = \"x\"\n[training]\nstpes = 5\n", ":3: unknown key \"stpes\""},
      {"name = \"x\"\n[training]\nsteps = -5\n", ":3:"},
      {"name = \"x\"\n[grid]\nn_train = []\n", ":3:"},
      {"name = \"x\"\n[training]\nsteps = \"many\"\n", ":3:"},
      {"name = \"x\"\n[grid]\nmodels = [\"phnn-s-rk3\"]\n", ":3:"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string sweep = write_sweep(dir, text);
    const std::string out = dir + "/never.h5";
    std::string log;
    EXPECT_EQ(shell(mpiexec(2) + " sweep " + sweep + " --out " + out, &log), 2) << log;
    EXPECT_THAT(log, HasSubstr(sweep + expected));
    struct stat st;
    EXPECT_NE(::stat(out.c_str(), &st), 0) << "a results file was written";
    EXPECT_NE(::stat(journal_directory(out).c_str(), &st), 0) << "a journal was written";
  }
}

// A sweep file that adds seeds (and a comment) resumes into a new version of
// its results file: the finished runs are kept bitwise, only the new ones are
// trained, and the whole equals a fresh run of the grown sweep. A sweep file
// that changes a run's configuration is refused on every rank, file unchanged.
TEST(SweepCommandTest, GrownSweepKeepsFinishedRunsAndChangedSweepIsRefused) {
  const std::string dir = temp_dir("grow");
  std::string text = kSweep;
  text.replace(text.find("seeds = [0, 1, 2]"), 17, "seeds = [0, 1]");
  const std::string out = dir + "/grow.h5", fresh = dir + "/fresh.h5";
  std::string log;
  ASSERT_EQ(shell(mpiexec(2) + " sweep " + write_sweep(dir, text) + " --quiet --out " + out, &log),
            0) << log;
  std::string grown = "# grown by one seed\n" + text;
  grown.replace(grown.find("seeds = [0, 1]"), 14, "seeds = [0, 1, 2]");
  const std::string sweep = write_sweep(dir, grown);
  ASSERT_EQ(shell(mpiexec(2) + " sweep " + sweep + " --quiet --out " + out, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("grew by 3 runs; new version of the file with 6 runs with results "
                             "kept bitwise"));
  EXPECT_THAT(log, HasSubstr("6 finished before, 3 to run"));
  ASSERT_EQ(shell(mpiexec(1) + " sweep " + sweep + " --quiet --out " + fresh, &log), 0) << log;
  {
    const ResultsFile a = ResultsFile::open_read_only(out), b = ResultsFile::open_read_only(fresh);
    ASSERT_EQ(a.read_run_ids(), b.read_run_ids());
    for (int row = 0; row < a.num_runs(); ++row) expect_same_run(a.read_run(row), b.read_run(row), row);
  }
  std::string changed = grown;
  changed.replace(changed.find("steps = 30"), 10, "steps = 40");
  const std::string hash_before = ResultsFile::open_read_only(out).sweep_hash();
  EXPECT_EQ(shell(mpiexec(2) + " sweep " + write_sweep(dir, changed) + " --out " + out, &log), 2)
      << log;
  EXPECT_THAT(log, HasSubstr("steps: 30 -> 40 (9 runs"));
  EXPECT_THAT(log, Not(HasSubstr("MPI_ABORT")));
  EXPECT_EQ(ResultsFile::open_read_only(out).sweep_hash(), hash_before);
}

// Array mode: each shard trains its cells into its own file; `phnn merge`
// gives bitwise the file of an unsharded run.
TEST(SweepCommandTest, ShardsMergedEqualAWholeRun) {
  const std::string dir = temp_dir("shards");
  const std::string sweep = write_sweep(dir, kSweep);
  std::string log;
  ASSERT_EQ(shell(mpiexec(2) + " sweep " + sweep + " --quiet --out " + dir + "/whole.h5", &log), 0)
      << log;
  for (const char* shard : {"0/2", "1/2"}) {
    ASSERT_EQ(shell("cd " + dir + " && " + mpiexec(1) + " sweep " + sweep + " --quiet --shard " +
                        shard + " --out " + dir + "/part" + std::string(1, shard[0]) + ".h5",
                    &log),
              0)
        << log;
    EXPECT_THAT(log, HasSubstr("shard " + std::string(shard) + ": 0 finished before"));
    EXPECT_THAT(log, HasSubstr("phnn merge OUT SHARD..."));
  }
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " merge " + dir + "/merged.h5 " + dir + "/part0.h5 " +
                      dir + "/part1.h5",
                  &log),
            0)
      << log;
  EXPECT_THAT(log, HasSubstr("9 of 9 runs with results"));
  const ResultsFile whole = ResultsFile::open_read_only(dir + "/whole.h5");
  const ResultsFile merged = ResultsFile::open_read_only(dir + "/merged.h5");
  ASSERT_EQ(merged.read_run_ids(), whole.read_run_ids());
  for (int row = 0; row < whole.num_runs(); ++row) {
    expect_same_run(merged.read_run(row), whole.read_run(row), row);
  }
  EXPECT_EQ(shell(std::string(PHNN_BINARY) + " reduce " + dir + "/merged.h5", &log), 0) << log;
}

TEST(SweepCommandTest, DryRunPrintsRunsAndCellsOfThePaper) {
  std::string log;
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + PHNN_SOURCE_DIR + "/sweeps/paper.toml --dry-run", &log), 0);
  EXPECT_EQ(log.substr(0, log.find('\n')), "1200 runs in 120 cells");
}

TEST(SweepCommandTest, DryRunPrintsTheScheduleForSeveralRankCounts) {
  const std::string paper = std::string(PHNN_SOURCE_DIR) + "/sweeps/paper.toml";
  std::string log;
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --dry-run --ranks 2,16,128", &log), 0)
      << log;
  EXPECT_THAT(log, HasSubstr("\n  2 ranks: 120 items (120 whole cells), makespan"));
  EXPECT_THAT(log, HasSubstr("\n  16 ranks: "));
  EXPECT_THAT(log, HasSubstr("\n  128 ranks: "));
  EXPECT_THAT(log, HasSubstr("split auto"));
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --dry-run --ranks 128 --split off", &log), 0)
      << log;
  EXPECT_THAT(log, HasSubstr("\n  128 ranks: 120 items (120 whole cells)"));
  EXPECT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --dry-run --ranks 0", &log), 2);
  EXPECT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --dry-run --split off --max-group-size 2", &log), 2);
  EXPECT_THAT(log, HasSubstr("needs mode auto"));
  // Numbers out of range are refused with the range, never wrapped.
  for (const char* bad : {"--threads 0", "--threads 4294967297", "--max-group-size 4294967297",
                          "--max-group-size -1", "--checkpoint-every -1"}) {
    EXPECT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --dry-run " + bad, &log), 2)
        << bad;
    EXPECT_THAT(log, HasSubstr("is outside [")) << bad;
  }
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --dry-run --cell-costs", &log), 0)
      << log;
  EXPECT_THAT(log, StartsWith("cell,system,model,size,n_train,regularizer,members,"));
  EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 121) << "header + 120 cells";
  EXPECT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --cell-costs", &log), 2);
  EXPECT_THAT(log, HasSubstr("add --dry-run"));
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --dry-run --items --ranks 2", &log), 0)
      << log;
  EXPECT_THAT(log, StartsWith("item,cell,runs,estimated_s,run_ids\n0,0,10,"));
  EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 121) << "header + 120 whole cells on 2 ranks";
  EXPECT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --dry-run --items --ranks 2,128", &log), 2);
  EXPECT_THAT(log, HasSubstr("give one rank count"));
  EXPECT_EQ(shell(std::string(PHNN_BINARY) + " sweep " + paper + " --items", &log), 2);
  EXPECT_THAT(log, HasSubstr("use it with --dry-run"));
}

}  // namespace
}  // namespace phnn
