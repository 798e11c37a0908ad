// tests/report/per_run_test.cpp — the per-run CSV export, without HDF5
// (end to end through `phnn reduce`: tests/apps/reduce_command_test.cpp).
#include "phnn/report/per_run.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace phnn {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::Pair;
using ::testing::StartsWith;

TEST(ParseCanonicalTest, SplitsKeyValuePairsAtTheFirstEquals) {
  EXPECT_THAT(parse_canonical("system=duffing;e0=0.1,0.5;x=a=b;seed=3"),
              ElementsAre(Pair("system", "duffing"), Pair("e0", "0.1,0.5"), Pair("x", "a=b"),
                          Pair("seed", "3")));
  EXPECT_THAT([] { parse_canonical("system=duffing;oops;seed=3"); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("part \"oops\"")));
  EXPECT_THAT([] { parse_canonical("seed=1;seed=2"); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("key \"seed\" repeats")));
}

RunRecord record(const std::string& canonical, RunStatus status, double mse) {
  RunRecord r;
  r.id = "00000000000000ab";
  r.studies = "I,II";
  r.model_label = "PHNN-S-DG";
  r.canonical = canonical;
  r.result.status = status;
  r.result.mse = mse;
  r.result.best_validation_loss = 0.1;
  r.result.wall_time_s = 12.5;
  r.result.best_step = 49000;
  r.result.steps = 50000;
  r.result.parameter_count = 852;
  r.result.diverged_rollouts = 0;
  r.result.newton_failures = 3;
  r.result.train_seconds = 11.25;
  r.trace_points = 101;
  r.initial_validation_loss = 0.5;
  r.final_train_loss = 0.25;
  r.final_validation_loss = 0.125;
  r.final_kappa = 1000.0;
  r.final_sigma_max = 2.0;
  r.final_rho = 0.0625;
  return r;
}

TEST(PerRunCsvTest, OneRowPerRunWithEveryConfigKeyAndFullPrecision) {
  const std::string csv = render_per_run_csv(
      {record("system=harmonic;model=phnn-s;damping=0.5;seed=0", RunStatus::kDone, 1.0 / 3.0),
       record("system=duffing;model=phnn-s;cubic_stiffness=1;damping=0.5;seed=1",
              RunStatus::kDone, 2e-3)});
  EXPECT_THAT(csv, StartsWith("run_id,studies,model_label,system,model,damping,seed,"
                              "cubic_stiffness,status,mse,best_step,best_validation_loss,"
                              "wall_time_s,steps_taken,parameter_count,diverged_rollouts,"
                              "newton_failures,train_seconds,trace_points,initial_validation_loss,"
                              "final_train_loss,final_validation_loss,final_kappa,"
                              "final_sigma_max,final_rho,message\n"));
  // The shortest text that reads back to the double: 1/3 needs 16 digits,
  // 0.1 one; a key the run lacks is empty.
  EXPECT_THAT(csv, HasSubstr("\n00000000000000ab,\"I,II\",PHNN-S-DG,harmonic,phnn-s,0.5,0,,done,"
                             "0.3333333333333333,49000,0.1,12.5,50000,852,0,3,11.25,"
                             "101,0.5,0.25,0.125,1000,2,0.0625,\n"));
  EXPECT_EQ(std::stod("0.3333333333333333"), 1.0 / 3.0);
  EXPECT_THAT(csv, HasSubstr(",PHNN-S-DG,duffing,phnn-s,0.5,1,1,done,0.002,"));
}

// Checkpoints become mse_at_<step>, train_s_at_<step> columns over the
// union of every run's budgets, empty where a run has no such budget.
TEST(PerRunCsvTest, CheckpointsBecomeOneColumnPairPerBudget) {
  RunRecord a = record("seed=0", RunStatus::kDone, 0.5);
  a.checkpoint_steps = {500, 1000};
  a.checkpoint_mse = {0.75, 0.5};
  a.checkpoint_train_seconds = {1.5, 3.0};
  RunRecord b = record("seed=1", RunStatus::kDone, 0.25);
  b.checkpoint_steps = {1000};
  b.checkpoint_mse = {std::numeric_limits<double>::infinity()};
  b.checkpoint_train_seconds = {2.0};
  const std::string csv = render_per_run_csv({a, b});
  EXPECT_THAT(csv, HasSubstr(",final_rho,mse_at_500,train_s_at_500,mse_at_1000,train_s_at_1000,"
                             "message\n"));
  EXPECT_THAT(csv, HasSubstr(",0.0625,0.75,1.5,0.5,3,\n"));
  EXPECT_THAT(csv, HasSubstr(",0.0625,,,inf,2,\n"));
}

TEST(PerRunCsvTest, NamesColumnsAsTheSweepFileAndSplitsMultiNumberKeys) {
  const std::string csv = render_per_run_csv(
      {record("lr=0.001;e0=0.10000000000000001,1;z=3,-4,1.3;newton=1e-12,20;adam=0.9,0.999;"
              "learning_rate=5;future_axis=a,b;seed=0",
              RunStatus::kDone, 1.0)});
  // adam has 2 parts, not 3: kept; lr would repeat learning_rate: kept.
  EXPECT_THAT(csv, StartsWith("run_id,studies,model_label,lr,energy_min,energy_max,z1,z2,z3,"
                              "newton_tolerance,newton_max_iterations,adam,learning_rate,"
                              "future_axis,seed,status,"));
  // Configuration numbers too: the canonical key's %.17g spelling of 0.1
  // becomes 0.1 (the same double); lists keep their text.
  EXPECT_THAT(csv, HasSubstr(",PHNN-S-DG,0.001,0.1,1,3,-4,1.3,1e-12,20,"
                             "\"0.9,0.999\",5,\"a,b\",0,done,1,"));
}

TEST(PerRunCsvTest, SpellsInfinityAndNanForPandasAndQuotesMessages) {
  RunRecord diverged = record("seed=0", RunStatus::kDiverged,
                              std::numeric_limits<double>::infinity());
  diverged.result.message = "rollout 1 diverged: ||x|| = 1.2e+06, \"stuck\"\nat step 42";
  RunRecord failed = record("seed=1", RunStatus::kFailed, -std::nan(""));
  failed.result.best_validation_loss = -std::numeric_limits<double>::infinity();
  const std::string csv = render_per_run_csv({diverged, failed});
  EXPECT_THAT(csv, HasSubstr(",0,diverged,inf,49000,"));
  EXPECT_THAT(csv, HasSubstr(",\"rollout 1 diverged: ||x|| = 1.2e+06, \"\"stuck\"\"\nat step 42\"\n"));
  EXPECT_THAT(csv, HasSubstr(",1,failed,nan,49000,-inf,12.5,"));  // no "-nan"
  EXPECT_THAT(csv, Not(HasSubstr("-nan")));
}

TEST(PerRunCsvTest, NoRecordsGiveTheFixedHeaderOnly) {
  EXPECT_EQ(render_per_run_csv({}),
            "run_id,studies,model_label,status,mse,best_step,best_validation_loss,wall_time_s,"
            "steps_taken,parameter_count,diverged_rollouts,newton_failures,train_seconds,"
            "trace_points,"
            "initial_validation_loss,final_train_loss,final_validation_loss,final_kappa,"
            "final_sigma_max,final_rho,message\n");
}

}  // namespace
}  // namespace phnn
