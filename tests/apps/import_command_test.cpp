// tests/apps/import_command_test.cpp — `phnn data --csv` and `phnn import`:
// the acceptance's round trip (a generated set through CSV trains to the
// same MSEs bit for bit), bad input refused with exit 2 and no output file,
// and files that are not phnn's never overwritten.
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "h5/h5file.h"
#include "phnn/store/ph_dataset_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

int phnn(const std::string& args, std::string* output) {
  return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, output);
}

const std::string kPendulum = std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/pendulum.toml";

bool exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

std::vector<double> mses(const std::string& results) {
  return h5::File::open(results, h5::Access::kReadOnly).read_doubles("/runs/mse");
}

// With a constant torque and with a torque of three sines (time-varying
// inputs: pairs carry u_n, inference replays the recorded inputs).
TEST(ImportCommandTest, AGeneratedSetThroughCsvTrainsToTheSameMsesBitForBit) {
  for (const std::string name : {"pendulum", "pendulum-forced"}) {
    const std::string system = std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/" + name + ".toml";
    const std::string dir = ::testing::TempDir() + "phnn_import_rt_" + std::to_string(::getpid()) + "/";
    ASSERT_EQ(std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str()), 0);
    std::string log;
    ASSERT_EQ(phnn("data --system " + system + " --n-train 25 --out " + dir + "a.h5 --csv " + dir +
                       "a.csv",
                   &log),
              0)
        << log;
    ASSERT_EQ(phnn("import " + dir + "a.csv --split trajectories --system " + system + " --out " + dir + "b.h5", &log), 0)
        << log;
    EXPECT_THAT(log, AllOf(HasSubstr("sample rate 100 Hz"), HasSubstr("25 training pairs")));
    for (const char* d : {"a", "b"}) {
      ASSERT_EQ(phnn("train --system " + system + " --model phnn-s-dg --n-train 25 --seeds 0-1 "
                     "--steps 200 --eval-every 100 --quiet --data " + dir + d + ".h5 --out " + dir +
                     "r" + d + ".h5",
                     &log),
                0)
          << log;
    }
    const std::vector<double> a = mses(dir + "ra.h5"), b = mses(dir + "rb.h5");
    ASSERT_EQ(a.size(), 2u);
    EXPECT_TRUE(std::isfinite(a[0]) && std::isfinite(a[1])) << name;
    EXPECT_EQ(a, b) << name;  // bitwise
    std::system(("rm -rf " + dir).c_str());
  }
}

// A structure-only system file (no H) is enough for measured data: the
// same recordings imported with it train to the MSEs of the full file
// (same name, so the same pair draws; same S, so the same models). It
// generates nothing: `phnn data` refuses it at its name, exit 2.
TEST(ImportCommandTest, AStructureOnlySystemFileIsEnoughForMeasuredData) {
  const std::string dir = ::testing::TempDir() + "phnn_import_structure_" + std::to_string(::getpid()) + "/";
  ASSERT_EQ(std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str()), 0);
  std::ifstream in(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/pendulum-structure.toml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string own_name = "name = \"pendulum-structure\"";
  text.replace(text.find(own_name), own_name.size(), "name = \"pendulum\"");
  std::ofstream(dir + "structure.toml") << text;
  std::string log;
  ASSERT_EQ(phnn("data --system " + kPendulum + " --n-train 25 --out " + dir + "a.h5 --csv " + dir +
                     "a.csv", &log), 0) << log;
  std::vector<double> mse[2];
  int k = 0;
  for (const std::string& system : {kPendulum, dir + "structure.toml"}) {
    ASSERT_EQ(phnn("import " + dir + "a.csv --split trajectories --system " + system + " --out " + dir + "b.h5", &log), 0) << log;
    ASSERT_EQ(phnn("train --system " + system + " --model phnn-jr-rk2 --n-train 25 --seeds 0-1 "
                   "--steps 100 --eval-every 50 --quiet --data " + dir + "b.h5 --out " + dir + "r.h5", &log),
              0) << log;
    mse[k++] = mses(dir + "r.h5");
    std::remove((dir + "b.h5").c_str());
    std::remove((dir + "r.h5").c_str());
  }
  EXPECT_TRUE(std::isfinite(mse[1][0]));
  EXPECT_EQ(mse[0], mse[1]);  // bitwise
  EXPECT_EQ(phnn("data --system " + dir + "structure.toml --out " + dir + "c.h5", &log), 2);
  EXPECT_THAT(log, AllOf(HasSubstr("structure.toml:7:"), HasSubstr("defines no energy H")));
  EXPECT_FALSE(exists(dir + "c.h5"));
  std::system(("rm -rf " + dir).c_str());
}

// One long recording (20 s at 100 Hz, a decaying oscillation under a
// changing torque) imported by time blocks, then trained from the data set
// alone: `phnn train --data` takes the system the file stores.
TEST(ImportCommandTest, ALongRecordingByBlocksTrainsWithoutSystem) {
  const std::string dir = ::testing::TempDir() + "phnn_import_blocks_" + std::to_string(::getpid()) + "/";
  ASSERT_EQ(std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str()), 0);
  {
    std::ofstream csv(dir + "rec.csv");
    csv.precision(17);
    csv << "trajectory,t,q,p,u\n";
    for (int k = 0; k < 2000; ++k) {
      const double t = k / 100.0, decay = std::exp(-0.1 * t);
      csv << 0 << "," << t << "," << 0.5 * decay * std::cos(4.4 * t) << "," << -0.1 * decay * std::sin(4.4 * t)
          << "," << 0.05 * std::sin(0.7 * t) << "\n";
    }
  }
  std::string log;
  ASSERT_EQ(phnn("import " + dir + "rec.csv --system " + kPendulum + " --window 2 --out " + dir + "rec.h5", &log), 0)
      << log;
  EXPECT_THAT(log, AllOf(HasSubstr("1 recording cut in time"), HasSubstr("1199 training pairs"),
                         HasSubstr("1 inference window of 2 s")));
  ASSERT_EQ(phnn("train --data " + dir + "rec.h5 --model phnn-s-dg --n-train 25 --steps 20 --eval-every 10 "
                 "--seeds 0-1 --quiet --out " + dir + "r.h5", &log), 0)
      << log;
  const std::vector<double> mse = mses(dir + "r.h5");
  ASSERT_EQ(mse.size(), 2u);
  EXPECT_TRUE(std::isfinite(mse[0]) && std::isfinite(mse[1]));
  EXPECT_EQ(phnn("train --data " + dir + "rec.h5 --system harmonic --model phnn-s-dg --steps 2", &log), 2);
  EXPECT_THAT(log, AllOf(HasSubstr("holds system pendulum"), HasSubstr("drop --system")));
  EXPECT_EQ(phnn("import " + dir + "rec.csv --system " + kPendulum + " --pair-window 0.3 --out " + dir + "x.h5", &log), 2);
  EXPECT_THAT(log, HasSubstr("--pair-window belongs to --split trajectories"));
  EXPECT_EQ(phnn("import " + dir + "rec.csv --system " + kPendulum + " --blocks 0.9,0.2 --out " + dir + "x.h5", &log), 2);
  EXPECT_THAT(log, HasSubstr("sum < 1"));
  EXPECT_FALSE(exists(dir + "x.h5"));
  std::system(("rm -rf " + dir).c_str());
}

TEST(ImportCommandTest, BadInputExitsTwoAndWritesNoDataSet) {
  const std::string dir = ::testing::TempDir() + "phnn_import_bad_" + std::to_string(::getpid()) + "/";
  ASSERT_EQ(std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str()), 0);
  std::ofstream(dir + "bad.csv") << "trajectory,t,q,p,u\n0,0,1,0,0\n0,0.1,1,0\n";
  std::string log;
  EXPECT_EQ(phnn("import " + dir + "bad.csv --system " + kPendulum + " --out " + dir + "o.h5", &log), 2);
  EXPECT_THAT(log, AllOf(HasSubstr("phnn import: " + dir + "bad.csv:3: 4 fields"), HasSubstr("one value per column")));
  EXPECT_FALSE(exists(dir + "o.h5"));
  // A built-in name: the system file is named.
  EXPECT_EQ(phnn("import " + dir + "bad.csv --system harmonic --out " + dir + "o.h5", &log), 2);
  EXPECT_THAT(log, HasSubstr("sweeps/systems/harmonic.toml"));
  // --out over a file phnn did not write (the input itself, or a user's file) is refused.
  EXPECT_EQ(phnn("import " + dir + "bad.csv --system " + kPendulum + " --out " + dir + "bad.csv", &log), 2);
  EXPECT_THAT(log, HasSubstr("is the input"));
  std::ofstream(dir + "mine.csv") << "trajectory,t,q,p,u\n";
  EXPECT_EQ(phnn("data --system " + kPendulum + " --n-train 5 --out " + dir + "d.h5 --csv " + dir + "mine.csv",
                 &log),
            2);
  EXPECT_THAT(log, AllOf(HasSubstr("mine.csv: exists"), HasSubstr("never overwrites")));
  EXPECT_FALSE(exists(dir + "d.h5"));
  std::ifstream in(dir + "mine.csv");
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "trajectory,t,q,p,u");
  std::system(("rm -rf " + dir).c_str());
}

TEST(ImportCommandTest, DataNoiseIsRecordedAndItsMisusesRefused) {
  const std::string dir = ::testing::TempDir() + "phnn_noise_cli_" + std::to_string(::getpid()) + "/";
  ASSERT_EQ(std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str()), 0);
  std::string log;
  ASSERT_EQ(phnn("data --system " + kPendulum + " --n-train 5 --noise 0.01 --out " + dir + "n.h5", &log), 0)
      << log;
  EXPECT_THAT(read_ph_dataset_file(dir + "n.h5").noise, HasSubstr("relative levels 0.01 0.01"));
  // A built-in name is its shipped file: noise applies alike.
  ASSERT_EQ(phnn("data --system harmonic --n-train 5 --noise 0.01 --out " + dir + "h.h5", &log), 0) << log;
  EXPECT_THAT(read_ph_dataset_file(dir + "h.h5").noise, HasSubstr("relative levels 0.01 0.01"));
  EXPECT_EQ(phnn("data --system " + kPendulum + " --noise 0.01,0.02,0.03 --out " + dir + "x.h5", &log), 2);
  EXPECT_THAT(log, HasSubstr("3 levels for 2 states"));
  EXPECT_EQ(phnn("data --system " + kPendulum + " --noise -1 --out " + dir + "x.h5", &log), 2);
  EXPECT_THAT(log, HasSubstr("is not a number >= 0"));
  EXPECT_EQ(phnn("data --system " + kPendulum + " --noise 0.01 --csv " + dir + "x.csv --out " + dir + "x.h5",
                 &log),
            2);
  EXPECT_THAT(log, HasSubstr("use one of them"));
  EXPECT_FALSE(exists(dir + "x.h5"));
  std::system(("rm -rf " + dir).c_str());
}

}  // namespace
}  // namespace phnn
