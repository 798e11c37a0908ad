// tests/sweep/data_settings_test.cpp — the tables of [data] and
// [physics.<system>] settings: run ids they write equal those written
// before the tables existed (ids from the binary of 26b39e8, whose keys
// were hand-written), sweeps/FORMAT.md shows the tables they generate, and
// the sweep file reads every key into its field.
#include "phnn/config/data_settings.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace {

std::string pendulum() { return std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/pendulum.toml"; }

// `text` parsed from a file of its own (system files are read relative to it).
SweepSpec parse(const std::string& text) {
  const std::string path =
      ::testing::TempDir() + "phnn_data_settings_" + std::to_string(::getpid()) + ".toml";
  std::ofstream(path) << text;
  SweepSpec spec = parse_sweep_file(path);
  std::remove(path.c_str());
  return spec;
}

// system name -> run id of every run of `text` (one per system).
std::map<std::string, std::string> ids(const std::string& text) {
  std::map<std::string, std::string> out;
  for (const RunConfig& run : expand_grid(parse(text)).runs) {
    out[run.system_name()] = run.id();
  }
  return out;
}

// Every [data] key and every parameter away from its default, on the
// three built-in systems and a system file.
std::string every_key() {
  return R"(name = "data-keys-a"
[data]
seed = 7
generation_step = 0.005
period = 0.5
alpha = 0.25
beta = 4.0
sample_rate = 50.0
energy_min = 0.2
energy_max = 0.9
equilibrium_energy_min = 0.15
equilibrium_energy_max = 0.8
num_trajectories = 5000
num_train_max = 300
num_validation = 200
num_inference = 20
newton_tolerance = 1e-13
[physics.harmonic]
mass = 0.2
stiffness = 5.0
damping = 0.3
[physics.duffing]
cubic_stiffness = 500.0
[physics.self-sustained]
z_coefficients = [-0.2, 0.05, 1.5]
[training]
steps = 10
[grid]
systems = ["harmonic", "duffing", "self-sustained", ")" +
         pendulum() + R"("]
models = ["phnn-jr-rk2"]
sizes = ["small"]
n_train = [8]
regularizers = ["none"]
seeds = [0]
)";
}

TEST(DataSettingsTest, RunIdsAreThoseWrittenBeforeTheTables) {
  EXPECT_EQ(ids(every_key()),
            (std::map<std::string, std::string>{{"duffing", "7b7e96a9eb57bb2a"},
                                                {"harmonic", "5c48ed13d4d8d36a"},
                                                {"pendulum", "5bdd7248cb7b83e8"},
                                                {"self-sustained", "71edf811d81026f6"}}));
  const std::string grid =
      "[training]\nsteps = 10\n[grid]\nmodels = [\"node-rk2\"]\n"
      "sizes = [\"small\"]\nn_train = [8]\nregularizers = [\"none\"]\n"
      "seeds = [0]\n";
  // energy_sampling away from its default: in the key of the systems that
  // use Algorithm 1 and of system files.
  EXPECT_EQ(ids("name = \"data-keys-b\"\n[data]\nenergy_sampling = \"direct\"\n" + grid +
                "systems = [\"harmonic\", \"self-sustained\", \"" + pendulum() + "\"]\n"),
            (std::map<std::string, std::string>{{"harmonic", "04e3bf99e7ccb08b"},
                                                {"pendulum", "8c4dd73a8676d45c"},
                                                {"self-sustained", "3f9b6b1b87766d42"}}));
  // Defaults.
  EXPECT_EQ(
      ids("name = \"data-keys-c\"\n" + grid +
          "systems = [\"harmonic\", \"duffing\", \"self-sustained\", \"" + pendulum() + "\"]\n"),
      (std::map<std::string, std::string>{{"duffing", "dca2fe73c92b8d2d"},
                                          {"harmonic", "d40c1e4f5f734d46"},
                                          {"pendulum", "14531958472a5bab"},
                                          {"self-sustained", "1c4fbf05b024660d"}}));
}

// The text of sweeps/FORMAT.md between `begin` and `end` markers.
std::string format_md_block(const std::string& what) {
  std::ifstream in(std::string(PHNN_SOURCE_DIR) + "/sweeps/FORMAT.md");
  std::stringstream all;
  all << in.rdbuf();
  const std::string text = all.str();
  const std::string begin = "<!-- " + what + ": generated, do not edit by hand -->\n";
  const std::string end = "<!-- end of " + what + " -->";
  const auto a = text.find(begin), b = text.find(end);
  if (a == std::string::npos || b == std::string::npos) return "(no " + what + " block)";
  return text.substr(a + begin.size(), b - a - begin.size());
}

TEST(DataSettingsTest, FormatMdShowsTheGeneratedTables) {
  EXPECT_EQ(format_md_block("data settings"), data_settings_markdown())
      << "sweeps/FORMAT.md's [data] table is stale; replace it by:\n"
      << data_settings_markdown();
  EXPECT_EQ(format_md_block("physics settings"), physics_settings_markdown())
      << "sweeps/FORMAT.md's [physics] table is stale; replace it by:\n"
      << physics_settings_markdown();
}

TEST(DataSettingsTest, EveryKeyIsReadFromASweepFileIntoItsField) {
  const SweepSpec spec = parse(every_key());
  const DatasetOptions defaults;
  for (const DataSetting& s : data_settings()) {
    if (s.kind == DataSetting::Kind::kChoice) continue;  // below
    EXPECT_NE(s.text(spec.data), s.text(defaults)) << s.key;
  }
  EXPECT_EQ(spec.data.generation_step, 0.005);
  EXPECT_EQ(spec.data.newton.newton_tolerance, 1e-13);
  EXPECT_EQ(spec.data.data_seed, 7u);
  const SweepSpec direct = parse_sweep_text(
      "name = \"d\"\n[data]\nenergy_sampling = \"direct\"\n[grid]\nsystems = [\"harmonic\"]\n"
      "models = [\"node-rk2\"]\nn_train = [8]\nseeds = [0]\n",
      "x.toml");
  EXPECT_EQ(direct.data.energy_sampling, EnergySampling::kDirect);
  // Each parameter its system uses, read into its field.
  for (const PhysicsSetting& s : physics_settings()) {
    for (SystemKind kind : s.systems) {
      const std::vector<double> read = s.get(spec.physics.at(kind));
      if (std::string(s.key) == "z_coefficients") {
        EXPECT_EQ(read, (std::vector<double>{-0.2, 0.05, 1.5}));
      } else if (kind == SystemKind::kHarmonic) {
        EXPECT_NE(read, s.get(OscillatorOptions::defaults(kind))) << s.key;
      }
    }
  }
  EXPECT_EQ(spec.physics.at(SystemKind::kDuffing).cubic_stiffness, 500.0);
}

// A parameter's default (the table shows one) is the same on every system
// that uses it; a parameter a system does not use is refused in its table.
TEST(DataSettingsTest, PhysicsDefaultsAgreeAndUnusedKeysAreRefused) {
  for (const PhysicsSetting& s : physics_settings()) {
    for (SystemKind kind : s.systems) {
      EXPECT_EQ(s.get(OscillatorOptions::defaults(kind)),
                s.get(OscillatorOptions::defaults(s.systems.front())))
          << s.key << " on " << to_string(kind);
    }
  }
  EXPECT_THAT(
      [] {
        parse_sweep_text(
            "name = \"d\"\n[physics.self-sustained]\ndamping = 0.2\n[grid]\n"
            "systems = [\"self-sustained\"]\nmodels = [\"node-rk2\"]\nn_train = [8]\n"
            "seeds = [0]\n",
            "x.toml");
      },
      ::testing::Throws<std::exception>());
}

}  // namespace
}  // namespace phnn
