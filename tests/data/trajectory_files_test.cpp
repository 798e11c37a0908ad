// tests/data/trajectory_files_test.cpp — every malformed CSV or HDF5
// trajectory file, and every recording the split refuses, fails with its
// place (FILE:LINE, or FILE:/trajectories/ID) and the fix; the files read
// twice, one trajectory at a time, give the data set of reading them all.
#include "phnn/store/trajectory_files.h"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <utility>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/data/measured.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/measurement_map.h"
#include "phnn/systems/system_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::unique_ptr<PhSystem> pendulum() { return testing_util::shipped_system("pendulum"); }

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const MeasuredDataError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a MeasuredDataError";
  return "";
}

const TrajectoryColumns kPendulum{{"q", "p"}, {"u"}};

std::string csv_file(const std::string& text) {
  static int counter = 0;
  // The process id too: ctest runs each test in a process of its own, in parallel.
  const std::string path = ::testing::TempDir() + "phnn_bad_" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter++) + ".csv";
  std::ofstream(path) << text;
  return path;
}

std::string read_error(const std::string& text) {
  const std::string path = csv_file(text);
  const std::string e = error_of([&] { read_trajectory_csv(path, kPendulum); });
  std::remove(path.c_str());
  return e;
}

// Reads and splits (1 validation, 1 inference trajectory).
std::string split_error(const std::string& text, ImportOptions o = {}) {
  if (o.num_validation == 2500) o.num_validation = o.num_inference = 1;
  const auto system = pendulum();
  const std::string path = csv_file(text);
  const std::string e = error_of([&] { split_measured_data(*system, read_trajectory_csv(path, kPendulum), o); });
  std::remove(path.c_str());
  return e;
}

const std::string kHeader = "trajectory,t,q,p,u\n";
// Three good trajectories of 3 samples at 10 Hz.
const std::string kGood = "0,0,1,0,0\n0,0.1,1,0,0\n0,0.2,1,0,0\n"
                          "1,0,2,0,0\n1,0.1,2,0,0\n1,0.2,2,0,0\n"
                          "2,0,3,0,0\n2,0.1,3,0,0\n2,0.2,3,0,0\n";

TEST(MeasuredDataTest, TheGoodFixtureIsAccepted) {
  const auto system = pendulum();
  const std::string path = csv_file("# a comment\n\n" + kHeader + kGood);
  ImportOptions o;
  o.num_validation = o.num_inference = 1;
  const PhSystemData d = split_measured_data(*system, read_trajectory_csv(path, kPendulum), o);
  EXPECT_EQ(d.train.size(), 1u);
  EXPECT_EQ(d.inference.states[0].size(), 3u);
  std::remove(path.c_str());
}

// Spreadsheets often save CSV with a UTF-8 byte order mark (as sweep files
// may have one): it is not part of the first column's name.
TEST(MeasuredDataTest, AByteOrderMarkBeforeTheHeaderIsSkipped) {
  const auto system = pendulum();
  const std::string path = csv_file("\xEF\xBB\xBF" + kHeader + kGood);
  ImportOptions o;
  o.num_validation = o.num_inference = 1;
  EXPECT_EQ(split_measured_data(*system, read_trajectory_csv(path, kPendulum), o).train.size(), 1u);
  std::remove(path.c_str());
}

TEST(MeasuredDataTest, MalformedCsvFailsAtItsLineWithTheFix) {
  // 1. missing state column
  EXPECT_THAT(read_error("trajectory,t,q,u\n0,0,1,0\n"),
              AllOf(HasSubstr(".csv:1: missing column \"p\""), HasSubstr("trajectory,t,q,p,u")));
  // 2. missing input column for a system with inputs
  EXPECT_THAT(read_error("trajectory,t,q,p\n0,0,1,0\n"),
              AllOf(HasSubstr("missing column \"u\""), HasSubstr("record it for every sample")));
  // 3. extra column
  EXPECT_THAT(read_error("trajectory,t,q,p,u,v\n"), HasSubstr(".csv:1: unknown column \"v\""));
  // 4. repeated column
  EXPECT_THAT(read_error("trajectory,t,q,q,p,u\n"), HasSubstr("column \"q\" appears twice"));
  // 5. ragged row
  EXPECT_THAT(read_error(kHeader + "0,0,1,0,0\n0,0.1,1,0\n"),
              AllOf(HasSubstr(".csv:3: 4 fields where the header has 5"), HasSubstr("one value per column")));
  // 6. not a number
  EXPECT_THAT(read_error(kHeader + "0,0,1,abc,0\n"),
              AllOf(HasSubstr(".csv:2: column p: \"abc\" is not a number")));
  // 7. NaN
  EXPECT_THAT(read_error(kHeader + "0,0,nan,0,0\n"), AllOf(HasSubstr(".csv:2: column q is nan"),
                                                             HasSubstr("finite")));
  // 8. infinity in an input
  EXPECT_THAT(read_error(kHeader + "0,0,1,0,inf\n"), HasSubstr(".csv:2: column u is inf"));
  // 9. a trajectory id that is not a non-negative integer
  EXPECT_THAT(read_error(kHeader + "-1,0,1,0,0\n"), HasSubstr(".csv:2: trajectory \"-1\" is not a non-negative integer"));
  EXPECT_THAT(read_error(kHeader + "1.5,0,1,0,0\n"), HasSubstr("trajectory \"1.5\""));
  // 10. a trajectory's rows split by another trajectory
  EXPECT_THAT(read_error(kHeader + "0,0,1,0,0\n1,0,1,0,0\n0,0.1,1,0,0\n"),
              AllOf(HasSubstr(".csv:4: trajectory 0 continues here"), HasSubstr("started at line 2")));
  // 11. time that does not increase
  EXPECT_THAT(read_error(kHeader + "0,0.1,1,0,0\n0,0.1,1,0,0\n"),
              AllOf(HasSubstr(".csv:3: trajectory 0: t = 0.10000000000000001 does not increase")));
  // 12. empty file and header only
  EXPECT_THAT(read_error(""), HasSubstr("no header line (the file is empty)"));
  EXPECT_THAT(read_error(kHeader), HasSubstr("a header and no samples"));
  // 13. a missing file
  EXPECT_THAT(error_of([] { read_trajectory_csv("/nonexistent/x.csv", kPendulum); }),
              HasSubstr("/nonexistent/x.csv: cannot open it"));
}

TEST(MeasuredDataTest, BadRecordingsFailAtTheirSampleWithTheFix) {
  // 14. a gap in t
  EXPECT_THAT(split_error(kHeader + kGood + "3,0,1,0,0\n3,0.1,1,0,0\n3,0.3,1,0,0\n3,0.4,1,0,0\n"),
              AllOf(HasSubstr(".csv:13: trajectory 3: t jumps by 0.2 s"), HasSubstr("a gap"),
                    HasSubstr("resample")));
  // 15. jitter in t
  EXPECT_THAT(split_error(kHeader + kGood + "3,0,1,0,0\n3,0.1,1,0,0\n3,0.2001,1,0,0\n3,0.3,1,0,0\n"),
              HasSubstr("jitter"));
  // 16. two sampling rates
  EXPECT_THAT(split_error(kHeader + kGood + "3,0,1,0,0\n3,0.2,1,0,0\n3,0.4,1,0,0\n"),
              AllOf(HasSubstr("trajectory 3 is sampled every 0.2 s"), HasSubstr("one sampling rate")));
  // 17. a trajectory too short for one pair
  EXPECT_THAT(split_error(kHeader + kGood + "3,0,1,0,0\n"),
              AllOf(HasSubstr(".csv:11: trajectory 3 has 1 sample"), HasSubstr("at least 2")));
  // 18. fewer trajectories than the split needs
  ImportOptions o;
  o.num_validation = 2;
  o.num_inference = 1;
  EXPECT_THAT(split_error(kHeader + kGood, o),
              AllOf(HasSubstr("the data hold 3 trajectories"), HasSubstr("need 4")));
  // 19. (no longer an error) an input that changes within a trajectory: the
  // inference trajectory (the last id) keeps it per sample.
  {
    ImportOptions one;
    one.num_validation = one.num_inference = 1;
    const std::string path = csv_file(kHeader + kGood + "3,0,1,0,0\n3,0.1,1,0,0.5\n3,0.2,1,0,-0.5\n");
    const PhSystemData d = split_measured_data(*pendulum(), read_trajectory_csv(path, kPendulum), one);
    std::remove(path.c_str());
    ASSERT_EQ(d.inference.inputs.size(), 1u);
    ASSERT_EQ(d.inference.inputs[0].size(), 3u);
    EXPECT_EQ(d.inference.inputs[0][1](0), 0.5);
    EXPECT_EQ(d.inference.inputs[0][2](0), -0.5);
  }
  // 20. a sample rate that disagrees with t
  ImportOptions rate;
  rate.num_validation = rate.num_inference = 1;
  rate.sample_rate = 100;
  EXPECT_THAT(split_error(kHeader + kGood, rate),
              AllOf(HasSubstr("--sample-rate 100 Hz disagrees"), HasSubstr("sampled at 10 Hz")));
}

TEST(MeasuredDataTest, TrajectoriesAcrossFilesNeedTheirOwnIds) {
  const auto system = pendulum();
  const std::string a = csv_file(kHeader + kGood), b = csv_file(kHeader + "1,0,1,0,0\n1,0.1,1,0,0\n");
  std::vector<MeasuredTrajectory> all = read_trajectory_csv(a, kPendulum);
  for (auto& m : read_trajectory_csv(b, kPendulum)) all.push_back(std::move(m));
  ImportOptions o;
  o.num_validation = o.num_inference = 1;
  EXPECT_THAT(error_of([&] { split_measured_data(*system, all, o); }),
              AllOf(HasSubstr(b + ":2: trajectory 1 was already read at " + a + ":5"),
                    HasSubstr("its own id")));
  std::remove(a.c_str());
  std::remove(b.c_str());
}

// A CSV trajectory is its numbers, flat: 8 bytes a value, no room left
// over once read (a 224 MB CSV peaked at 2.97 GB resident as one VecX per
// state and input, 0.40 GB flat: docs/BENCHMARKS.md, 2026-11-28).
TEST(MeasuredDataTest, CsvTrajectoriesAreReadIntoFlatArraysOfTheirSize) {
  std::string text = kHeader;
  for (int id = 0; id < 3; ++id) {
    for (int k = 0; k < 100 + id; ++k) {
      text += std::to_string(id) + "," + std::to_string(0.1 * k) + ",1," + std::to_string(k) +
              ",0.5\n";
    }
  }
  const std::string path = csv_file(text);
  const std::vector<MeasuredTrajectory> all = read_trajectory_csv(path, kPendulum);
  ASSERT_EQ(all.size(), 3u);
  for (const MeasuredTrajectory& m : all) {
    EXPECT_EQ(m.size(), static_cast<std::size_t>(100 + m.id));
    EXPECT_EQ(m.x.size(), 2 * m.size());
    EXPECT_EQ(m.u.size(), m.size());
    EXPECT_EQ(m.x.capacity(), m.x.size());
    EXPECT_EQ(m.t.capacity(), m.t.size());
    EXPECT_EQ(m.x[7 * 2 + 1], 7.0);  // sample 7: state 1, input 0
    EXPECT_EQ(m.u[7], 0.5);
  }
  std::remove(path.c_str());
}

// 40 trajectories of 12 to 23 samples at 10 Hz over two files (ids 0, 3,
// 6, ... in the second, so the files interleave), every fourth with an
// input that changes at every sample.
std::pair<std::string, std::string> two_recording_files() {
  std::string a = kHeader, b = kHeader;
  for (int id = 0; id < 40; ++id) {
    std::string& text = id % 3 == 0 ? b : a;
    for (int k = 0; k < 12 + id % 12; ++k) {
      const double q = ((id * 37 + k * 11) % 201 - 100) / 100.0, p = ((id * 13 + k * 29) % 97 - 48) / 50.0;
      text += std::to_string(id) + "," + std::to_string(k) + "e-1," + std::to_string(q) + "," +
              std::to_string(p) + "," + (id % 4 == 0 ? std::to_string(k) + "e-2" : "0.5") + "\n";
    }
  }
  return {csv_file(a), csv_file(b)};
}

// `phnn import` reads its files twice, one trajectory at a time
// (recorded_trajectories, split_measured_stream): the data set, its
// options and its summary are those of reading every trajectory first, in
// both splits, shuffled or not. The checksums are those of the data sets
// phnn import wrote for these files and options before it streamed
// (48ade44): the same data set, bit for bit.
TEST(MeasuredDataTest, TwoPassesOverTheFilesGiveTheDataSetOfReadingThemAll) {
  const auto system = pendulum();
  const auto [a, b] = two_recording_files();
  std::vector<MeasuredTrajectory> all = read_trajectory_csv(a, kPendulum);
  for (auto& m : read_trajectory_csv(b, kPendulum)) all.push_back(std::move(m));
  const MeasurementMap states = MeasurementMap::of_system_text(system->source_text(), "pendulum.toml");
  ImportOptions by_id, shuffled, blocks, windows;
  by_id.num_validation = shuffled.num_validation = 5;
  by_id.num_inference = shuffled.num_inference = 4;
  shuffled.split_seed = 3;
  shuffled.pair_window = 0.45;
  blocks.split = windows.split = ImportSplit::kBlocks;
  windows.window = 0.2;
  windows.num_validation = 30;
  windows.data_seed = 7;
  const std::pair<ImportOptions, std::string> cases[] = {
      {by_id, "ad8c324ff05a773f"}, {shuffled, "ac2b43035f5b40b6"},
      {blocks, "89e853f1155bc8a4"}, {windows, "e8fce8fe83fff1d5"}};
  for (const auto& [o, checksum] : cases) {
    std::string in_memory, streamed;
    const PhSystemData want = split_measured_data(*system, all, o, &in_memory);
    const MeasuredDataSet rows =
        split_measured_stream(*system, recorded_trajectories({a, b}, kPendulum, states), o, &streamed);
    const PhSystemData got = to_ph_system_data(rows);
    EXPECT_EQ(data_set_checksum(got), data_set_checksum(want));
    EXPECT_EQ(data_set_checksum(got), checksum) << streamed;
    EXPECT_EQ(streamed, in_memory);
    EXPECT_EQ(got.train.trajectory, want.train.trajectory);
    EXPECT_EQ(got.train.position, want.train.position);
    EXPECT_EQ(got.validation.trajectory, want.validation.trajectory);
    EXPECT_EQ(got.validation.position, want.validation.position);
    EXPECT_EQ(got.inference.trajectory, want.inference.trajectory);
    EXPECT_EQ(got.inference.position, want.inference.position);
    EXPECT_EQ(got.inference.inputs.size(), want.inference.inputs.size());
    EXPECT_EQ(got.split, want.split);
    EXPECT_EQ(got.options.alpha, want.options.alpha);
    EXPECT_EQ(got.options.beta, want.options.beta);
    EXPECT_EQ(got.options.num_train_max, want.options.num_train_max);
    // The file written from the rows is the file of the data set.
    const std::string path =
        ::testing::TempDir() + "phnn_streamed_" + std::to_string(::getpid()) + ".h5";
    write_ph_dataset_file(path, rows.data, rows.train, rows.validation, rows.inference);
    EXPECT_EQ(data_set_checksum(read_ph_dataset_file(path)), checksum);
    std::remove(path.c_str());
  }
  // A file that changes between the passes is refused, not half read.
  int pass = 0;
  const TrajectorySource changing = [&](const TrajectoryVisitor& visit) {
    for (const MeasuredTrajectory& m : all) {
      if (pass == 0 || m.id != 7) visit(m);
    }
    ++pass;
  };
  EXPECT_THAT(error_of([&] { split_measured_stream(*system, changing, by_id); }),
              AllOf(HasSubstr("not what the first pass over the recordings read"),
                    HasSubstr("did a file change")));
  std::remove(a.c_str());
  std::remove(b.c_str());
}

// HDF5 trajectory files: the documented layout reads like the CSV.
std::string h5_file(const std::function<void(h5::File&)>& fill) {
  static int counter = 0;
  const std::string path = ::testing::TempDir() + "phnn_traj_" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter++) + ".h5";
  h5::File f = h5::File::create(path);
  fill(f);
  f.close();
  return path;
}

void put_trajectory(h5::File& f, const std::string& id, int samples, int x_cols = 2, bool with_u = true) {
  const std::string g = "/trajectories/" + id;
  f.create_group(g);
  std::vector<double> t, x, u;
  for (int n = 0; n < samples; ++n) {
    t.push_back(n * 0.1);
    for (int j = 0; j < x_cols; ++j) x.push_back(n + j);
    u.push_back(0.5);
  }
  const auto n = static_cast<std::uint64_t>(samples);
  f.write(g + "/t", {n}, t);
  f.write(g + "/x", {n, static_cast<std::uint64_t>(x_cols)}, x);
  if (with_u) f.write(g + "/u", {n, 1}, u);
}

TEST(MeasuredDataTest, Hdf5TrajectoryFilesReadAndFailWithTheirPlace) {
  const std::string good = h5_file([](h5::File& f) {
    f.create_group("/trajectories");
    f.set_attribute("/trajectories", "state_names", std::string("q,p"));
    put_trajectory(f, "3", 4);
    put_trajectory(f, "12", 5);
  });
  const auto read = read_trajectory_h5(good, kPendulum);
  ASSERT_EQ(read.size(), 2u);
  std::set<std::int64_t> got;
  for (const auto& m : read) {
    got.insert(m.id);
    EXPECT_EQ(m.x.size(), 2 * m.t.size());
    EXPECT_EQ(m.x[1 * 2 + 1], 2.0);  // sample 1: state 1
    EXPECT_EQ(m.u[0], 0.5);
  }
  EXPECT_EQ(got, (std::set<std::int64_t>{3, 12}));
  // 21. no /trajectories group
  const std::string none = h5_file([](h5::File& f) { f.create_group("/other"); });
  EXPECT_THAT(error_of([&] { read_trajectory_h5(none, kPendulum); }), HasSubstr("no group /trajectories"));
  // 22. x with the wrong number of columns
  const std::string wide = h5_file([](h5::File& f) { put_trajectory(f, "0", 4, 3); });
  EXPECT_THAT(error_of([&] { read_trajectory_h5(wide, kPendulum); }),
              AllOf(HasSubstr(":/trajectories/0: t must be (N) and x (N x 2)"), HasSubstr("(q,p)")));
  // 23. inputs missing for a system with inputs
  const std::string no_u = h5_file([](h5::File& f) { put_trajectory(f, "0", 4, 2, false); });
  EXPECT_THAT(error_of([&] { read_trajectory_h5(no_u, kPendulum); }),
              AllOf(HasSubstr("no dataset u"), HasSubstr("record them")));
  // 24. state names in another order
  const std::string swapped = h5_file([](h5::File& f) {
    f.create_group("/trajectories");
    f.set_attribute("/trajectories", "state_names", std::string("p,q"));
    put_trajectory(f, "0", 4);
  });
  EXPECT_THAT(error_of([&] { read_trajectory_h5(swapped, kPendulum); }),
              HasSubstr("state_names = \"p,q\" but the system's are \"q,p\""));
  // 25. a group name that is not an id
  const std::string named = h5_file([](h5::File& f) { put_trajectory(f, "run-a", 4); });
  EXPECT_THAT(error_of([&] { read_trajectory_h5(named, kPendulum); }),
              HasSubstr("trajectory \"run-a\" is not a non-negative integer"));
  // 26. not HDF5 at all
  const std::string text = csv_file(kHeader);
  EXPECT_THAT(error_of([&] { read_trajectory_h5(text, kPendulum); }), HasSubstr("not an HDF5 file"));
  for (const std::string& p : {good, none, wide, no_u, swapped, named, text}) std::remove(p.c_str());
}

}  // namespace
}  // namespace phnn
