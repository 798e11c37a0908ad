// tests/data/dataset_file_test.cpp
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "h5/h5file.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/store/results_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + std::to_string(::getpid()) + "_phnn_" + name;
}

// A built-in system's data set is its shipped file's, with the physics of
// the data written into the stored text (builtin_physics reads them back).
TEST(DatasetFileTest, BuiltInDataRoundTripWithTheirPhysicsInTheText) {
  DatasetOptions o;
  o.num_validation = 20;
  o.num_inference = 2;
  o.energy_sampling = EnergySampling::kDirect;
  OscillatorOptions physics = OscillatorOptions::defaults(SystemKind::kDuffing);
  physics.damping = 0.9;
  const PhSystemData data = make_ph_system_data(*builtin_system(physics, o), o, 25);
  const std::string path = temp_path("roundtrip.h5");
  write_ph_dataset_file(path, data);
  const PhSystemData back = read_ph_dataset_file(path);
  EXPECT_EQ(back.system_name, "duffing");
  EXPECT_EQ(back.system_text, data.system_text);
  EXPECT_EQ(builtin_physics(back.system_text, path).damping, 0.9);
  EXPECT_EQ(back.options.num_validation, 20);
  EXPECT_EQ(back.options.energy_sampling, EnergySampling::kDirect);
  ASSERT_EQ(back.train.size(), 25u);
  for (std::size_t i = 0; i < 25; ++i) {
    EXPECT_EQ(back.train.x[i], data.train.x[i]);
    EXPECT_EQ(back.train.x_next[i], data.train.x_next[i]);
    EXPECT_EQ(back.train.u[i], data.train.u[i]);
  }
  ASSERT_EQ(back.inference.states.size(), 2u);
  EXPECT_EQ(back.inference.states[1][500], data.inference.states[1][500]);
  std::remove(path.c_str());
}

// The version-1 data of a results file written on 2026-11-25 (the 2-state
// generator then, closed-form discrete gradient and Algorithms 1 and 3 of
// its own) read as the harmonic oscillator's shipped file, and generated
// again by today's one generator to <= 1e-12: an independent check of the
// built-in data.
TEST(DatasetFileTest, VersionOneDataAreTheShippedFilesAndTodaysGenerationsToRoundOff) {
  const std::string fixture = std::string(PHNN_SOURCE_DIR) + "/tests/fixtures/results-2026-11-25.h5";
  const PhSystemData old = ResultsFile::open_read_only(fixture).read_system_data("harmonic");
  EXPECT_EQ(old.system_text, builtin_system_text(OscillatorOptions::defaults(SystemKind::kHarmonic),
                                                 builtin_energies(old.options)));
  const PhSystemData now =
      make_ph_system_data(*builtin_system(OscillatorOptions::defaults(SystemKind::kHarmonic), old.options),
                          old.options, static_cast<int>(old.train.size()));
  ASSERT_EQ(now.train.size(), old.train.size());
  ASSERT_EQ(now.validation.size(), old.validation.size());
  ASSERT_EQ(now.inference.size(), old.inference.size());
  EXPECT_EQ(now.train.position, old.train.position);
  double worst = 0.0;
  auto diff = [&worst](const VecX& a, const VecX& b) {
    ASSERT_EQ(a.size(), b.size());
    worst = std::max(worst, (a - b).cwiseAbs().maxCoeff());
  };
  for (std::size_t i = 0; i < now.train.size(); ++i) {
    diff(now.train.x[i], old.train.x[i]);
    diff(now.train.x_next[i], old.train.x_next[i]);
    diff(now.train.u[i], old.train.u[i]);
  }
  for (std::size_t i = 0; i < now.validation.size(); ++i) diff(now.validation.x_next[i], old.validation.x_next[i]);
  for (std::size_t n = 0; n < now.inference.states[0].size(); ++n) {
    diff(now.inference.states[0][n], old.inference.states[0][n]);
  }
  EXPECT_LE(worst, 1e-12);
  RecordProperty("version1_vs_now", std::to_string(worst));
}

TEST(DatasetFileTest, RefusesMissingAndForeignFiles) {
  EXPECT_THAT([] { read_ph_dataset_file("/nonexistent/dir/x.h5"); },
              ::testing::ThrowsMessage<h5::Error>(HasSubstr("no such file")));
  const std::string text = temp_path("not_hdf5.h5");
  std::ofstream(text) << "hello";
  EXPECT_THAT([&] { read_ph_dataset_file(text); },
              ::testing::ThrowsMessage<h5::Error>(HasSubstr("not an HDF5 file")));
  const std::string foreign = temp_path("foreign.h5");
  {
    h5::File f = h5::File::create(foreign);
    f.write("/something", {2}, std::vector<double>{1, 2});
  }
  EXPECT_THAT([&] { read_ph_dataset_file(foreign); },
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
  const PhSystemData data = read_ph_dataset_file(path);
  EXPECT_EQ(data.train.size(), 25u);
  EXPECT_EQ(data.validation.size(), 2500u);
  EXPECT_EQ(data.inference.size(), 100u);
  std::remove(path.c_str());
}

// `--system duffing` is the shipped file: the two data sets are the same
// bytes (every dataset, and the stored system text).
TEST(DataCommandTest, BuiltInNameAndShippedFileWriteTheSameDataSet) {
  std::string out;
  const std::string a = temp_path("by_name.h5"), b = temp_path("by_file.h5");
  ASSERT_EQ(run("data --system duffing --n-train 10 --out " + a, &out), 0) << out;
  ASSERT_EQ(run("data --system " + std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/duffing.toml "
                "--n-train 10 --out " + b, &out), 0) << out;
  const h5::File fa = h5::File::open(a, h5::Access::kReadOnly);
  const h5::File fb = h5::File::open(b, h5::Access::kReadOnly);
  for (const char* name : {"/train/x", "/train/x_next", "/train/u", "/validation/x", "/validation/x_next",
                           "/validation/u", "/inference/states", "/inference/u"}) {
    const std::vector<double> va = fa.read_doubles(name), vb = fb.read_doubles(name);
    ASSERT_EQ(va.size(), vb.size()) << name;
    EXPECT_EQ(std::memcmp(va.data(), vb.data(), va.size() * sizeof(double)), 0) << name;
  }
  EXPECT_EQ(fa.string_attribute("/", "system_file"), fb.string_attribute("/", "system_file"));
  std::remove(a.c_str());
  std::remove(b.c_str());
}

}  // namespace
}  // namespace phnn
