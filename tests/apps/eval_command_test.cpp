// tests/apps/eval_command_test.cpp — `phnn eval`: runs reloaded from their
// stored weights reproduce their stored MSE bitwise, and the energy CSV.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_util.h"

#include "phnn/store/results_file.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;

int run(const std::string& args, std::string* output) {
  return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, output);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string item; std::getline(s, item, ',');) out.push_back(item);
  return out;
}

class EvalCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = ::testing::TempDir() + "phnn_eval_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".h5";
    std::remove(out_.c_str());
  }
  void TearDown() override { std::remove(out_.c_str()); }

  // Trains `model` on `system` (2 seeds, 40 steps) into out_; the run ids.
  std::vector<std::string> train(const std::string& system, const std::string& model) {
    std::string log;
    EXPECT_EQ(run("train --system " + system + " --model " + model +
                      " --n-train 25 --seeds 0-1 --steps 40 --eval-every 20 --quiet --out " + out_,
                  &log),
              0)
        << log;
    return ResultsFile::open_read_only(out_).read_run_ids();
  }

  std::string out_;
};

// The stored weights are the inference weights: evaluating them again gives
// the stored MSE bitwise, for explicit, DG (Newton) and fourth-order steps.
TEST_F(EvalCommandTest, ReloadedRunsReproduceTheirStoredMseBitwise) {
  for (const auto& [system, model] :
       std::vector<std::pair<std::string, std::string>>{{"duffing", "phnn-jr-dg"},
                                                        {"self-sustained", "phnn-s-rk4"},
                                                        {"harmonic", "node-rk2"}}) {
    SCOPED_TRACE(system + " " + model);
    std::remove(out_.c_str());
    const std::vector<std::string> ids = train(system, model);
    ASSERT_EQ(ids.size(), 2u);
    const ResultsFile file = ResultsFile::open_read_only(out_);
    EXPECT_TRUE(file.layout().weights);
    for (int row = 0; row < 2; ++row) {
      EXPECT_EQ(static_cast<long>(file.read_run(row).weights.size()),
                file.read_run(row).parameter_count);
      std::string log;
      EXPECT_EQ(run("eval " + out_ + " --run " + ids[static_cast<std::size_t>(row)], &log), 0)
          << log;
      EXPECT_THAT(log, HasSubstr("bitwise equal"));
    }
  }
}

// A file of another kernel set (the 2026-11-25 fixture, computed before our
// own kernels) evaluates to round-off, and says which sets; a stored MSE off
// by 1e-3 is named a difference beyond round-off, with exit status 1.
TEST_F(EvalCommandTest, AnotherKernelSetsRunsAgreeToRoundOffAndDamageDoesNot) {
  const std::string fixture = std::string(PHNN_SOURCE_DIR) + "/tests/fixtures/results-2026-11-25.h5";
  const std::vector<std::string> ids = ResultsFile::open_read_only(fixture).read_run_ids();
  ASSERT_EQ(ids.size(), 4u);
  int rounded = 0;
  for (const std::string& id : ids) {
    std::string log;
    EXPECT_EQ(run("eval " + fixture + " --run " + id, &log), 0) << log;
    if (log.find("equal to round-off (stored by no phnn kernels") != std::string::npos) ++rounded;
    else EXPECT_THAT(log, HasSubstr("bitwise equal"));
  }
  EXPECT_GE(rounded, 1) << "kernel set 2 reproduces kernel set 0's rollouts bitwise everywhere?";
  std::string copy_log;
  ASSERT_EQ(testing_util::run_shell("cp " + fixture + " " + out_ +
                                        " && /usr/bin/python3 -c \"import h5py; f = h5py.File('" +
                                        out_ + "', 'r+'); m = f['runs/mse']; m[0] = m[0] * 1.001\"",
                                    &copy_log),
            0)
      << copy_log;
  std::string log;
  EXPECT_EQ(run("eval " + out_ + " --run " + ids[0], &log), 1) << log;
  EXPECT_THAT(log, HasSubstr("DIFFERENT beyond round-off"));
}

// The seeds of one cell share their ids' first digits: a short prefix names
// them all and says so; --seed picks one of them.
TEST_F(EvalCommandTest, AnAmbiguousPrefixIsResolvedBySeed) {
  const std::vector<std::string> ids = train("harmonic", "node-rk2");
  ASSERT_EQ(ids.size(), 2u);
  std::size_t common = 0;
  while (common < ids[0].size() && ids[0][common] == ids[1][common]) ++common;
  ASSERT_GE(common, 1u) << ids[0] << " " << ids[1];
  const std::string prefix = ids[0].substr(0, common);
  std::string log;
  EXPECT_EQ(run("eval " + out_ + " --run " + prefix, &log), 2);
  EXPECT_THAT(log, HasSubstr("matches 2 runs (" + ids[0] + " (seed 0), " + ids[1] + " (seed 1))"));
  EXPECT_THAT(log, HasSubstr("add --seed N"));
  ASSERT_EQ(run("eval " + out_ + " --run " + prefix + " --seed 1", &log), 0) << log;
  EXPECT_THAT(log, HasSubstr(ids[1]));
  EXPECT_EQ(run("eval " + out_ + " --run " + prefix + " --seed 7", &log), 2);
  EXPECT_THAT(log, HasSubstr("no run with id " + prefix + " and seed 7"));
}

// The CSV: both figure trajectories from t = 0, the true H(x0) of each
// (0.5 J and 0.75 J by construction), and no learned energy for NODE.
TEST_F(EvalCommandTest, EnergyCsvStartsAtTheFigureEnergies) {
  for (const std::string model : {"phnn-s-dg", "node-rk2"}) {
    SCOPED_TRACE(model);
    std::remove(out_.c_str());
    const std::vector<std::string> ids = train("harmonic", model);
    const std::string csv = out_ + ".csv";
    std::string log;
    ASSERT_EQ(run("eval " + out_ + " --run " + ids[0].substr(0, 10) + " --out " + csv, &log), 0)
        << log;
    std::ifstream in(csv);
    std::string line;
    ASSERT_TRUE(std::getline(in, line));
    EXPECT_EQ(line, "h0,t,q,p,q_ref,p_ref,H_true,H_true_ref,H_model,H_model_ref");
    int rows_05 = 0, rows_075 = 0;
    while (std::getline(in, line)) {
      const std::vector<std::string> f = split(line);
      ASSERT_EQ(f.size(), 10u) << line;
      const double t = std::stod(f[1]), h_true_ref = std::stod(f[7]), h_model = std::stod(f[8]);
      if (t == 0.0) {
        EXPECT_NEAR(h_true_ref, std::stod(f[0]), 1e-12) << line;
      }
      EXPECT_EQ(std::isnan(h_model), model == "node-rk2") << line;
      (f[0] == "0.5" ? rows_05 : rows_075) += 1;
    }
    EXPECT_EQ(rows_05, 501);  // x_0 ... x_500 of the inference duration
    EXPECT_EQ(rows_075, 501);
    std::remove(csv.c_str());
  }
}

// Settings of the sweep file reach the reloaded model: a PHNN-JR-DG run
// whose DG step evaluates R at x_n (not the default midpoint) reproduces.
TEST_F(EvalCommandTest, SweepFileSettingsReachTheReloadedModel) {
  const std::string sweep = out_ + ".toml";
  {
    std::ofstream s(sweep);
    s << "name = \"eval-start\"\n[data]\nnum_validation = 50\nnum_inference = 5\n"
         "[training]\nsteps = 20\neval_every = 10\ndg_structure_point = \"start\"\n"
         "[grid]\nsystems = [\"duffing\"]\nmodels = [\"phnn-jr-dg\"]\nseeds = [0, 1]\n";
  }
  std::string log;
  ASSERT_EQ(run("sweep " + sweep + " --out " + out_ + " --quiet", &log), 0) << log;
  for (const std::string& id : ResultsFile::open_read_only(out_).read_run_ids()) {
    EXPECT_EQ(run("eval " + out_ + " --run " + id, &log), 0) << log;
    EXPECT_THAT(log, HasSubstr("bitwise equal"));
  }
  std::remove(sweep.c_str());
  testing_util::run_shell("rm -rf " + out_ + ".journal " + out_ + ".lock", &log);
}

// Float32 training: the stored weights are the float32 best weights upcast
// (each a float32 value), and `phnn eval` rebuilds the same float64
// inference model from them, so the stored MSE reproduces bitwise (DG
// Newton, RK2 and the fourth-order DG4).
TEST_F(EvalCommandTest, Float32RunsReproduceTheirStoredMseBitwise) {
  const std::string sweep = out_ + ".toml";
  {
    std::ofstream s(sweep);
    s << "name = \"eval-float32\"\n[data]\nnum_validation = 50\nnum_inference = 5\n"
         "[training]\nsteps = 20\neval_every = 10\nprecision = \"float32\"\n"
         "[grid]\nsystems = [\"duffing\"]\n"
         "models = [\"phnn-jr-dg\", \"phnn-s-rk2\", \"phnn-jr-dg4\"]\nseeds = [0, 1]\n";
  }
  std::string log;
  ASSERT_EQ(run("sweep " + sweep + " --out " + out_ + " --quiet", &log), 0) << log;
  const ResultsFile file = ResultsFile::open_read_only(out_);
  const std::vector<std::string> ids = file.read_run_ids();
  ASSERT_EQ(ids.size(), 6u);
  for (std::size_t row = 0; row < ids.size(); ++row) {
    const RunResult stored = file.read_run(static_cast<int>(row));
    ASSERT_FALSE(stored.weights.empty());
    for (double w : stored.weights) {
      ASSERT_EQ(static_cast<double>(static_cast<float>(w)), w) << ids[row];
    }
    EXPECT_EQ(run("eval " + out_ + " --run " + ids[row], &log), 0) << log;
    EXPECT_THAT(log, HasSubstr("bitwise equal"));
  }
  std::remove(sweep.c_str());
  testing_util::run_shell("rm -rf " + out_ + ".journal " + out_ + ".lock", &log);
}

TEST_F(EvalCommandTest, UnknownOrMissingRunIsAUsageError) {
  train("harmonic", "phnn-jr-rk2");
  std::string log;
  EXPECT_EQ(run("eval " + out_ + " --run ffffffffffffffff", &log), 2);
  EXPECT_THAT(log, HasSubstr("--per-run"));
  EXPECT_EQ(run("eval " + out_, &log), 2);
  EXPECT_THAT(log, HasSubstr("--run ID is required"));
}

// --data: the runs of a file rolled out on another data set. On the data
// they were trained on (a data-set file, trained with --data) each run's
// MSE and errors per trajectory are its stored ones, bit for bit (the
// trainer's inference and eval's are the same code from the same weights);
// the CSV's MSE is the mean of its errors (Eq. 31); on a chirp-driven set
// the MSE differs; a data set of other states is refused.
TEST_F(EvalCommandTest, OnAnotherDataSetEveryRunRollsOutAndItsErrorsAreWritten) {
  const std::string dir = out_ + ".d/";
  ASSERT_EQ(std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str()), 0);
  const std::string systems = std::string(PHNN_SOURCE_DIR) + "/sweeps/systems/";
  std::string log;
  ASSERT_EQ(run("data --system " + systems + "pendulum-forced.toml --n-train 25 --out " + dir + "sines.h5", &log), 0) << log;
  ASSERT_EQ(run("data --system " + systems + "pendulum-chirp.toml --n-train 1 --out " + dir + "chirp.h5", &log), 0) << log;
  ASSERT_EQ(run("train --data " + dir + "sines.h5 --model phnn-s-dg --n-train 25 --seeds 0-1 --steps 40 "
                "--eval-every 20 --quiet --out " + out_, &log), 0) << log;
  ASSERT_EQ(run("eval " + out_ + " --data " + dir + "sines.h5 --errors " + dir + "own.csv", &log), 0) << log;
  ASSERT_EQ(run("eval " + out_ + " --data " + dir + "chirp.h5 --errors " + dir + "chirp.csv", &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("on " + dir + "chirp.h5 (100 trajectories;"));
  const ResultsFile file = ResultsFile::open_read_only(out_);
  const std::vector<std::string> ids = file.read_run_ids();
  // Per run: the CSV's (error per trajectory, MSE), in file order.
  const auto read_csv = [&](const std::string& path) {
    std::map<std::string, std::pair<std::vector<double>, double>> rows;
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "run_id,system,model,integrator,size,n_train,regularizer,seed,trajectory,position,error,mse");
    while (std::getline(in, line)) {
      const auto f = split(line);
      rows[f[0]].first.push_back(std::stod(f[10]));
      rows[f[0]].second = std::stod(f[11]);
    }
    return rows;
  };
  const auto own = read_csv(dir + "own.csv"), chirp = read_csv(dir + "chirp.csv");
  ASSERT_EQ(own.size(), 2u);
  for (std::size_t row = 0; row < ids.size(); ++row) {
    const RunResult stored = file.read_run(static_cast<int>(row));
    const auto& [errors, mse] = own.at(ids[row]);
    EXPECT_EQ(mse, stored.mse);  // %.17g round-trips a double
    EXPECT_EQ(errors, stored.trajectory_errors);
    double mean = 0;
    for (double e : chirp.at(ids[row]).first) mean += e;
    mean /= static_cast<double>(chirp.at(ids[row]).first.size());
    EXPECT_NEAR(mean, chirp.at(ids[row]).second, 1e-13 * mean);
    EXPECT_NE(chirp.at(ids[row]).second, stored.mse);
  }
  ASSERT_EQ(run("data --system " + systems + "coupled-duffing.toml --n-train 1 --out " + dir + "four.h5", &log), 0);
  EXPECT_EQ(run("eval " + out_ + " --data " + dir + "four.h5", &log), 2);
  EXPECT_THAT(log, HasSubstr("no finished run of " + out_ + " fits --data " + dir + "four.h5: it has states [q1,"));
  EXPECT_EQ(run("eval " + out_ + " --errors " + dir + "x.csv --run " + ids[0], &log), 2);
  EXPECT_THAT(log, HasSubstr("--errors goes with --data FILE"));
  std::system(("rm -rf " + dir).c_str());
}

}  // namespace
}  // namespace phnn
