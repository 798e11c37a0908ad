// tests/data/measured_test.cpp — recorded trajectories into data sets: a
// generated set written as CSV and read back is the same set bit for bit;
// the split keeps training, validation and inference trajectories apart;
// pair windows, shuffles and cuts; and every malformed CSV or HDF5 input
// fails with its place and the fix.
#include "phnn/data/measured.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/store/trajectory_files.h"
#include "phnn/systems/system_file.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::unique_ptr<PhSystem> pendulum() {
  return load_system_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/pendulum.toml");
}

DatasetOptions small_options() {
  DatasetOptions o;
  o.num_train_max = 6;
  o.num_validation = 7;
  o.num_inference = 3;
  o.beta = 1.0;  // 100 inference steps
  return o;
}

void expect_same_pairs(const PhPairSet& a, const PhPairSet& b) {
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.x_next, b.x_next);
  EXPECT_EQ(a.u, b.u);
  EXPECT_EQ(a.trajectory, b.trajectory);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.step, b.step);
}

// The acceptance's round trip in memory: generate, write the trajectories
// as CSV, read them, split them: the same pairs and inference trajectories,
// bit for bit (the pair draws share their key; t = n / 100 gives h = 0.01).
TEST(MeasuredDataTest, AGeneratedSetWrittenAsCsvAndImportedIsTheSameSet) {
  const auto system = pendulum();
  const PhSystemData data = make_ph_system_data(*system, small_options(), 4);
  const std::string csv = ::testing::TempDir() + "phnn_measured_roundtrip.csv";
  const TrajectoryColumns columns{system->state_names(), system->input_names()};
  write_trajectory_csv(csv, columns, generated_trajectories(*system, data), "test");
  EXPECT_TRUE(is_phnn_trajectory_csv(csv));
  ImportOptions o;
  o.num_validation = 7;
  o.num_inference = 3;
  std::string summary;
  const PhSystemData back = split_measured_data(*system, read_trajectory_csv(csv, columns), o, &summary);
  EXPECT_THAT(summary, HasSubstr("sample rate 100 Hz (from t)"));
  expect_same_pairs(back.train, data.train);
  expect_same_pairs(back.validation, data.validation);
  EXPECT_EQ(back.inference.states, data.inference.states);
  EXPECT_EQ(back.inference.u, data.inference.u);
  EXPECT_EQ(back.inference.trajectory, data.inference.trajectory);
  EXPECT_EQ(back.inference.step, data.inference.step);
  EXPECT_EQ(back.system_text, system->source_text());
  std::remove(csv.c_str());
}

// Synthetic recordings: trajectory id k has `samples` samples at 50 Hz,
// q = k + t, p = -t, u = 0.1 k.
std::vector<MeasuredTrajectory> recordings(int count, int samples) {
  std::vector<MeasuredTrajectory> all;
  for (int k = count - 1; k >= 0; --k) {  // out of order: the split sorts by id
    MeasuredTrajectory m;
    m.id = 10 * k;
    m.source = "rec.csv";
    for (int n = 0; n < samples + k % 3; ++n) {
      const double t = n / 50.0;
      m.t.push_back(t);
      VecX x(2);
      x << k + t, -t;
      m.x.push_back(x);
      m.u.push_back(VecX::Constant(1, 0.1 * k));
    }
    all.push_back(std::move(m));
  }
  return all;
}

std::set<std::int64_t> ids(const std::vector<std::int64_t>& v) { return {v.begin(), v.end()}; }

TEST(MeasuredDataTest, SplitKeepsTheRolesApartAndCutsInferenceToTheShortest) {
  const auto system = pendulum();
  ImportOptions o;
  o.num_validation = 4;
  o.num_inference = 3;
  for (std::int64_t split_seed : {-1, 0, 7}) {
    o.split_seed = split_seed;
    const PhSystemData d = split_measured_data(*system, recordings(12, 20), o);
    const auto train = ids(d.train.trajectory), val = ids(d.validation.trajectory),
               inf = ids(d.inference.trajectory);
    EXPECT_EQ(train.size() + val.size() + inf.size(), 12u);
    std::set<std::int64_t> all = train;
    all.insert(val.begin(), val.end());
    all.insert(inf.begin(), inf.end());
    EXPECT_EQ(all.size(), 12u) << "a trajectory serves two roles";
    std::size_t shortest = 1000;
    for (std::int64_t id : inf) shortest = std::min<std::size_t>(shortest, 20 + (id / 10) % 3);
    for (const auto& states : d.inference.states) EXPECT_EQ(states.size(), shortest);
    EXPECT_DOUBLE_EQ(d.train.step, 0.02);
    for (std::size_t i = 0; i < d.train.size(); ++i) {
      const double k = static_cast<double>(d.train.trajectory[i] / 10);
      const double t = d.train.position[i] / 50.0;  // x_n is the sample at its position
      EXPECT_DOUBLE_EQ(d.train.x[i](0), k + t);
      EXPECT_DOUBLE_EQ(d.train.x_next[i](1), -(d.train.position[i] + 1) / 50.0);
      EXPECT_DOUBLE_EQ(d.train.u[i](0), 0.1 * k);
    }
    if (split_seed < 0) {  // in id order: the last three ids infer
      EXPECT_EQ(inf, (std::set<std::int64_t>{90, 100, 110}));
      EXPECT_EQ(train, (std::set<std::int64_t>{0, 10, 20, 30, 40}));
    }
  }
  o.split_seed = 7;
  const PhSystemData a = split_measured_data(*system, recordings(12, 20), o);
  o.split_seed = 8;
  const PhSystemData b = split_measured_data(*system, recordings(12, 20), o);
  EXPECT_NE(ids(a.inference.trajectory), ids(b.inference.trajectory));  // 220 choices
}

TEST(MeasuredDataTest, PairWindowLimitsWherePairsAreDrawn) {
  const auto system = pendulum();
  ImportOptions o;
  o.num_validation = 2;
  o.num_inference = 1;
  o.pair_window = 0.1;  // t_n+1 <= 0.1 s at 50 Hz: n + 1 <= 5
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    o.data_seed = seed;
    const PhSystemData d = split_measured_data(*system, recordings(8, 40), o);
    for (int n : d.train.position) EXPECT_LE(n, 4);
    for (int n : d.validation.position) EXPECT_LE(n, 4);
  }
  o.pair_window = 0.01;  // shorter than one step
  EXPECT_THROW(
      {
        try {
          split_measured_data(*system, recordings(8, 40), o);
        } catch (const MeasuredDataError& e) {
          EXPECT_THAT(e.what(), HasSubstr("widen the window"));
          throw;
        }
      },
      MeasuredDataError);
}

// Measurement noise: N(0, sigma_j^2) on the pairs only, sigma_j = level x
// the clean pairs' spread of state j, each trajectory's draws its own.
TEST(MeasuredDataTest, NoiseIsGaussianWithTheAskedSigmaOnThePairsOnly) {
  const auto system = pendulum();
  DatasetOptions o = small_options();
  o.num_validation = 500;
  const PhSystemData clean = make_ph_system_data(*system, o, 6);
  PhSystemData noisy = clean;
  NoiseOptions noise;
  noise.levels = {0.01, 0.05};
  const std::vector<double> sigma = add_measurement_noise(&noisy, system->rng_id(), noise);
  ASSERT_EQ(sigma.size(), 2u);
  EXPECT_THAT(noisy.noise, AllOf(HasSubstr("relative levels 0.01 0.05"), HasSubstr("inference clean")));
  for (int j = 0; j < 2; ++j) {
    // The spread, independently: standard deviation of x_j over the validation pairs.
    std::vector<double> v;
    for (const VecX& x : clean.validation.x) v.push_back(x(j));
    double mean = 0, var = 0;
    for (double x : v) mean += x / static_cast<double>(v.size());
    for (double x : v) var += (x - mean) * (x - mean) / static_cast<double>(v.size() - 1);
    EXPECT_NEAR(sigma[static_cast<std::size_t>(j)], noise.levels[static_cast<std::size_t>(j)] * std::sqrt(var), 1e-12);
    // Standardized errors: mean ~ 0 (SE 0.03 for ~1000), std ~ 1 (SE 0.022).
    std::vector<double> z;
    for (int split = 0; split < 2; ++split) {
      const PhPairSet& c = split ? clean.validation : clean.train;
      const PhPairSet& n = split ? noisy.validation : noisy.train;
      for (std::size_t i = 0; i < c.size(); ++i) {
        z.push_back((n.x[i](j) - c.x[i](j)) / sigma[static_cast<std::size_t>(j)]);
        z.push_back((n.x_next[i](j) - c.x_next[i](j)) / sigma[static_cast<std::size_t>(j)]);
      }
    }
    double zm = 0, zv = 0;
    for (double x : z) zm += x / static_cast<double>(z.size());
    for (double x : z) zv += (x - zm) * (x - zm) / static_cast<double>(z.size() - 1);
    EXPECT_LT(std::abs(zm), 0.15) << "state " << j;
    EXPECT_NEAR(std::sqrt(zv), 1.0, 0.1) << "state " << j;
  }
  EXPECT_EQ(noisy.inference.states, clean.inference.states);
  // A trajectory's noise depends on its index only: fewer training pairs
  // keep the same noisy pairs.
  PhSystemData fewer = make_ph_system_data(*system, o, 3);
  add_measurement_noise(&fewer, system->rng_id(), noise);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(fewer.train.x[i], noisy.train.x[i]);
  EXPECT_EQ(fewer.validation.x_next, noisy.validation.x_next);
  EXPECT_NE(data_set_checksum(noisy), data_set_checksum(clean));
  NoiseOptions wrong;
  wrong.levels = {0.1};
  EXPECT_THROW(add_measurement_noise(&fewer, system->rng_id(), wrong), std::invalid_argument);
}

// ------------------------------------------------------------ bad input

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
  const std::string path = ::testing::TempDir() + "phnn_bad_" + std::to_string(counter++) + ".csv";
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
  // 19. an input that changes within a trajectory
  EXPECT_THAT(split_error(kHeader + kGood + "3,0,1,0,0\n3,0.1,1,0,0.5\n"),
              AllOf(HasSubstr(".csv:12: trajectory 3: the input changes"), HasSubstr("split the recording")));
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

// HDF5 trajectory files: the documented layout reads like the CSV.
std::string h5_file(const std::function<void(h5::File&)>& fill) {
  static int counter = 0;
  const std::string path = ::testing::TempDir() + "phnn_traj_" + std::to_string(counter++) + ".h5";
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
    EXPECT_EQ(m.x.size(), m.t.size());
    EXPECT_EQ(m.x[1](1), 2.0);
    EXPECT_EQ(m.u[0](0), 0.5);
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
