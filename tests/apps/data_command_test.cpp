// tests/apps/data_command_test.cpp — `phnn data --system FILE`: a system
// file's data set written with its names and text; a bad file refused with
// FILE:LINE and the fix, and no output file left behind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "phnn/store/ph_dataset_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

int phnn(const std::string& args, std::string* output) {
  return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, output);
}

TEST(DataCommandTest, WritesASystemFilesDataSet) {
  const std::string out =
      ::testing::TempDir() + std::to_string(::getpid()) + "_phnn_data_pendulum.h5";
  std::remove(out.c_str());
  std::string log;
  ASSERT_EQ(phnn("data --system " + std::string(PHNN_SOURCE_DIR) +
                     "/sweeps/systems/pendulum.toml --n-train 5 --out " + out,
                 &log),
            0)
      << log;
  EXPECT_THAT(log, HasSubstr("pendulum"));
  const PhSystemData data = read_ph_dataset_file(out);
  EXPECT_EQ(data.system_name, "pendulum");
  EXPECT_EQ(data.state_names, (std::vector<std::string>{"q", "p"}));
  EXPECT_EQ(data.state_units, (std::vector<std::string>{"rad", "kg m^2/s"}));
  EXPECT_THAT(data.system_text, HasSubstr("m*g*l*(1 - cos(q))"));
  EXPECT_EQ(data.train.size(), 5u);
  EXPECT_EQ(data.validation.size(), 2500u);
  EXPECT_EQ(data.inference.size(), 100u);
  EXPECT_EQ(data.inference.states[0].size(), 501u);
  std::remove(out.c_str());
}

// The bits of a system file's data depend on the file only, not on the
// process: GiNaC orders the terms of its expressions by hashes of addresses
// (different in every process), so two `phnn data` processes compare them.
TEST(DataCommandTest, SystemFileDataAreTheSameBitsInEveryProcess) {
  std::vector<PhSystemData> runs;
  for (int k = 0; k < 2; ++k) {
    const std::string out = ::testing::TempDir() + std::to_string(::getpid()) + "_phnn_data_bits_" +
                            std::to_string(k) + ".h5";
    std::remove(out.c_str());
    std::string log;
    ASSERT_EQ(phnn("data --system " + std::string(PHNN_SOURCE_DIR) +
                       "/sweeps/systems/coupled-duffing.toml --n-train 25 --out " + out,
                   &log),
              0)
        << log;
    runs.push_back(read_ph_dataset_file(out));
    std::remove(out.c_str());
  }
  const PhSystemData& a = runs[0];
  const PhSystemData& b = runs[1];
  ASSERT_EQ(a.inference.size(), b.inference.size());
  for (std::size_t i = 0; i < a.inference.size(); ++i) {
    for (std::size_t n = 0; n < a.inference.states[i].size(); ++n) {
      ASSERT_EQ(a.inference.states[i][n], b.inference.states[i][n])
          << "trajectory " << i << ", step " << n;
    }
  }
  for (std::size_t i = 0; i < a.validation.size(); ++i) {
    ASSERT_EQ(a.validation.x_next[i], b.validation.x_next[i]) << "validation pair " << i;
  }
}

TEST(DataCommandTest, RefusesAMalformedSystemFileWithItsLine) {
  const std::string sys =
      ::testing::TempDir() + std::to_string(::getpid()) + "_phnn_bad_system.toml";
  const std::string out = ::testing::TempDir() + std::to_string(::getpid()) + "_phnn_bad_system.h5";
  std::remove(out.c_str());
  std::ofstream(sys) << "name = \"bad\"\nstates = [\"q\", \"p\"]\nH = \"q^2 + p^2 + mass\"\n"
                        "S = [[0, 1], [-1, 0]]\n[initial]\nmethod = \"energy\"\nenergy = [0.1, 1]\n";
  std::string log;
  EXPECT_EQ(phnn("data --system " + sys + " --out " + out, &log), 2);
  EXPECT_THAT(log, HasSubstr(sys + ":3: unknown symbol \"mass\""));
  EXPECT_THAT(log, HasSubstr("declare it under [parameters]"));
  std::ifstream probe(out);
  EXPECT_FALSE(probe.good()) << "no output file for a refused system";
  EXPECT_EQ(phnn("data --system " + sys + " --damping 0.2 --out " + out, &log), 2);
  EXPECT_THAT(log, HasSubstr("a system file sets its own under [parameters]"));
  std::remove(sys.c_str());
}

// `phnn train --system FILE`: the n-dimensional models train and print the
// per-seed table; --out (2-state results files only) is refused up front.
// `phnn train --system FILE --out`: a results file like a sweep's, which
// reduce and eval read without the system file (its text is stored).
TEST(TrainCommandTest, TrainsOnASystemFileAndWritesItsResults) {
  const std::string sys = std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/coupled-duffing.toml";
  std::string log;
  ASSERT_EQ(phnn("train --system " + sys + " --model phnn-s-rk2 --seeds 0 --steps 5 --quiet", &log), 0)
      << log;
  EXPECT_THAT(log, HasSubstr("coupled-duffing (4 states, 2 ports, 1 input) PHNN-S-RK2"));
  EXPECT_THAT(log, HasSubstr("median [IQR]"));
  const std::string out =
      ::testing::TempDir() + std::to_string(::getpid()) + "_phnn_train_file_out.h5";
  std::remove(out.c_str());
  ASSERT_EQ(phnn("train --system " + sys + " --model phnn-jr-dg --seeds 0,1 --steps 5 --quiet --out " +
                     out,
                 &log),
            0)
      << log;
  EXPECT_THAT(log, HasSubstr("runs written to " + out));
  ASSERT_EQ(phnn("reduce " + out, &log), 0) << log;
  EXPECT_THAT(log, AllOf(HasSubstr("— coupled-duffing"), HasSubstr("PHNN-JR-DG")));
  ASSERT_EQ(phnn("reduce " + out + " --format csv --per-run", &log), 0) << log;
  const std::size_t line = log.find('\n') + 1;
  ASSERT_EQ(phnn("eval " + out + " --run " + log.substr(line, 16), &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("bitwise equal"));
  EXPECT_EQ(phnn("train --system " + sys + " --model phnn-s-rk2 --seeds 0 --steps 5 --out " + out, &log), 2);
  EXPECT_THAT(log, HasSubstr("exists; phnn train writes a new results file"));
  std::remove(out.c_str());
}

}  // namespace
}  // namespace phnn
