// tests/data/dataset_file_test.cpp
#include "phnn/store/dataset_file.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_util.h"

#include "h5/h5file.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "phnn_" + name;
}

TEST(DatasetFileTest, RoundTripsEveryValueAndAttribute) {
  DatasetOptions o;
  o.num_validation = 20;
  o.num_inference = 2;
  const SystemData data =
      make_system_data(OscillatorOptions::defaults(SystemKind::kDuffing), o, 25);
  const std::string path = temp_path("roundtrip.h5");
  write_dataset_file(path, data);
  const SystemData back = read_dataset_file(path);
  EXPECT_EQ(back.system.kind, SystemKind::kDuffing);
  EXPECT_EQ(back.system.damping, data.system.damping);
  EXPECT_EQ(back.options.num_validation, 20);
  ASSERT_EQ(back.train.size(), 25u);
  for (std::size_t i = 0; i < 25; ++i) {
    EXPECT_EQ(back.train.x[i], data.train.x[i]);
    EXPECT_EQ(back.train.x_next[i], data.train.x_next[i]);
    EXPECT_EQ(back.train.u[i], data.train.u[i]);
  }
  ASSERT_EQ(back.inference.states.size(), 2u);
  EXPECT_EQ(back.inference.states[1][500], data.inference.states[1][500]);
  const h5::File f = h5::File::open(path, h5::Access::kReadOnly);
  EXPECT_EQ(f.string_attribute("/", "state_units"), "q [m], p [kg m/s]");
  EXPECT_EQ(f.string_attribute("/", "energy_sampling"), "algorithm1");
  std::remove(path.c_str());
}

// The data set records how its initial energies were drawn, and reads it
// back (a file without the attribute predates it: Algorithm 1).
TEST(DatasetFileTest, RoundTripsEnergySampling) {
  DatasetOptions o;
  o.num_validation = 2;
  o.num_inference = 1;
  o.energy_sampling = EnergySampling::kDirect;
  const SystemData data = make_system_data(OscillatorOptions::defaults(SystemKind::kHarmonic), o, 3);
  const std::string path = temp_path("direct.h5");
  write_dataset_file(path, data);
  const SystemData back = read_dataset_file(path);
  EXPECT_EQ(back.options.energy_sampling, EnergySampling::kDirect);
  EXPECT_EQ(back.train.x[2], data.train.x[2]);
  std::remove(path.c_str());
}

TEST(DatasetFileTest, RefusesMissingAndForeignFiles) {
  EXPECT_THAT([] { read_dataset_file("/nonexistent/dir/x.h5"); },
              ::testing::ThrowsMessage<h5::Error>(HasSubstr("no such file")));
  const std::string text = temp_path("not_hdf5.h5");
  std::ofstream(text) << "hello";
  EXPECT_THAT([&] { read_dataset_file(text); },
              ::testing::ThrowsMessage<h5::Error>(HasSubstr("not an HDF5 file")));
  const std::string foreign = temp_path("foreign.h5");
  {
    h5::File f = h5::File::create(foreign);
    f.write("/something", {2}, std::vector<double>{1, 2});
  }
  EXPECT_THAT([&] { read_dataset_file(foreign); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("not a phnn data set")));
  std::remove(text.c_str());
  std::remove(foreign.c_str());
}

// The CLI: bad options exit with status 2 and name the option.
int run(const std::string& args, std::string* output) {
  return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, output);
}

TEST(DataCommandTest, RejectsUnknownSystemAndBadNumbers) {
  std::string out;
  EXPECT_EQ(run("data --system vanderpol --out /tmp/x.h5", &out), 2);
  EXPECT_THAT(out, HasSubstr("unknown system \"vanderpol\""));
  EXPECT_EQ(run("data --system duffing --out /tmp/x.h5 --n-train -3", &out), 2);
  EXPECT_THAT(out, HasSubstr("--n-train = -3"));
  EXPECT_EQ(run("data --system duffing --out /tmp/x.h5 --mass -1", &out), 2);
  EXPECT_THAT(out, HasSubstr("mass = -1"));
  EXPECT_EQ(run("data --system duffing --bogus 1", &out), 2);
  EXPECT_THAT(out, HasSubstr("unknown option --bogus"));
}

TEST(DataCommandTest, WritesAFileReadableBack) {
  std::string out;
  const std::string path = temp_path("cli_data.h5");
  ASSERT_EQ(run("data --system self-sustained --n-train 25 --out " + path, &out), 0) << out;
  const SystemData data = read_dataset_file(path);
  EXPECT_EQ(data.train.size(), 25u);
  EXPECT_EQ(data.validation.size(), 2500u);
  EXPECT_EQ(data.inference.size(), 100u);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace phnn
