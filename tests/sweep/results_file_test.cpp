// tests/sweep/results_file_test.cpp — the serial path (MPI_COMM_NULL, no
// MPI_Init); tests/mpi/results_file_mpi_test.cpp covers the parallel one.
// Size: one test file per module; each layout feature needs its round trip.
#include "phnn/store/results_file.h"

#include "phnn/config/model_config.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/config/result_columns.h"
#include "phnn/store/journal.h"
#include "sweep/sample_results.h"

namespace phnn {
namespace {

using ::testing::EndsWith;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;
using testing_util::bits;
using testing_util::expect_bit_equal;
using testing_util::sample_layout;
using testing_util::sample_result;
using testing_util::sample_runs;
using testing_util::sample_studies;

constexpr int kNumRuns = 7;
constexpr char kSweepHash[] = "1a2b3c4d5e6f7081";

class ResultsFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = ::testing::TempDir() + "phnn_results_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".h5";
  }
  void TearDown() override {
    std::remove(path_.c_str());
    remove_journals(path_);
  }

  ResultsFile create(int num_runs = kNumRuns) const {
    return ResultsFile::create(path_, MPI_COMM_NULL, sample_runs(num_runs),
                               sample_studies(num_runs), "demo", "name = demo\nseeds = 0..6\n",
                               kSweepHash, "phnn-sweep 0.1.0", sample_layout());
  }

  // A file made without checkpoints has no such columns and reads none.
  void create_plain_and_check_no_checkpoints() const {
    std::remove(path_.c_str());
    remove_journals(path_);
    create().close();
    const ResultsFile file = ResultsFile::open_read_only(path_);
    EXPECT_EQ(file.layout().checkpoints, 0);
    EXPECT_TRUE(file.read_run(0).checkpoint_mse.empty());
  }

  std::string path_;
};

TEST_F(ResultsFileTest, RoundTripsEveryFieldBitExactly) {
  const ResultsLayout layout = sample_layout();
  {
    ResultsFile file = create();
    // Row 6 stays pending.
    for (int row = 0; row < kNumRuns - 1; ++row) file.write_run(row, sample_result(row, layout));
    file.close();
  }
  const ResultsFile file = ResultsFile::open_read_only(path_);
  ASSERT_EQ(file.num_runs(), kNumRuns);
  EXPECT_EQ(file.layout().num_inference, layout.num_inference);
  EXPECT_EQ(file.layout().trace_points, layout.trace_points);
  EXPECT_EQ(file.layout().figure_points, layout.figure_points);
  for (int row = 0; row < kNumRuns - 1; ++row) {
    SCOPED_TRACE("row " + std::to_string(row));
    expect_bit_equal(sample_result(row, layout), file.read_run(row));
  }
  const RunResult pending = file.read_run(kNumRuns - 1);
  EXPECT_EQ(pending.status, RunStatus::kPending);
  EXPECT_TRUE(std::isnan(pending.mse));
  EXPECT_TRUE(pending.trace.empty());
  EXPECT_TRUE(pending.trajectory_errors.empty());
  EXPECT_TRUE(pending.figure_prediction_05.empty());
  // The padding really is NaN in the file.
  const std::vector<double> trace = file.read_double_column("trace");
  EXPECT_TRUE(std::isnan(trace[(1 * layout.trace_points + 2) * 7]));  // row 1 has 2 points
  EXPECT_EQ(bits(file.read_double_column("mse")[1]),
            bits(std::numeric_limits<double>::infinity()));
}

// Checkpoint columns exist only when the layout asks for them; a run's own
// count (<= the layout's) round-trips bit-exactly, +inf included, and a run
// with more checkpoints than the file holds is refused.
TEST_F(ResultsFileTest, RoundTripsCheckpointsWhenTheLayoutHasThem) {
  ResultsLayout layout = sample_layout();
  layout.checkpoints = 3;
  RunResult two = sample_result(0, layout), three = sample_result(3, layout);
  two.checkpoint_steps = {500, 1000};
  two.checkpoint_mse = {0.25, std::numeric_limits<double>::infinity()};
  two.checkpoint_train_seconds = {1.5, 3.25};
  three.checkpoint_steps = {100, 200, 300};
  three.checkpoint_mse = {3e-4, 2e-4, 1e-4};
  three.checkpoint_train_seconds = {0.1, 0.2, 0.3};
  {
    ResultsFile file = ResultsFile::create(path_, MPI_COMM_NULL, sample_runs(kNumRuns),
                                           sample_studies(kNumRuns), "demo", "x", kSweepHash,
                                           "phnn-sweep 0.1.0", layout);
    file.write_run(0, two);
    file.write_run(3, three);
    RunResult four = three;
    four.checkpoint_steps.push_back(400);
    four.checkpoint_mse.push_back(1.0);
    four.checkpoint_train_seconds.push_back(1.0);
    EXPECT_THROW(file.write_run(1, four), std::exception);
    file.close();
  }
  const ResultsFile file = ResultsFile::open_read_only(path_);
  EXPECT_EQ(file.layout().checkpoints, 3);
  expect_bit_equal(two, file.read_run(0));
  expect_bit_equal(three, file.read_run(3));
  EXPECT_TRUE(file.read_run(2).checkpoint_steps.empty());  // pending
  create_plain_and_check_no_checkpoints();
}

// Weights are stored back to back at offsets given by each run's parameter
// count (the last run's room ends with /weights), round-trip bit-exactly,
// and a run with more weights than its model has is refused.
TEST_F(ResultsFileTest, RoundTripsWeightsAtTheirOffsets) {
  ResultsLayout layout = sample_layout();
  layout.weights = true;
  const std::vector<RunConfig> runs = sample_runs(kNumRuns);
  auto weights_of = [&](int row) {
    const RunConfig& run = runs[static_cast<std::size_t>(row)];
    std::vector<double> w(static_cast<std::size_t>(
        parameter_count(run.model, run.size, run.n_x, run.n_w, run.n_u)));
    for (std::size_t i = 0; i < w.size(); ++i) w[i] = row + 1.0 / (3.0 + static_cast<double>(i));
    return w;
  };
  RunResult first = sample_result(0, layout), last = sample_result(kNumRuns - 1, layout);
  first.weights = weights_of(0);
  last.weights = weights_of(kNumRuns - 1);
  last.weights.back() = -std::numeric_limits<double>::infinity();
  {
    ResultsFile file = ResultsFile::create(path_, MPI_COMM_NULL, runs, sample_studies(kNumRuns),
                                           "demo", "x", kSweepHash, "phnn-sweep 0.1.0", layout);
    file.write_run(0, first);
    file.write_run(kNumRuns - 1, last);
    RunResult too_many = sample_result(1, layout);
    too_many.weights = weights_of(1);
    too_many.weights.push_back(1.0);
    EXPECT_THROW(file.write_run(1, too_many), std::invalid_argument);
    file.close();
  }
  const ResultsFile file = ResultsFile::open_read_only(path_);
  EXPECT_TRUE(file.layout().weights);
  expect_bit_equal(first, file.read_run(0));
  expect_bit_equal(last, file.read_run(kNumRuns - 1));
  EXPECT_TRUE(file.read_run(1).weights.empty());  // refused: still pending
  const std::vector<std::int64_t> offsets = file.read_int_column("weights_offset");
  std::int64_t expected = 0;
  for (int row = 0; row < kNumRuns; ++row) {
    EXPECT_EQ(offsets[static_cast<std::size_t>(row)], expected);
    expected += static_cast<std::int64_t>(weights_of(row).size());
  }
}

TEST_F(ResultsFileTest, StoresConfigColumnsAndFileAttributes) {
  create().close();
  const ResultsFile file = ResultsFile::open_read_only(path_);
  const std::vector<RunConfig> runs = sample_runs(kNumRuns);
  const std::vector<std::string> ids = file.read_run_ids();
  const std::vector<std::string> canonical = file.read_canonical();
  ASSERT_EQ(ids.size(), runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    EXPECT_EQ(ids[i], runs[i].id());
    EXPECT_EQ(canonical[i], runs[i].canonical());
    EXPECT_EQ(file.read_string_column("system")[i], to_string(runs[i].system));
    EXPECT_EQ(file.read_string_column("model")[i], to_string(runs[i].model));
    EXPECT_EQ(file.read_string_column("integrator")[i], to_string(runs[i].integrator));
    EXPECT_EQ(file.read_string_column("size")[i], to_string(runs[i].size));
    EXPECT_EQ(file.read_string_column("regularizer")[i], to_string(runs[i].regularizer));
    EXPECT_EQ(file.read_int_column("n_train")[i], runs[i].n_train);
    EXPECT_EQ(file.read_seeds()[i], runs[i].seed);
    EXPECT_EQ(file.read_studies()[i], sample_studies(kNumRuns)[i]);
  }
  EXPECT_EQ(file.sweep_name(), "demo");
  EXPECT_EQ(file.sweep_text(), "name = demo\nseeds = 0..6\n");
  EXPECT_EQ(file.sweep_hash(), kSweepHash);
  EXPECT_EQ(file.program_version(), "phnn-sweep 0.1.0");
  EXPECT_THAT(file.created(), ::testing::MatchesRegex("[0-9]{4}-[0-9]{2}-[0-9]{2}T.*Z"));
  const h5::File raw = h5::File::open(path_, h5::Access::kReadOnly);
  EXPECT_EQ(raw.string_attribute("/", "format"), "phnn-results");
  EXPECT_EQ(raw.int_attribute("/", "format_version"), 1);
  EXPECT_THAT(raw.string_attribute("/", "units"), HasSubstr("q [m], p [kg m/s]"));
  EXPECT_THAT(raw.string_attribute("/runs/mse", "units"), HasSubstr("m^2 and (kg m/s)^2"));
  EXPECT_EQ(raw.string_attribute("/runs/wall_time_s", "units"), "s");
  // Units are units; the prose is the description.
  EXPECT_EQ(raw.string_attribute("/runs/mse", "units"), "m^2 and (kg m/s)^2");
  EXPECT_THAT(raw.string_attribute("/runs/mse", "description"), HasSubstr("+inf if a rollout"));
  EXPECT_EQ(raw.string_attribute("/runs/n_train", "units"), "1");
  EXPECT_EQ(raw.string_attribute("/runs/status", "units"), "");
  EXPECT_THAT(raw.string_attribute("/runs/status", "description"), HasSubstr("2 diverged"));
}

// Every run setting is its own column under /runs/config (the per-run CSV's
// names): numbers as float64, names as strings, NaN where a run lacks one.
TEST_F(ResultsFileTest, EverySettingIsItsOwnColumn) {
  create().close();
  const std::vector<RunConfig> runs = sample_runs(kNumRuns);
  const h5::File raw = h5::File::open(path_, h5::Access::kReadOnly);
  const std::vector<double> n_train = raw.read_doubles("/runs/config/n_train");
  const std::vector<double> seed = raw.read_doubles("/runs/config/seed");
  const std::vector<double> lr = raw.read_doubles("/runs/config/learning_rate");
  const std::vector<double> e_max = raw.read_doubles("/runs/config/energy_max");
  const std::vector<std::string> system = raw.read_strings("/runs/config/system");
  ASSERT_EQ(n_train.size(), static_cast<std::size_t>(kNumRuns));
  for (int r = 0; r < kNumRuns; ++r) {
    const RunConfig& run = runs[static_cast<std::size_t>(r)];
    EXPECT_EQ(n_train[r], run.n_train) << r;
    EXPECT_EQ(seed[r], run.seed) << r;
    EXPECT_EQ(lr[r], run.training.learning_rate) << r;  // bitwise: %.17g read back
    EXPECT_EQ(e_max[r], run.data.energy_max) << r;
    EXPECT_EQ(system[r], run.system_name()) << r;
  }
  EXPECT_THAT(raw.string_attribute("/runs/config/learning_rate", "description"),
              HasSubstr("run setting `learning_rate`"));
  // Damping exists for every built-in system; the Duffing-only cubic
  // stiffness is NaN in the other rows (or absent when no run has it).
  if (raw.exists("/runs/config/cubic_stiffness")) {
    const std::vector<double> k3 = raw.read_doubles("/runs/config/cubic_stiffness");
    for (int r = 0; r < kNumRuns; ++r) {
      EXPECT_EQ(std::isnan(k3[r]), runs[static_cast<std::size_t>(r)].system != SystemKind::kDuffing)
          << r;
    }
  }
}

// Strings are UTF-8 (a sweep file's comments, a system file's state names):
// any text round-trips, and the session attribute still changes in place.
TEST_F(ResultsFileTest, Utf8TextRoundTrips) {
  const std::string text = "name = \"θ-sweep\"  # Größe, 質量\n";
  ResultsFile::create(path_, MPI_COMM_NULL, sample_runs(3), sample_studies(3), "θ-sweep", text,
                      kSweepHash, "v", sample_layout())
      .close();
  const ResultsFile file = ResultsFile::open_read_only(path_);
  EXPECT_EQ(file.sweep_text(), text);
  EXPECT_EQ(file.sweep_name(), "θ-sweep");
}

// A results file written by the build before /runs/config, the weights
// layout, UTF-8 strings and the status enum (tests/fixtures): still read,
// row for row, and its session can still be ended in place.
TEST(ResultsFileFixtureTest, AFileOfTheEarlierFormatIsRead) {
  const std::string fixture = std::string(PHNN_SOURCE_DIR) + "/tests/fixtures/results-2026-11-25.h5";
  const ResultsFile file = ResultsFile::open_read_only(fixture);
  EXPECT_EQ(file.num_runs(), 4);
  EXPECT_EQ(file.read_statuses(), std::vector<RunStatus>(4, RunStatus::kDone));
  EXPECT_TRUE(file.damaged_rows().empty());
  for (int row = 0; row < 4; ++row) {
    const RunResult r = file.read_run(row);
    EXPECT_TRUE(std::isfinite(r.mse)) << row;
    EXPECT_EQ(static_cast<long>(r.weights.size()), r.parameter_count) << row;
    EXPECT_TRUE(std::isnan(r.train_seconds)) << row;  // a column added after the file
  }
  for (const RunResult& r : file.read_result_columns()) EXPECT_TRUE(std::isnan(r.train_seconds));
  const h5::File raw = h5::File::open(fixture, h5::Access::kReadOnly);
  EXPECT_FALSE(raw.exists("/runs/train_seconds"));
  EXPECT_FALSE(raw.exists("/runs/config"));
  EXPECT_FALSE(raw.exists("/runs/weights_layout"));
}

// A row written into a file of before train_seconds (checksum rule 1, no
// /runs/train_seconds): the column is skipped, the rest stored, and the row
// verifies (rule 1 hashes the journal encoding, which leaves NaN out).
TEST(ResultsFileFixtureTest, ARowWrittenIntoAFileOfBeforeAColumnVerifies) {
  const std::string fixture =
      std::string(PHNN_SOURCE_DIR) + "/tests/fixtures/results-2026-11-25.h5";
  const std::string path =
      ::testing::TempDir() + "phnn_fixture_copy_" + std::to_string(::getpid()) + ".h5";
  {
    std::ifstream in(fixture, std::ios::binary);
    std::ofstream(path, std::ios::binary) << in.rdbuf();
  }
  RunResult r;
  std::string hash;
  {
    const ResultsFile old = ResultsFile::open_read_only(path);
    r = old.read_run(1);
    hash = old.sweep_hash();
  }
  r.train_seconds = 3.0;
  r.mse = 0.25;
  {
    ResultsFile file = ResultsFile::open(path, MPI_COMM_NULL, hash);
    file.write_run(1, r);
    file.close();
  }
  const ResultsFile file = ResultsFile::open_read_only(path);
  const RunResult back = file.read_run(1);
  EXPECT_EQ(back.mse, 0.25);
  EXPECT_TRUE(std::isnan(back.train_seconds));
  EXPECT_TRUE(file.damaged_rows().empty());
  std::remove(path.c_str());
  remove_journals(path);
}

// Each column of config/result_columns.h, declared once, reaches every
// place a result goes: its /runs dataset with the declared units and
// description, the row written and read, the whole-column reader, the
// row checksum (rule 2 covers the dataset), the journal record and the
// per-run CSV header (tests/report/per_run_test.cpp, reduce_command_test).
TEST_F(ResultsFileTest, EveryResultColumnReachesItsDatasetRowChecksumAndJournal) {
  const ResultsLayout layout = sample_layout();
  std::set<std::string> names, csv_names;
  {
    ResultsFile file = create();
    for (int row = 0; row < kNumRuns; ++row) file.write_run(row, sample_result(row, layout));
    file.close();
  }
  std::vector<RunResult> columns, rows;
  {
    const ResultsFile file = ResultsFile::open_read_only(path_);
    columns = file.read_result_columns();
    for (int row = 0; row < kNumRuns; ++row) rows.push_back(file.read_run(row));
  }
  ASSERT_EQ(columns.size(), static_cast<std::size_t>(kNumRuns));
  const std::string record = internal::encode_journal_record("0a", sample_result(0, layout), 1);
  for (const ResultColumn& c : result_columns()) {
    SCOPED_TRACE(c.name);
    EXPECT_TRUE(names.insert(c.name).second);
    EXPECT_TRUE(csv_names.insert(c.csv_name).second);
    const std::string dataset = std::string("/runs/") + c.name;
    {
      const h5::File raw = h5::File::open(path_, h5::Access::kReadOnly);
      ASSERT_TRUE(raw.exists(dataset));
      EXPECT_EQ(raw.string_attribute(dataset, "units"), c.units);
      EXPECT_EQ(raw.string_attribute(dataset, "description"), c.description);
    }
    EXPECT_THAT(record, HasSubstr(std::string(" ") + c.name + "="));
    for (int row = 0; row < kNumRuns; ++row) {
      const RunResult expected = sample_result(row, layout);
      if (c.type == ResultColumn::Type::kInt) {
        EXPECT_EQ(c.get_int(rows[row]), c.get_int(expected));
        EXPECT_EQ(c.get_int(columns[row]), c.get_int(expected));
      } else {
        EXPECT_EQ(bits(c.get_double(rows[row])), bits(c.get_double(expected)));
        EXPECT_EQ(bits(c.get_double(columns[row])), bits(c.get_double(expected)));
      }
    }
    // Rule 2: one changed bit of the column damages the row.
    h5::File damaged = h5::File::open(path_, h5::Access::kReadWrite);
    if (c.type == ResultColumn::Type::kInt) {
      std::int64_t v = damaged.read_ints(dataset, 3, 1).at(0) ^ 1;
      damaged.write_rows(dataset, 3, 1, &v);
      damaged.close();
      EXPECT_EQ(ResultsFile::open_read_only(path_).damaged_rows(), std::vector<int>{3});
      damaged = h5::File::open(path_, h5::Access::kReadWrite);
      v ^= 1;
      damaged.write_rows(dataset, 3, 1, &v);
    } else {
      double v = damaged.read_doubles(dataset, 3, 1).at(0);
      const double before = v;
      v = std::nextafter(v, 1e300);
      damaged.write_rows(dataset, 3, 1, &v);
      damaged.close();
      EXPECT_EQ(ResultsFile::open_read_only(path_).damaged_rows(), std::vector<int>{3});
      damaged = h5::File::open(path_, h5::Access::kReadWrite);
      damaged.write_rows(dataset, 3, 1, &before);
    }
    damaged.close();
  }
  EXPECT_TRUE(ResultsFile::open_read_only(path_).damaged_rows().empty());
}

TEST_F(ResultsFileTest, StatusesDefaultToPendingUntilWritten) {
  ResultsFile file = create();
  EXPECT_EQ(file.read_statuses(), std::vector<RunStatus>(kNumRuns, RunStatus::kPending));
  file.write_run(2, sample_result(/*row=*/1, sample_layout()));
  std::vector<RunStatus> expected(kNumRuns, RunStatus::kPending);
  expected[2] = RunStatus::kDiverged;
  EXPECT_EQ(file.read_statuses(), expected);
}

TEST_F(ResultsFileTest, TruncatesLongMessagesWithoutSplittingACharacter) {
  ResultsFile file = create();
  RunResult r = sample_result(0, sample_layout());
  r.message = std::string(252, 'a') + "\xc3\xbc" + std::string(100, 'b');  // u-umlaut at 252
  file.write_run(0, r);
  const std::string back = file.read_run(0).message;
  EXPECT_EQ(back, std::string(252, 'a') + "...");
  EXPECT_LE(back.size(), kMessageLength);
}

TEST_F(ResultsFileTest, RejectsArraysLongerThanTheLayout) {
  ResultsFile file = create();
  RunResult r = sample_result(0, sample_layout());
  r.trace.resize(sample_layout().trace_points + 1);
  EXPECT_THAT([&] { file.write_run(0, r); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("trace has 7 points, the file holds 6")));
  r = sample_result(0, sample_layout());
  r.figure_reference_05.push_back(1.0);
  EXPECT_THAT([&] { file.write_run(0, r); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("figure_reference_05 has 19 values")));
  EXPECT_THAT([&] { file.write_run(kNumRuns, sample_result(0, sample_layout())); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("row outside [0, 7)")));
}

TEST_F(ResultsFileTest, ReopensForResumeKeepingEveryRow) {
  const ResultsLayout layout = sample_layout();
  {
    ResultsFile file = create();
    file.write_run(0, sample_result(0, layout));
  }  // the destructor closes
  {
    ResultsFile file = ResultsFile::open(path_, MPI_COMM_NULL, kSweepHash);
    EXPECT_EQ(file.num_runs(), kNumRuns);
    file.write_run(3, sample_result(3, layout));
  }
  const ResultsFile file = ResultsFile::open_read_only(path_);
  expect_bit_equal(sample_result(0, layout), file.read_run(0));
  expect_bit_equal(sample_result(3, layout), file.read_run(3));
  EXPECT_EQ(file.read_statuses()[1], RunStatus::kPending);
}

TEST_F(ResultsFileTest, RefusesAFileWrittenByAnotherSweep) {
  create().close();
  EXPECT_THAT([&] { ResultsFile::open(path_, MPI_COMM_NULL, "3c4d000000000000"); },
              ThrowsMessage<std::runtime_error>(::testing::AllOf(
                  HasSubstr(path_ + " was written by sweep 'demo' (hash 1a2b3c4d5e6f7081)"),
                  HasSubstr("not by this sweep file (hash 3c4d000000000000)"),
                  HasSubstr("pass a new --out path or delete the file"))));
}

TEST_F(ResultsFileTest, RefusesMissingNonHdf5AndForeignFiles) {
  EXPECT_THAT([] { ResultsFile::open("/nonexistent/dir/r.h5", MPI_COMM_NULL, kSweepHash); },
              ThrowsMessage<std::runtime_error>(
                  HasSubstr("/nonexistent/dir/r.h5: no such results file")));
  std::ofstream(path_) << "not hdf5 at all";
  EXPECT_THAT([&] { ResultsFile::open(path_, MPI_COMM_NULL, kSweepHash); },
              ThrowsMessage<std::runtime_error>(HasSubstr(path_ + ": not an HDF5 file")));
  {
    h5::File foreign = h5::File::create(path_);
    foreign.write("/something", {2}, std::vector<double>{1, 2});
  }
  EXPECT_THAT([&] { ResultsFile::open_read_only(path_); },
              ThrowsMessage<std::runtime_error>(HasSubstr("not a phnn results file")));
}

TEST_F(ResultsFileTest, RefusesBadRunListsBeforeTouchingTheFile) {
  std::vector<RunConfig> runs = sample_runs(3);
  runs[2] = runs[0];
  EXPECT_THAT(
      [&] {
        ResultsFile::create(path_, MPI_COMM_NULL, runs, sample_studies(3), "demo", "", kSweepHash,
                            "v", sample_layout());
      },
      ThrowsMessage<std::invalid_argument>(HasSubstr("runs 0 and 2 are the same run")));
  EXPECT_THAT(
      [&] {
        ResultsFile::create(path_, MPI_COMM_NULL, sample_runs(3), sample_studies(2), "demo", "",
                            kSweepHash, "v", sample_layout());
      },
      ThrowsMessage<std::invalid_argument>(HasSubstr("got 2 study lists for 3 runs")));
  EXPECT_THAT(
      [&] {
        ResultsFile::create("/nonexistent/dir/r.h5", MPI_COMM_NULL, sample_runs(3),
                            sample_studies(3), "demo", "", kSweepHash, "v", sample_layout());
      },
      ThrowsMessage<std::runtime_error>(HasSubstr("directory /nonexistent/dir does not exist")));
  EXPECT_FALSE(h5::File::is_hdf5(path_));
}

// A file lost mid-creation is rebuilt from the journal, so create() keeps it.
TEST_F(ResultsFileTest, CreateKeepsTheJournal) {
  Journal(path_, 0).append("0123456789abcdef", sample_result(0, sample_layout()));
  create().close();
  EXPECT_EQ(replay_journals(path_).size(), 1u);
  remove_journals(path_);
  EXPECT_TRUE(replay_journals(path_).empty());
}

TEST_F(ResultsFileTest, StoresEachSystemsDataOnce) {
  DatasetOptions options;
  options.num_validation = 20;
  options.num_inference = 2;
  const PhSystemData data =
      make_ph_system_data(*builtin_system(OscillatorOptions::defaults(SystemKind::kDuffing), options),
                          options, 25);
  ResultsFile file = create();
  EXPECT_FALSE(file.has_system_data("duffing"));
  file.store_system_data("duffing", data);
  EXPECT_TRUE(file.has_system_data("duffing"));
  EXPECT_THAT([&] { file.store_system_data("duffing", data); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("/data/duffing is already stored")));
  file.close();
  const PhSystemData back = ResultsFile::open_read_only(path_).read_system_data("duffing");
  EXPECT_EQ(back.system_name, "duffing");
  EXPECT_EQ(back.system_text, data.system_text);
  ASSERT_EQ(back.train.size(), 25u);
  EXPECT_EQ(back.train.x[24], data.train.x[24]);
  EXPECT_EQ(back.inference.states[1][500], data.inference.states[1][500]);
}

// Runs of systems with 2 and 4 states in one file: the figure datasets are
// [points][4], each run's figures round-trip with its own state count
// (/runs/n_x), the padding is NaN; a system file's data set and the text it
// was made from come back through stored_system_files().
TEST_F(ResultsFileTest, StoresFiguresOfAnyStateCountAndSystemFileData) {
  std::vector<RunConfig> runs = sample_runs(2);
  runs[1].system_file = "quad";
  runs[1].system_file_hash = "00000000000000aa";
  runs[1].n_x = 4;
  runs[1].n_w = 2;
  ResultsLayout layout = sample_layout();
  layout.figure_states = 2;
  EXPECT_EQ(ResultsLayout::for_runs(runs).figure_states, 4);
  layout.figure_states = 4;
  RunResult two = sample_result(0, layout), four = sample_result(1, layout);
  for (auto* f : {&four.figure_prediction_05, &four.figure_prediction_075,
                  &four.figure_reference_05, &four.figure_reference_075}) {
    f->resize(f->size() / 2 * 2);  // an even count: [n][2] -> [n/2][4]
    while (f->size() % 4 != 0) f->pop_back();
  }
  PhSystemData data;
  data.system_name = "quad";
  data.system_text = "name = \"quad\"\n# the file's text\n";
  data.state_names = {"a", "b", "c", "d"};
  data.state_units = {"m", "m", "m", "m"};
  data.input_names = {"u"};
  data.n_w = 2;
  data.train.x = {VecX::Constant(4, 0.5)};
  data.train.x_next = {VecX::Constant(4, 0.25)};
  data.train.u = {VecX::Constant(1, 1.0)};
  data.train.trajectory = {3};
  data.train.position = {7};
  {
    ResultsFile file = ResultsFile::create(path_, MPI_COMM_NULL, runs, sample_studies(2), "demo",
                                           "name = demo\n", kSweepHash, "phnn-sweep 0.1.0", layout);
    file.write_run(0, two);
    file.write_run(1, four);
    file.store_system_data("quad", data, "systems/quad.toml");
    file.close();
  }
  const ResultsFile file = ResultsFile::open_read_only(path_);
  EXPECT_EQ(file.layout().figure_states, 4);
  EXPECT_EQ(file.read_int_column("n_x"), (std::vector<std::int64_t>{2, 4}));
  expect_bit_equal(two, file.read_run(0));
  expect_bit_equal(four, file.read_run(1));
  const std::vector<double> column = file.read_double_column("figure/prediction_05");
  EXPECT_TRUE(std::isnan(column[2]) && std::isnan(column[3]));  // run 0, point 0, states 3-4
  EXPECT_EQ(bits(column[0]), bits(two.figure_prediction_05[0]));
  const PhSystemData back = file.read_system_data("quad");
  EXPECT_EQ(back.state_names, data.state_names);
  EXPECT_EQ(back.train.x_next[0], data.train.x_next[0]);
  const SystemFileText stored = file.stored_system_files()("systems/quad.toml");
  EXPECT_EQ(stored.text, data.system_text);
  EXPECT_THAT(stored.shown_as, EndsWith("@/data/quad"));
  EXPECT_THAT([&] { file.stored_system_files()("systems/other.toml"); },
              ThrowsMessage<std::runtime_error>(HasSubstr("stores no system file systems/other.toml")));
}

// All metadata is written by create(), so a writer killed without closing
// (kill -9 mid-sweep) leaves a readable file with its finished rows.
TEST_F(ResultsFileTest, SurvivesAWriterKilledWithoutClosing) {
  const ResultsLayout layout = sample_layout();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ResultsFile file = create();
    file.write_run(0, sample_result(0, layout));
    file.write_run(1, sample_result(1, layout));
    std::raise(SIGKILL);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  const ResultsFile file = ResultsFile::open_read_only(path_);
  expect_bit_equal(sample_result(0, layout), file.read_run(0));
  expect_bit_equal(sample_result(1, layout), file.read_run(1));
  EXPECT_EQ(file.read_statuses()[2], RunStatus::kPending);
}

TEST_F(ResultsFileTest, IsReadableByH5dump) {
  {
    ResultsFile file = create();
    file.write_run(0, sample_result(0, sample_layout()));
  }
  const std::string command = "h5dump -H " + path_ + " > /dev/null 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
}

TEST(ResultsLayoutTest, ForRunsIsTheSmallestLayoutThatHoldsEveryRun) {
  std::vector<RunConfig> runs = sample_runs(2);
  runs[0].training.steps = 50000;
  runs[0].training.eval_every = 500;
  runs[1].training.steps = 1000;
  runs[1].training.eval_every = 3;
  const ResultsLayout layout = ResultsLayout::for_runs(runs);
  EXPECT_EQ(layout.trace_points, 1000 / 3 + 2);
  EXPECT_EQ(layout.num_inference, 100);
  EXPECT_EQ(layout.figure_points, 501);
}

TEST(ResultsLayoutTest, RejectsNonPositiveSizes) {
  ResultsLayout layout;
  layout.trace_points = 0;
  EXPECT_THAT([&] { layout.validate(); },
              ThrowsMessage<std::invalid_argument>(HasSubstr("trace_points = 0")));
}

}  // namespace
}  // namespace phnn
