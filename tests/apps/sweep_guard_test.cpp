// tests/apps/sweep_guard_test.cpp — `phnn sweep` against hostile input under
// mpiexec -n 1/2/3, each launch under `timeout` so a hang fails the test:
// one writer per results file, no rank waiting forever, nothing that is not
// ours destroyed, damaged files rebuilt, provenance stored. Also the guards
// of `phnn data --out` and `phnn train --seeds`.
// Size: one scenario per hostile input, each with its own setup and timeout.
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "apps/provenance.h"
#include "h5/h5file.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/ph_system.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/writer_lock.h"
#include "store/results_file_internal.h"  // group_digest: another build's file
#include "sweep/sample_results.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// Seconds after which a launch counts as hung (a clean failure takes ~1 s).
constexpr int kHangSeconds = 60;
constexpr int kTimedOut = 124;  // timeout(1)'s status

std::string temp_dir(const std::string& name) {
  const std::string dir =
      ::testing::TempDir() + "phnn_guard_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str());
  return dir;
}

int shell(const std::string& command, std::string* output = nullptr) {
  return testing_util::run_shell(command, output);
}

// `phnn ARGS` on `ranks` ranks; each rank appends "[exit S]" to the log so
// the test sees every rank's own status. Returns mpiexec's status.
int run_ranks(int ranks, const std::string& args, std::string* log) {
  const std::string command = "timeout -k 5 " + std::to_string(kHangSeconds) + " " + PHNN_MPIEXEC +
                              " -n " + std::to_string(ranks) + " " + PHNN_MPIEXEC_PREFLAGS +
                              " sh -c '\"$0\" \"$@\"; echo \"[exit $?]\"' " + PHNN_BINARY + " " + args;
  return shell(command, log);
}

// Every one of `ranks` ranks exited with `status`, none hung.
void expect_every_rank_exits(int ranks, const std::string& args, int status,
                             const std::string& message) {
  SCOPED_TRACE(std::to_string(ranks) + " ranks: phnn " + args);
  std::string log;
  const int mpiexec_status = run_ranks(ranks, args, &log);
  ASSERT_NE(mpiexec_status, kTimedOut) << "hung:\n" << log;
  std::size_t count = 0;
  for (std::size_t at = log.find("[exit " + std::to_string(status) + "]"); at != std::string::npos;
       at = log.find("[exit " + std::to_string(status) + "]", at + 1)) {
    ++count;
  }
  EXPECT_EQ(count, static_cast<std::size_t>(ranks)) << log;
  EXPECT_THAT(log, HasSubstr(message));
  EXPECT_THAT(log, Not(HasSubstr("MPI_ABORT")));
}

using testing_util::read_all;

bool exists(const std::string& path) {
  struct stat st;
  return ::lstat(path.c_str(), &st) == 0;
}

std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d)) {
      const std::string name = e->d_name;
      if (name != "." && name != "..") names.push_back(name);
    }
    ::closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

// 2 runs of 30 steps: a sweep that finishes in a few seconds.
const char* kTinySweep = R"(name = "tiny"
[data]
num_validation = 40
num_inference = 3
[training]
steps = 30
eval_every = 10
batch_size = 16
[grid]
systems = ["harmonic"]
models = ["node-rk2"]
n_train = [25]
seeds = [0, 1]
)";

std::string write_file(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// Runs the tiny sweep into `out` on `ranks` ranks; returns the log.
std::string run_tiny(const std::string& sweep, const std::string& out, int ranks) {
  std::string log;
  EXPECT_EQ(run_ranks(ranks, "sweep " + sweep + " --quiet --out " + out, &log), 0) << log;
  return log;
}

// --- item 2: no rank waits forever ------------------------------------------

// Every fixture goes through the same path (parse on every rank, agree,
// exit 2); SweepFileErrorTest.EveryHostileFixtureIsRefusedNamingTheFile
// checks all of them in-process, this launches a sample on 1, 2, 3 ranks.
TEST(SweepGuardTest, HostileSweepFilesFailWithTheirNameOnEveryRank) {
  const std::string fixtures = std::string(PHNN_SOURCE_DIR) + "/tests/fixtures/hostile/";
  const std::string dir = temp_dir("fixtures");
  const char* sample[] = {"deep-nesting.toml", "nul-bytes.toml", "seeds-range-huge.toml"};
  for (int ranks : {1, 2, 3}) {
    for (const char* name : sample) {
      expect_every_rank_exits(ranks, "sweep " + fixtures + name + " --out " + dir + "/never.h5", 2,
                              fixtures + name + ":");
    }
  }
  EXPECT_EQ(list_dir(dir), std::vector<std::string>{}) << "a hostile sweep file wrote something";
}

TEST(SweepGuardTest, FifoDeviceDirectoryAndOversizedSweepFilesFailWithoutWaiting) {
  const std::string dir = temp_dir("special");
  const std::string fifo = dir + "/fifo.toml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const std::string big = write_file(dir + "/big.toml", "name = \"big\"\n" + std::string(61000, '#'));
  const std::pair<std::string, std::string> cases[] = {
      {fifo, "not a regular file"},
      {"/dev/zero", "not a regular file"},
      {dir, "not a regular file"},
      {big, "61013 bytes, more than the 60000 a sweep file may have"}};
  for (const auto& [sweep, message] : cases) {
    for (int ranks : {1, 2, 3}) {
      expect_every_rank_exits(ranks, "sweep " + sweep + " --out " + dir + "/never.h5", 2,
                              sweep + ": " + message);
    }
  }
  EXPECT_FALSE(exists(dir + "/never.h5"));
}

// A file failing its structural checks is never resumed: moved aside (its
// bytes kept) and rebuilt from the journals, every run restored untrained.
TEST(SweepGuardTest, ResultsFileWithAnImpossibleStatusIsMovedAsideAndRebuilt) {
  const std::string dir = temp_dir("status");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  run_tiny(sweep, out, 1);
  {
    h5::File file = h5::File::open(out, h5::Access::kReadWrite);
    const std::int64_t bad = 7;
    file.write_rows("/runs/status", 1, 1, &bad);
  }
  const std::string before = read_all(out);
  for (int ranks : {2, 1}) {
    expect_every_rank_exits(ranks, "sweep " + sweep + " --out " + out, 0,
                            ranks == 2 ? "the file is damaged; moved to " + out + ".damaged-"
                                       : "0 to run");
  }
  std::string aside;
  ASSERT_EQ(shell("ls " + out + ".damaged-*", &aside), 0) << aside;
  EXPECT_EQ(read_all(aside.substr(0, aside.find('\n'))), before);
  for (RunStatus s : ResultsFile::open_read_only(out).read_statuses()) EXPECT_EQ(s, RunStatus::kDone);
}

TEST(SweepGuardTest, JournalPathThatIsARegularFileFailsOnEveryRank) {
  const std::string dir = temp_dir("journal");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  write_file(journal_directory(out), "mine\n");
  for (int ranks : {1, 2, 3}) {
    expect_every_rank_exits(ranks, "sweep " + sweep + " --out " + out, 2,
                            journal_directory(out) + ": not a directory");
  }
  EXPECT_FALSE(exists(out));
  EXPECT_EQ(read_all(journal_directory(out)), "mine\n");
}

TEST(SweepGuardTest, TrainCapsSeedsBeforeExpandingThem) {
  std::string log;
  const int status = shell("timeout 20 " + std::string(PHNN_BINARY) +
                               " train --system harmonic --model node --seeds 0-100000000",
                           &log);
  EXPECT_EQ(status, 2) << log;
  EXPECT_THAT(log, HasSubstr("--seeds = \"0-100000000\": more than 100000 values"));
}

// --- item 1: one writer -----------------------------------------------------

TEST(SweepGuardTest, SecondWriterIsRefusedAtOnceNamingTheHolder) {
  const std::string dir = temp_dir("lock");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  WriterLock holder;  // this test process stands for the first sweep
  ASSERT_TRUE(holder.acquire(out, "0123456789abcdef").acquired);
  for (int ranks : {1, 2, 3}) {
    expect_every_rank_exits(ranks, "sweep " + sweep + " --out " + out, 1,
                            out + " is being written by another phnn sweep: pid " +
                                std::to_string(::getpid()) + " on host " + host_name());
  }
  EXPECT_FALSE(exists(out));
  holder.release();
  run_tiny(sweep, out, 2);
  EXPECT_FALSE(exists(WriterLock::lock_path(out))) << "the lock outlived the sweep";
}

TEST(SweepGuardTest, StaleLockOfADeadSweepIsTakenOverWithANote) {
  const std::string dir = temp_dir("stale");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  std::string pid;
  shell("sh -c 'echo $$'", &pid);  // a process of this host, gone now
  pid.erase(pid.find_last_not_of("\n") + 1);
  write_file(WriterLock::lock_path(out), "host = " + host_name() + "\npid = " + pid +
                                             "\nstarted = 2024-01-01T00:00:00Z\nsweep_hash = x\n");
  EXPECT_THAT(run_tiny(sweep, out, 2), HasSubstr("taking over a stale lock of pid " + pid));
}

TEST(SweepGuardTest, SrunWithoutPmiIsRefusedWithTheFix) {
  const std::string dir = temp_dir("pmi");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  std::string log;
  EXPECT_EQ(shell("SLURM_NTASKS=4 timeout 60 " + std::string(PHNN_BINARY) + " sweep " + sweep +
                      " --out " + dir + "/out.h5",
                  &log),
            2)
      << log;
  EXPECT_THAT(log, HasSubstr("Slurm started 4 tasks but MPI sees 1 rank"));
  EXPECT_THAT(log, HasSubstr("srun --mpi=pmix"));
  EXPECT_FALSE(exists(dir + "/out.h5"));
}

// --- item 3: never destroy what is not ours ---------------------------------

TEST(SweepGuardTest, OutputThatIsNotAResultsFileIsNeverReplaced) {
  const std::string dir = temp_dir("notours");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string text = write_file(dir + "/notes.txt", "my thesis\n");
  ASSERT_EQ(::mkdir((dir + "/adir").c_str(), 0755), 0);
  const std::string data = dir + "/data.h5";
  write_ph_dataset_file(data, make_ph_system_data(*make_system("harmonic"), DatasetOptions{}, 2));
  const std::string data_bytes = read_all(data);
  const std::vector<std::string> before = list_dir(dir);
  const std::pair<std::string, std::string> cases[] = {
      {text, "exists and is not an HDF5 file"},
      {dir + "/adir", "not a regular file (a directory)"},
      {sweep, "is the sweep file itself"},
      {data, "an HDF5 file but not a phnn results file"}};
  for (const auto& [out, message] : cases) {
    expect_every_rank_exits(2, "sweep " + sweep + " --out " + out, 2, out + ": " + message);
  }
  EXPECT_EQ(list_dir(dir), before) << "something was renamed or created";
  EXPECT_EQ(read_all(text), "my thesis\n");
  EXPECT_EQ(read_all(sweep), kTinySweep);
  EXPECT_EQ(read_all(data), data_bytes);
}

TEST(SweepGuardTest, TruncatedResultsFileIsMovedAsideAndRebuiltFromTheJournals) {
  const std::string dir = temp_dir("truncated");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  run_tiny(sweep, out, 2);
  std::vector<RunResult> reference;
  {
    const ResultsFile file = ResultsFile::open_read_only(out);
    for (int row = 0; row < file.num_runs(); ++row) reference.push_back(file.read_run(row));
  }
  struct stat st;
  ASSERT_EQ(::stat(out.c_str(), &st), 0);
  ASSERT_EQ(::truncate(out.c_str(), st.st_size / 2), 0);
  const std::string log = run_tiny(sweep, out, 2);
  EXPECT_THAT(log, HasSubstr(out + ": damaged: "));
  EXPECT_THAT(log, HasSubstr("moved to " + out + ".damaged-"));
  EXPECT_THAT(log, HasSubstr("recovered 2 finished runs from the journals"));
  EXPECT_THAT(log, HasSubstr("2 finished before, 0 to run"));
  const ResultsFile rebuilt = ResultsFile::open_read_only(out);
  ASSERT_EQ(rebuilt.num_runs(), static_cast<int>(reference.size()));
  for (int row = 0; row < rebuilt.num_runs(); ++row) {
    SCOPED_TRACE("row " + std::to_string(row));
    testing_util::expect_bit_equal(reference[static_cast<std::size_t>(row)], rebuilt.read_run(row));
  }
  EXPECT_TRUE(rebuilt.has_system_data("harmonic"));
}

TEST(SweepGuardTest, MissingDataGroupIsWrittenAgainOnResume) {
  const std::string dir = temp_dir("data");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  run_tiny(sweep, out, 1);
  const PhSystemData expected = ResultsFile::open_read_only(out).read_system_data("harmonic");
  {
    h5::File file = h5::File::open(out, h5::Access::kReadWrite);
    file.remove("/data/harmonic");
  }
  ASSERT_FALSE(ResultsFile::open_read_only(out).has_system_data("harmonic"));
  EXPECT_THAT(run_tiny(sweep, out, 2), HasSubstr("wrote the missing data group(s) /data/harmonic"));
  const PhSystemData stored = ResultsFile::open_read_only(out).read_system_data("harmonic");
  EXPECT_EQ(stored.train.u, expected.train.u);
  EXPECT_EQ(stored.validation.u, expected.validation.u);
  EXPECT_EQ(stored.inference.u, expected.inference.u);
  ASSERT_EQ(stored.train.x.size(), expected.train.x.size());
  for (std::size_t i = 0; i < stored.train.x.size(); ++i) EXPECT_EQ(stored.train.x[i], expected.train.x[i]);
}

TEST(SweepGuardTest, DataRefusesToOverwriteAFileItDidNotWrite) {
  const std::string dir = temp_dir("data_out");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string results = dir + "/out.h5";
  run_tiny(sweep, results, 1);
  const std::string text = write_file(dir + "/notes.txt", "keep me\n");
  const std::string results_bytes = read_all(results);
  const std::string data = std::string(PHNN_BINARY) + " data --system harmonic --n-train 2 --out ";
  std::string log;
  for (const std::string& out : {results, text, dir}) {
    EXPECT_EQ(shell("timeout 60 " + data + out, &log), 2) << log;
    EXPECT_THAT(log, HasSubstr("--out " + out + ": " +
                               (out == dir ? "not a regular file"
                                           : "exists; phnn data only replaces data-set files it wrote")));
  }
  EXPECT_EQ(read_all(results), results_bytes);
  EXPECT_EQ(read_all(text), "keep me\n");
  EXPECT_EQ(shell("timeout 60 " + data + dir + "/set.h5", &log), 0) << log;
  EXPECT_EQ(shell("timeout 60 " + data + dir + "/set.h5", &log), 0) << "its own file: " << log;
}

// --- item 6: provenance -----------------------------------------------------

std::map<std::string, std::string> as_map(const Provenance& p) {
  return std::map<std::string, std::string>(p.begin(), p.end());
}

TEST(SweepGuardTest, EverySessionAndRunRecordsItsProvenance) {
  const std::string dir = temp_dir("provenance");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  run_tiny(sweep, out, 2);
  run_tiny(sweep, out, 1);  // a resume is a session too
  const ResultsFile file = ResultsFile::open_read_only(out);
  const std::vector<Provenance> sessions = file.read_sessions();
  ASSERT_EQ(sessions.size(), 2u);
  const auto first = as_map(sessions[0]);
  for (const char* key : {"program_version", "git_commit", "compiler", "libtorch", "blas", "hdf5",
                          "mpi", "hosts", "ranks", "command_line", "started", "finished"}) {
    ASSERT_TRUE(first.count(key)) << key;
    EXPECT_NE(first.at(key), "") << key;
  }
  EXPECT_EQ(first.at("ranks"), "2");
  EXPECT_EQ(as_map(sessions[1]).at("ranks"), "1");
  EXPECT_EQ(first.at("hosts"), host_name());
  EXPECT_THAT(first.at("command_line"), HasSubstr(" sweep " + sweep + " --quiet --out " + out));
  EXPECT_THAT(first.at("hdf5"), HasSubstr("HDF5 1."));
  EXPECT_THAT(first.at("libtorch"), HasSubstr("LibTorch "));
  EXPECT_EQ(first.at("started").size(), 20u);
  EXPECT_GE(first.at("finished"), first.at("started"));
  for (int row = 0; row < file.num_runs(); ++row) {
    const RunResult r = file.read_run(row);
    EXPECT_EQ(r.started_utc.size(), 20u);
    EXPECT_GE(r.finished_utc, r.started_utc);
    EXPECT_GE(r.started_utc, first.at("started"));
  }
}

// A file written before provenance existed (no /provenance, no run times)
// still resumes; it gains a session, its runs no times.
TEST(SweepGuardTest, ResultsFilesWithoutProvenanceStillResume) {
  const std::string dir = temp_dir("old");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  run_tiny(sweep, out, 1);
  {
    h5::File file = h5::File::open(out, h5::Access::kReadWrite);
    for (const char* name : {"/provenance", "/runs/started_utc", "/runs/finished_utc",
                             "/runs/checksum"}) {  // nor checksums, which came later
      file.remove(name);
    }
    for (const char* object : {"/", "/data/harmonic"}) file.remove_attribute(object, "digest");
    file.remove_attribute("/", "checksum_version");
  }
  ASSERT_EQ(shell("rm -rf " + journal_directory(out)), 0);
  const std::string hash = ResultsFile::open_read_only(out).sweep_hash();
  {
    ResultsFile file = ResultsFile::open(out, MPI_COMM_NULL, hash);
    file.write_run(0, RunResult{});  // pending again: the resume trains it
  }
  EXPECT_THAT(run_tiny(sweep, out, 2), HasSubstr("1 finished before, 1 to run"));
  const ResultsFile file = ResultsFile::open_read_only(out);
  for (int row = 0; row < file.num_runs(); ++row) {  // no run times: read as ""
    EXPECT_EQ(file.read_run(row).started_utc, "");
    EXPECT_EQ(file.read_run(row).finished_utc, "");
  }
  EXPECT_EQ(file.read_sessions().size(), 1u);
  for (RunStatus s : file.read_statuses()) EXPECT_EQ(s, RunStatus::kDone);
}

// Runs of another kernel set differ by round-off: resuming into their file
// is refused on every rank, naming the set and the way out, and changes
// nothing; --mix-kernels resumes anyway.
TEST(SweepGuardTest, ResumeRefusesAnotherKernelSetUnlessTold) {
  const std::string dir = temp_dir("kernels");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  run_tiny(sweep, out, 1);
  EXPECT_THAT(as_map(ResultsFile::open_read_only(out).read_sessions()[0]).at("kernels"),
              HasSubstr("phnn kernels "));
  {
    h5::File file = h5::File::open(out, h5::Access::kReadWrite);
    file.set_attribute("/provenance/session_0", "kernels", std::string("phnn kernels 0; avx2"));
  }
  const std::string hash = ResultsFile::open_read_only(out).sweep_hash();
  {
    ResultsFile file = ResultsFile::open(out, MPI_COMM_NULL, hash);
    file.write_run(0, RunResult{});  // pending again: a resume would train it
  }
  expect_every_rank_exits(2, "sweep " + sweep + " --quiet --out " + out, 2, "--mix-kernels");
  EXPECT_EQ(ResultsFile::open_read_only(out).read_sessions().size(), 1u);
  EXPECT_EQ(ResultsFile::open_read_only(out).read_statuses()[0], RunStatus::kPending);
  std::string log;
  EXPECT_EQ(run_ranks(1, "sweep " + sweep + " --quiet --mix-kernels --out " + out, &log), 0) << log;
  EXPECT_EQ(ResultsFile::open_read_only(out).read_statuses()[0], RunStatus::kDone);
}

// Only sessions that finished a run decide a resume's or a merge's kernel
// check: a session of another kernel set that was stopped at once (or was
// refused) mixes nothing into the file.
TEST(SweepGuardTest, SessionsWithRunsAreThoseARunFinishedIn) {
  const std::vector<Provenance> sessions = {
      {{"kernels", "phnn kernels 1; avx512"}, {"started", "2026-11-26T08:00:00Z"},
       {"finished", "2026-11-26T09:00:00Z"}},
      {{"kernels", "phnn kernels 0; avx2"}, {"started", "2026-11-26T09:30:00Z"}},
      {{"kernels", "phnn kernels 1; avx2"}, {"started", "2026-11-26T10:00:00Z"}}};
  // Runs finished in sessions 0 and 2 only (session 1 ends where 2 starts).
  std::vector<std::string> finished = {"2026-11-26T08:10:00Z", "", "2026-11-26T10:05:00Z"};
  EXPECT_EQ(sessions_with_runs(sessions, finished), (std::vector<bool>{true, false, true}));
  finished[1] = "2026-11-26T09:45:00Z";  // now one in session 1's window
  EXPECT_EQ(sessions_with_runs(sessions, finished), (std::vector<bool>{true, true, true}));
  // Boundaries: a run finished at the second session 0 ended is session 0's.
  EXPECT_EQ(sessions_with_runs({sessions[0]}, {"2026-11-26T09:00:00Z"}), (std::vector<bool>{true}));
  EXPECT_EQ(sessions_with_runs({sessions[0]}, {"2026-11-26T09:00:01Z"}), (std::vector<bool>{false}));
  EXPECT_EQ(sessions_with_runs({sessions[0]}, {"2026-11-26T07:59:59Z"}), (std::vector<bool>{false}));
  // Nothing to tell: a session without `started`, a file without run times.
  EXPECT_EQ(sessions_with_runs({{{"kernels", "phnn kernels 0"}}}, {""}), (std::vector<bool>{true}));
  EXPECT_EQ(sessions_with_runs(sessions, {}), (std::vector<bool>{true, true, true}));
}

// A resume regenerates the data sets: if they are not the stored bits
// (another phnn version or C library made them), it is refused on every
// rank, naming the split and the way out, and changes nothing.
TEST(SweepGuardTest, ResumeRefusesDataThatAreNotTheStoredOnes) {
  const std::string dir = temp_dir("stored-data");
  const std::string sweep = write_file(dir + "/tiny.toml", kTinySweep);
  const std::string out = dir + "/out.h5";
  run_tiny(sweep, out, 1);
  const std::string hash = ResultsFile::open_read_only(out).sweep_hash();
  {
    h5::File file = h5::File::open(out, h5::Access::kReadWrite);
    std::vector<double> row = file.read_doubles("/data/harmonic/validation/x_next", 3, 1);
    row[1] = std::nextafter(row[1], 1e300);  // one ulp: what another generator gives
    file.write_rows("/data/harmonic/validation/x_next", 3, 1, row.data());
    const std::string group = "/data/harmonic";  // whose digest that generator recorded
    file.set_attribute(group, "digest", results_io::group_digest(file, group));
  }
  {
    ResultsFile file = ResultsFile::open(out, MPI_COMM_NULL, hash);
    file.write_run(0, RunResult{});  // pending again: a resume would train it
  }
  expect_every_rank_exits(2, "sweep " + sweep + " --quiet --out " + out, 2,
                          "differ from the data set stored in the file (validation pair 3 "
                          "differs)");
  EXPECT_EQ(ResultsFile::open_read_only(out).read_sessions().size(), 1u);
  EXPECT_EQ(ResultsFile::open_read_only(out).read_statuses()[0], RunStatus::kPending);
  std::string log;
  EXPECT_EQ(run_ranks(1, "sweep " + sweep + " --quiet --mix-kernels --out " + out, &log), 0) << log;
  EXPECT_EQ(ResultsFile::open_read_only(out).read_statuses()[0], RunStatus::kDone);
}

TEST(SweepGuardTest, VersionPrintsTheBuildAndItsLibraries) {
  std::string log;
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " --version", &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("program_version: phnn-sweep "));
  EXPECT_THAT(log, HasSubstr("\ngit_commit: "));
  EXPECT_THAT(log, HasSubstr("\nhdf5: HDF5 1."));
  EXPECT_THAT(log, HasSubstr("\nmpi: "));
  EXPECT_THAT(log, HasSubstr("\nlibtorch: LibTorch "));
}

}  // namespace
}  // namespace phnn
