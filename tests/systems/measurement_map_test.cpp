// tests/systems/measurement_map_test.cpp — a system file's [measurement]:
// states computed from recorded columns and parameters (against the closed
// form), the columns a recording must then hold, skipped columns, errors at
// the entry's line; and `phnn import` of such a recording.
#include "phnn/systems/measurement_map.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/data/measured.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/systems/system_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A pendulum recorded as angle q and angular velocity v (rad/s); the
// momentum p = m l^2 v.
const std::string kMeasured = R"(name = "pendulum-v"
states = ["q", "p"]
inputs = ["u"]
ports = ["w"]
S = [[0, 1, 0, 0], [-1, 0, -1, -1], [0, 1, 0, 0], [0, 1, 0, 0]]
[parameters]
m = 0.2
l = 0.5
[measurement]
p = "m*l^2*v"
ignore = ["temperature"]
)";

std::string error_of(const std::string& text) {
  try {
    MeasurementMap::of_system_text(text, "m.toml");
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(MeasurementMapTest, ComputesStatesFromRecordedColumns) {
  const MeasurementMap map = MeasurementMap::of_system_text(kMeasured, "m.toml");
  EXPECT_FALSE(map.identity());
  EXPECT_THAT(map.recorded(), ElementsAre("q", "v"));
  EXPECT_THAT(map.ignored(), ElementsAre("temperature"));
  EXPECT_EQ(map.describe(), "p = m*l^2*v");
  for (double v : {0.0, 1.5, -3.25, 1e-7}) {
    const double recorded[2] = {0.3, v};
    double x[2] = {0, 0};
    map.states(recorded, x);
    EXPECT_EQ(x[0], 0.3);
    EXPECT_NEAR(x[1], 0.2 * 0.25 * v, 1e-16 * std::abs(v));  // m l^2 = 0.05, two roundings
  }
  // Without [measurement]: every state is its own column.
  const MeasurementMap plain =
      MeasurementMap::of_system_text(kMeasured.substr(0, kMeasured.find("[measurement]")), "m.toml");
  EXPECT_TRUE(plain.identity());
  EXPECT_THAT(plain.recorded(), ElementsAre("q", "p"));
}

TEST(MeasurementMapTest, ErrorsNameTheEntryAndTheFix) {
  const auto with = [](const std::string& from, const std::string& to) {
    std::string t = kMeasured;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  EXPECT_THAT(error_of(with("p = \"m*l^2*v\"", "pp = \"v\"")),
              AllOf(HasSubstr("m.toml:10:"), HasSubstr("\"pp\" is not a state"), HasSubstr("\"p\"?")));
  EXPECT_THAT(error_of(with("m*l^2*v", "2*p")),
              AllOf(HasSubstr("m.toml:10:"), HasSubstr("reads \"p\", which is a state [measurement] computes")));
  EXPECT_THAT(error_of(with("m*l^2*v", "u*v")), HasSubstr("which is an input"));
  EXPECT_THAT(error_of(with("m*l^2*v", "m*(v")), AllOf(HasSubstr("m.toml:10:"), HasSubstr("is not an expression")));
  EXPECT_THAT(error_of(with("p = \"m*l^2*v\"", "p = 3")), HasSubstr("must be an expression in quotes"));
}

// The recording holds q, v, u and a temperature column; import computes p.
TEST(MeasurementMapTest, ImportComputesTheStatesAndSkipsColumns) {
  const std::string dir = ::testing::TempDir() + "phnn_measurement_" + std::to_string(::getpid()) + "/";
  ASSERT_EQ(std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str()), 0);
  std::ofstream(dir + "pv.toml") << kMeasured;
  {
    std::ofstream csv(dir + "rec.csv");
    csv << "trajectory,t,temperature,q,v,u,t_ms\n";
    for (int k = 0; k < 500; ++k) {
      csv << "0," << k / 100.0 << ",21.5," << 0.001 * k << "," << 0.01 * k << ",0.1," << 10 * k << "\n";
    }
  }
  std::string log;
  ASSERT_EQ(testing_util::run_shell(std::string(PHNN_BINARY) + " import " + dir + "rec.csv --system " + dir +
                                        "pv.toml --ignore-columns t_ms --out " + dir + "rec.h5",
                                    &log),
            0)
      << log;
  EXPECT_THAT(log, HasSubstr("states from [measurement]: p = m*l^2*v"));
  const PhSystemData d = read_ph_dataset_file(dir + "rec.h5");
  ASSERT_GT(d.train.size(), 0u);
  for (std::size_t i = 0; i < d.train.size(); ++i) {
    const double v = 0.01 * d.train.position[i];
    EXPECT_NEAR(d.train.x[i](1), 0.05 * v, 1e-16 + 1e-15 * v);
    EXPECT_NEAR(d.train.x[i](0), 0.001 * d.train.position[i], 1e-15);
  }
  // Without --ignore-columns the extra column is named, with the way out.
  EXPECT_EQ(testing_util::run_shell(std::string(PHNN_BINARY) + " import " + dir + "rec.csv --system " + dir +
                                        "pv.toml --out " + dir + "x.h5",
                                    &log),
            2);
  EXPECT_THAT(log, AllOf(HasSubstr("unknown column \"t_ms\""), HasSubstr("--ignore-columns")));
  std::system(("rm -rf " + dir).c_str());
}

}  // namespace
}  // namespace phnn
