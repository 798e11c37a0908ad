// tests/sweep/sweep_system_files_test.cpp — system files in sweep files:
// read relative to the sweep file, part of every run's identity, their
// errors at the right FILE:LINE; and end to end under mpiexec: a sweep of a
// system file finishes, resumes, reduces, evaluates, and is independent of
// the number of ranks; a changed system file is refused on every rank.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/systems/system_file.h"
#include "test_util.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

std::string temp_dir(const std::string& name) {
  const std::string dir =
      ::testing::TempDir() + "phnn_sysfiles_" + name + "_" + std::to_string(::getpid());
  std::system(("rm -rf " + dir + " && mkdir -p " + dir + "/systems").c_str());
  return dir;
}

std::string read_text(const std::string& path) { return read_system_file_text(path); }

// The shipped pendulum renamed "osc", in dir/systems/osc.toml.
std::string write_osc(const std::string& dir, const std::string& replace_from = "",
                      const std::string& replace_to = "") {
  std::string text = read_text(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/pendulum.toml");
  text.replace(text.find("name = \"pendulum\""), 17, "name = \"osc\"");
  if (!replace_from.empty()) text.replace(text.find(replace_from), replace_from.size(), replace_to);
  const std::string path = dir + "/systems/osc.toml";
  std::ofstream(path) << text;
  return path;
}

const char* kSweep = R"(name = "sysfile"
[data]
num_validation = 40
num_inference = 3
[training]
steps = 30
eval_every = 10
[grid]
systems = ["systems/osc.toml", "harmonic"]
models = ["phnn-s-dg", "node-rk2"]
n_train = [25]
seeds = [0, 1]
)";

std::string write_sweep(const std::string& dir, const std::string& text) {
  const std::string path = dir + "/sweep.toml";
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::string& path) {
  try {
    parse_sweep_file(path);
  } catch (const SweepFileError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string error_of_text(const std::string& text) {
  try {
    parse_sweep_text(text, "x.toml");
  } catch (const SweepFileError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string mpiexec(int ranks) { return testing_util::mpiexec_phnn(ranks); }

int shell(const std::string& command, std::string* output) {
  return testing_util::run_shell(command, output);
}

TEST(SweepSystemFilesTest, ExampleSweepReadsItsSystemFileRelativeToItself) {
  const SweepSpec spec =
      parse_sweep_file(std::string(PHNN_SOURCE_DIR) + "/sweeps/examples/coupled-duffing.toml");
  ASSERT_EQ(spec.system_files.size(), 1u);
  const SweepSystemFile& f = spec.system_files[0];
  EXPECT_EQ(f.entry, "../systems/coupled-duffing.toml");
  EXPECT_EQ(f.name, "coupled-duffing");
  EXPECT_EQ(f.n_x, 4);
  EXPECT_EQ(f.n_w, 2);
  EXPECT_EQ(f.n_u, 1);
  EXPECT_EQ(f.text, read_text(std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/coupled-duffing.toml"));
  EXPECT_THAT(spec.studies[0].systems, ElementsAre("coupled-duffing"));
  const Grid grid = expand_grid(spec);
  ASSERT_EQ(grid.runs.size(), 100u);
  for (const RunConfig& run : grid.runs) {
    EXPECT_EQ(run.system_name(), "coupled-duffing");
    EXPECT_EQ(run.n_x, 4);
    EXPECT_THAT(run.canonical(), HasSubstr(";system_file=" + f.text_hash + ";"));
    EXPECT_THAT(run.canonical(), Not(HasSubstr("mass=")));  // the file holds the parameters
  }
}

// Any byte of a system file is part of the sweep's hash and of its runs'
// ids; a sweep without system files hashes its own text as before.
TEST(SweepSystemFilesTest, ChangedSystemFileChangesTheHashAndTheRuns) {
  const std::string dir = temp_dir("hash");
  write_osc(dir);
  const std::string sweep = write_sweep(dir, kSweep);
  const SweepSpec before = parse_sweep_file(sweep);
  write_osc(dir, "m = 0.2 ", "m = 0.25");
  const SweepSpec after = parse_sweep_file(sweep);
  EXPECT_EQ(before.text, after.text);
  EXPECT_NE(before.text_hash, after.text_hash);
  const Grid a = expand_grid(before), b = expand_grid(after);
  ASSERT_EQ(a.runs.size(), b.runs.size());
  for (std::size_t i = 0; i < a.runs.size(); ++i) {
    EXPECT_EQ(a.runs[i].id() != b.runs[i].id(), a.runs[i].has_system_file()) << i;
  }
  const SweepSpec plain = parse_sweep_text("name = \"x\"\n", "x.toml");
  EXPECT_EQ(plain.text_hash, hex64(fnv1a64(plain.text)));
}

TEST(SweepSystemFilesTest, ErrorsNameTheSweepLineOrTheSystemFilesLine) {
  const std::string dir = temp_dir("errors");
  const std::string osc = write_osc(dir);
  auto sweep_with = [&](const std::string& systems) {
    std::string text = kSweep;
    text.replace(text.find("systems = [\"systems/osc.toml\", \"harmonic\"]"), 42,
                 "systems = " + systems);
    return write_sweep(dir, text);
  };
  std::string sweep = sweep_with("[\"systems/none.toml\"]");
  EXPECT_THAT(error_of(sweep), AllOf(HasSubstr(sweep + ":9: systems value \"systems/none.toml\""),
                                     HasSubstr(dir + "/systems/none.toml: cannot open")));
  sweep = sweep_with("[\"duffng\"]");
  EXPECT_THAT(error_of(sweep), AllOf(HasSubstr(sweep + ":9: unknown systems value"),
                                     HasSubstr("did you mean \"duffing\""),
                                     HasSubstr("or a system file")));
  std::ofstream(dir + "/systems/osc2.toml") << read_text(osc);
  sweep = sweep_with("[\"systems/osc.toml\",\n  \"systems/osc2.toml\"]");
  EXPECT_THAT(error_of(sweep), HasSubstr(sweep + ":10: system files \"systems/osc.toml\" and "
                                                 "\"systems/osc2.toml\" are both named \"osc\""));
  std::string as_harmonic = read_text(osc);
  as_harmonic.replace(as_harmonic.find("name = \"osc\""), 12, "name = \"harmonic\"");
  std::ofstream(dir + "/systems/h.toml") << as_harmonic;
  sweep = sweep_with("[\"systems/h.toml\", \"harmonic\"]");  // one axis: a duplicate name
  EXPECT_THAT(error_of(sweep), HasSubstr(sweep + ":9: systems lists two systems named \"harmonic\""));
  sweep = write_sweep(dir, "name = \"x\"\n[study.a]\nsystems = [\"systems/h.toml\"]\n[study.b]\n"
                           "systems = [\"harmonic\"]\n");
  EXPECT_THAT(error_of(sweep), HasSubstr(sweep + ":5: the built-in system \"harmonic\" and the "
                                                 "system file \"systems/h.toml\" (line 3)"));
  // A bad system file: its own path and line.
  std::string bad = read_text(osc);
  bad.replace(bad.find("H = \""), 5, "H = \"mass_typo + ");
  std::ofstream(dir + "/systems/bad.toml") << bad;
  sweep = sweep_with("[\"systems/bad.toml\"]");
  const std::string e = error_of(sweep);
  EXPECT_THAT(e, AllOf(HasSubstr(dir + "/systems/bad.toml:"), HasSubstr("unknown symbol \"mass_typo\""),
                       HasSubstr("declare it under [parameters]")));
  // Text without a directory to read system files from.
  EXPECT_THAT(error_of_text(kSweep), HasSubstr("x.toml:9: system file \"systems/osc.toml\" cannot be read here"));
}

// End to end: 2 ranks and 1 rank give the same bits; a rerun resumes with
// nothing to do; reduce and eval read the system file from the results file
// alone (the sweep's directory is gone); a changed system file is refused
// on every rank with the file unchanged; a bad one exits 2 with its line.
TEST(SweepSystemFilesTest, SweepOfASystemFileFinishesResumesReducesAndEvaluates) {
  const std::string dir = temp_dir("e2e");
  write_osc(dir);
  const std::string sweep = write_sweep(dir, kSweep);
  const std::string out = ::testing::TempDir() + "phnn_sysfiles_e2e_" + std::to_string(::getpid()) + ".h5";
  const std::string one = out + ".one.h5";
  std::system(("rm -rf " + out + "* ").c_str());
  std::string log;
  ASSERT_EQ(shell(mpiexec(2) + " sweep " + sweep + " --quiet --out " + out, &log), 0) << log;
  ASSERT_EQ(shell(mpiexec(1) + " sweep " + sweep + " --quiet --out " + one, &log), 0) << log;
  ASSERT_EQ(shell(mpiexec(2) + " sweep " + sweep + " --quiet --out " + out, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("8 finished before, 0 to run"));
  {
    const ResultsFile a = ResultsFile::open_read_only(out), b = ResultsFile::open_read_only(one);
    ASSERT_EQ(a.read_run_ids(), b.read_run_ids());
    EXPECT_EQ(a.read_string_column("system"), (std::vector<std::string>{"osc", "osc", "osc", "osc", "harmonic",
                                                          "harmonic", "harmonic", "harmonic"}));
    for (int row = 0; row < a.num_runs(); ++row) {
      const RunResult x = a.read_run(row), y = b.read_run(row);
      EXPECT_EQ(x.status, RunStatus::kDone) << row;
      EXPECT_EQ(x.mse, y.mse) << row;  // bitwise
      EXPECT_EQ(x.trajectory_errors, y.trajectory_errors) << row;
      EXPECT_EQ(x.weights, y.weights) << row;
    }
    const PhSystemData data = a.read_system_data("osc");
    EXPECT_EQ(data.state_names, (std::vector<std::string>{"q", "p"}));
    EXPECT_THAT(data.system_text, HasSubstr("name = \"osc\""));
  }
  std::system(("rm -rf " + dir).c_str());  // reduce and eval need the results file only
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " reduce " + out, &log), 0) << log;
  EXPECT_THAT(log, AllOf(HasSubstr("— osc"), HasSubstr("— harmonic"), HasSubstr("PHNN-S-DG")));
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " reduce " + out + " --format csv --per-run", &log), 0);
  const std::size_t at = log.find(",osc,phnn-s,dg,");
  ASSERT_NE(at, std::string::npos) << log;
  const std::string id = log.substr(log.rfind('\n', at) + 1, 16);
  const std::string csv = out + ".csv";
  ASSERT_EQ(shell(std::string(PHNN_BINARY) + " eval " + out + " --run " + id + " --out " + csv, &log),
            0)
      << log;
  EXPECT_THAT(log, HasSubstr("bitwise equal"));
  {
    // The figure trajectories of a system file: inference trajectories 0
    // and 1, states by the file's names, from the true x0.
    std::ifstream in(csv);
    std::string line;
    ASSERT_TRUE(std::getline(in, line));
    EXPECT_EQ(line, "trajectory,t,q,p,q_ref,p_ref,H_true,H_true_ref,H_model,H_model_ref");
    ASSERT_TRUE(std::getline(in, line));
    double v[10];
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1],
                          &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9]),
              10)
        << line;
    EXPECT_EQ(v[0], 0.0);
    EXPECT_EQ(v[1], 0.0);
    EXPECT_EQ(v[2], v[4]);  // x0 is the true initial state
    EXPECT_EQ(v[3], v[5]);
    EXPECT_EQ(v[6], v[7]);
    int rows = 1;
    while (std::getline(in, line)) ++rows;
    EXPECT_EQ(rows, 2 * 501);
  }
  // The system file changed: refused, file unchanged.
  const std::string dir2 = temp_dir("e2e_changed");
  write_osc(dir2, "m = 0.2 ", "m = 0.25");
  const std::string hash = ResultsFile::open_read_only(out).sweep_hash();
  EXPECT_EQ(shell(mpiexec(2) + " sweep " + write_sweep(dir2, kSweep) + " --out " + out, &log), 2)
      << log;
  EXPECT_THAT(log, AllOf(HasSubstr("system_file: "), HasSubstr("the text of a system file")));
  EXPECT_EQ(ResultsFile::open_read_only(out).sweep_hash(), hash);
  // A bad system file: exit 2 on every rank, its FILE:LINE, nothing written.
  write_osc(dir2, "S = [[", "S = [[1, ");
  const std::string never = out + ".never.h5";
  EXPECT_EQ(shell(mpiexec(2) + " sweep " + dir2 + "/sweep.toml --out " + never, &log), 2) << log;
  EXPECT_THAT(log, HasSubstr(dir2 + "/systems/osc.toml:"));
  struct stat st;
  EXPECT_NE(::stat(never.c_str(), &st), 0);
  std::system(("rm -rf " + dir2 + " " + out + "*").c_str());
}

}  // namespace
}  // namespace phnn
