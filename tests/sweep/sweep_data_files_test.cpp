// tests/sweep/sweep_data_files_test.cpp — `data = [...]` in sweep files:
// data-set files as systems of their own, their contents part of every
// run's identity (a rewrite with the same contents is the same sweep), their
// errors at the right line; and end to end: a sweep of an imported data set
// trains, reduces from the results file alone, and a changed data file is
// refused on resume.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/data/ph_dataset.h"
#include "phnn/store/dataset_file.h"
#include "phnn/store/ph_dataset_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/systems/system_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::string temp_dir(const std::string& name) {
  const std::string dir =
      ::testing::TempDir() + "phnn_datafiles_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + dir + " && mkdir -p " + dir + "/d").c_str());
  return dir;
}

// A small pendulum data set (8 training pairs and inference of 0.5 s unless
// told) with this data seed.
void write_data(const std::string& path, std::uint64_t seed, int train_pairs = 8,
                double beta = 0.5) {
  const auto system = load_system_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/pendulum.toml");
  DatasetOptions o;
  o.data_seed = seed;
  o.num_train_max = train_pairs;
  o.num_validation = 10;
  o.num_inference = 2;
  o.beta = beta;
  write_ph_dataset_file(path, make_ph_system_data(*system, o, train_pairs));
}

std::string sweep(const std::string& data_line, const std::string& n_train = "[4]") {
  return "name = \"datafiles\"\n"       // 1
         "[training]\n"                 // 2
         "steps = 30\n"                 // 3
         "eval_every = 10\n"            // 4
         "[grid]\n"                     // 5
         + data_line + "\n"             // 6
         "models = [\"phnn-s-dg\"]\n"   // 7
         "n_train = " + n_train + "\n"  // 8
         "seeds = \"0-1\"\n";           // 9
}

SweepSpec parse_in(const std::string& dir, const std::string& text) {
  std::ofstream(dir + "/s.toml") << text;
  return parse_sweep_file(dir + "/s.toml");
}

std::string error_in(const std::string& dir, const std::string& text) {
  try {
    parse_in(dir, text);
  } catch (const SweepFileError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a SweepFileError for:\n" << text;
  return "";
}

TEST(SweepDataFilesTest, ADataFileIsASystemNamedByItsStemWhoseContentsAreItsIdentity) {
  const std::string dir = temp_dir("identity");
  write_data(dir + "/d/meas.h5", 0);
  const SweepSpec spec = parse_in(dir, sweep("data = \"d/meas.h5\""));
  ASSERT_EQ(spec.system_files.size(), 1u);
  const SweepSystemFile& f = spec.system_files[0];
  EXPECT_TRUE(f.is_data());
  EXPECT_EQ(f.name, "meas");
  EXPECT_EQ(f.data_train_pairs, 8);
  EXPECT_EQ(spec.studies[0].systems, std::vector<std::string>{"meas"});  // no built-ins
  const Grid grid = expand_grid(spec);
  ASSERT_EQ(grid.runs.size(), 2u);
  EXPECT_EQ(grid.runs[0].system_name(), "meas");

  // Written again with the same contents: the same runs and sweep hash.
  write_data(dir + "/d/meas.h5", 0);
  const SweepSpec same = parse_in(dir, sweep("data = \"d/meas.h5\""));
  EXPECT_EQ(expand_grid(same).runs[0].id(), grid.runs[0].id());
  EXPECT_EQ(same.text_hash, spec.text_hash);
  // Other contents (another data seed): other runs.
  write_data(dir + "/d/meas.h5", 1);
  const SweepSpec other = parse_in(dir, sweep("data = \"d/meas.h5\""));
  EXPECT_NE(expand_grid(other).runs[0].id(), grid.runs[0].id());
  EXPECT_NE(other.text_hash, spec.text_hash);
  // With `systems`, both.
  const SweepSpec both = parse_in(dir, sweep("systems = [\"harmonic\"]\ndata = [\"d/meas.h5\"]", "[4]"));
  EXPECT_EQ(both.studies[0].systems, (std::vector<std::string>{"harmonic", "meas"}));
  std::system(("rm -rf " + dir).c_str());
}

// n_train of a data-set file is bounded by its training pairs, not by [data]
// num_train_max (400 by default), which bounds the generated systems only.
TEST(SweepDataFilesTest, NTrainOfADataFileIsBoundedByItsPairsNotByNumTrainMax) {
  const std::string dir = temp_dir("ntrain");
  write_data(dir + "/d/long.h5", 0, 450);
  const SweepSpec spec = parse_in(dir, sweep("data = \"d/long.h5\"", "[450]"));
  EXPECT_EQ(spec.studies[0].n_train, std::vector<int>{450});
  EXPECT_THAT(error_in(dir, sweep("systems = [\"harmonic\"]\ndata = [\"d/long.h5\"]", "[450]")),
              AllOf(HasSubstr("s.toml:9:"), HasSubstr("num_train_max = 400")));
  std::system(("rm -rf " + dir).c_str());
}

TEST(SweepDataFilesTest, BadDataValuesFailAtTheirLineWithTheFix) {
  const std::string dir = temp_dir("errors");
  write_data(dir + "/d/meas.h5", 0);
  EXPECT_THAT(error_in(dir, sweep("data = \"d/meas.csv\"")),
              AllOf(HasSubstr("s.toml:6:"), HasSubstr("paths ending in .h5"), HasSubstr("phnn import")));
  EXPECT_THAT(error_in(dir, sweep("data = \"d/none.h5\"")),
              AllOf(HasSubstr("s.toml:6:"), HasSubstr("d/none.h5")));
  EXPECT_THAT(error_in(dir, sweep("data = \"d/meas.h5\"", "[4, 9]")),
              AllOf(HasSubstr("s.toml:8:"), HasSubstr("more than the 8 training pairs"),
                    HasSubstr("import more training trajectories")));
  EXPECT_THAT(error_in(dir, sweep("data = [\"d/meas.h5\", \"d/meas.h5\"]")),
              AllOf(HasSubstr("s.toml:6:"), HasSubstr("twice")));
  // A stem that is a built-in system's name.
  write_data(dir + "/d/duffing.h5", 0);
  EXPECT_THAT(error_in(dir, sweep("data = \"d/duffing.h5\"")),
              AllOf(HasSubstr("s.toml:6:"), HasSubstr("built-in system's name"), HasSubstr("rename")));
  // A structure-only system file (no H) as a system to generate: refused
  // at its line with the import route.
  EXPECT_THAT(error_in(dir, sweep("systems = [\"" + std::string(PHNN_SOURCE_DIR) +
                                  "/sweeps/systems/pendulum-structure.toml\"]")),
              AllOf(HasSubstr("s.toml:6:"), HasSubstr("defines no energy H"),
                    HasSubstr("phnn import"), HasSubstr("data = [...]")));
  std::system(("rm -rf " + dir).c_str());
}

int phnn(const std::string& args, std::string* output) {
  return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, output);
}

TEST(SweepDataFilesTest, ASweepOfADataFileTrainsReducesAloneAndRefusesChangedData) {
  const std::string dir = temp_dir("e2e");
  // Inference trajectories of 6 s, longer than the sweep's own [data] (5 s):
  // the results file's figure and trace columns take the data file's length.
  write_data(dir + "/d/meas.h5", 0, 8, 6.0);
  std::ofstream(dir + "/s.toml") << sweep("data = \"d/meas.h5\"");
  std::string log;
  ASSERT_EQ(phnn("sweep " + dir + "/s.toml --out " + dir + "/r.h5", &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("2 done"));
  std::system(("mv " + dir + "/d " + dir + "/gone").c_str());  // reduce needs only the results
  ASSERT_EQ(phnn("reduce " + dir + "/r.h5", &log), 0) << log;
  EXPECT_THAT(log, AllOf(HasSubstr("Study grid — meas"), HasSubstr("PHNN-S-DG")));
  std::system(("mkdir -p " + dir + "/d").c_str());
  write_data(dir + "/d/meas.h5", 5);
  EXPECT_EQ(phnn("sweep " + dir + "/s.toml --out " + dir + "/r.h5", &log), 2) << log;
  EXPECT_THAT(log, AllOf(HasSubstr("system_file:"), HasSubstr("data-set file")));
  std::system(("rm -rf " + dir).c_str());
}

}  // namespace
}  // namespace phnn
