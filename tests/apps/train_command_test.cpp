// tests/apps/train_command_test.cpp — `phnn train` end to end.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_util.h"

#include "phnn/store/results_file.h"

namespace phnn {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

int run(const std::string& args, std::string* output) {
  return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, output);
}

TEST(TrainCommandTest, TrainsACellAndWritesAFileTheReducerReads) {
  const std::string out = ::testing::TempDir() + "phnn_train_cell_" + std::to_string(::getpid()) + ".h5";
  std::remove(out.c_str());
  std::string log;
  ASSERT_EQ(run("train --system harmonic --model phnn-s-dg --n-train 25 --seeds 0-2 "
                "--steps 40 --eval-every 20 --quiet --out " + out, &log), 0) << log;
  EXPECT_THAT(log, Not(HasSubstr("older spelling")));
  EXPECT_THAT(log, HasSubstr("median [IQR]:"));
  EXPECT_THAT(log, HasSubstr("parameters/member: 852"));
  const ResultsFile file = ResultsFile::open_read_only(out);
  ASSERT_EQ(file.num_runs(), 3);
  for (RunStatus s : file.read_statuses()) EXPECT_NE(s, RunStatus::kPending);
  EXPECT_EQ(file.read_seeds(), (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_TRUE(file.has_system_data("harmonic"));
  ASSERT_EQ(run("reduce " + out, &log), 0) << log;
  EXPECT_THAT(log, HasSubstr("| PHNN-S-DG |"));
  // Never overwrites.
  EXPECT_EQ(run("train --system harmonic --model phnn-s --steps 1 --out " + out, &log), 2);
  EXPECT_THAT(log, HasSubstr("exists"));
  std::remove(out.c_str());
}

TEST(TrainCommandTest, RejectsBadOptionsWithStatusTwo) {
  std::string log;
  EXPECT_EQ(run("train --system harmonic --model node --integrator dg --steps 1", &log), 2);
  EXPECT_THAT(log, HasSubstr("integrator = dg with model = node"));
  EXPECT_THAT(log, Not(HasSubstr("phnn train: phnn train")));  // no made-up FILE:LINE
  EXPECT_THAT(log, Not(HasSubstr("CellSpec")));  // no internal names in messages
  EXPECT_EQ(run("train --system harmonic --model phnn-jr --steps -4", &log), 2);
  EXPECT_THAT(log, HasSubstr("--steps = -4 is outside [1, 2147483647]"));
  // No silent wrap-around of int counters, no empty training.
  for (const char* bad : {"--steps 100000000000", "--steps 3000000000", "--steps 0",
                          "--batch 4294967360", "--batch 0", "--eval-every 0",
                          "--n-train 4294967321"}) {
    EXPECT_EQ(run(std::string("train --system harmonic --model phnn-jr-rk2 ") + bad, &log), 2) << bad;
    EXPECT_THAT(log, HasSubstr("is outside [")) << bad;
  }
  EXPECT_EQ(run("train --system harmonic --model phnn-jr-rk2 --precision float16 --steps 1", &log), 2);
  EXPECT_THAT(log, HasSubstr("unknown precision \"float16\" (did you mean \"float64\"?); "
                             "expected one of: float64, float32"));
  EXPECT_EQ(run("train --system harmonic --model phnn-jr --seeds 3-1", &log), 2);
  EXPECT_THAT(log, HasSubstr("--seeds"));
  EXPECT_EQ(run("train --system harmonic --model phnn-jr --seeds 1,1 --steps 1", &log), 2);
  EXPECT_THAT(log, HasSubstr("seed 1 listed twice"));
  EXPECT_EQ(run("train --system harmonic --model mlp", &log), 2);
  EXPECT_THAT(log, HasSubstr("--model \"mlp\": expected formulation-integrator"));  // nothing near
  EXPECT_EQ(run("train --system harmonic --model node-dg --steps 1", &log), 2);
  EXPECT_THAT(log, HasSubstr("integrator = dg with model = node"));
  EXPECT_THAT(log, Not(HasSubstr("phnn train: phnn train")));  // no made-up FILE:LINE
  EXPECT_EQ(run("train --system harmonic --model phnn-jr-rk2 --integrator dg --steps 1", &log), 2);
  EXPECT_THAT(log, HasSubstr("already names the integrator rk2"));
  // "Did you mean" for a system and a model a letter away.
  EXPECT_EQ(run("train --system duffin --model phnn-jr-rk2 --steps 1", &log), 2);
  EXPECT_THAT(log, HasSubstr("unknown system \"duffin\" (did you mean \"duffing\"?)"));
  EXPECT_EQ(run("train --system duffing --model phnn-jr-rk3 --steps 1", &log), 2);
  EXPECT_THAT(log, HasSubstr("--model \"phnn-jr-rk3\" (did you mean \"phnn-jr-rk2\"?)"));
}

// One name for a model and its integrator, as in sweep files; the older
// two-option spelling trains the same cell, with a note.
TEST(TrainCommandTest, OneModelNameAndTheOlderSpellingTrainTheSameCell) {
  std::string joined, split;
  ASSERT_EQ(run("train --system duffing --model phnn-jr-dg --seeds 0 --steps 20 --eval-every 10 "
                "--quiet", &joined), 0) << joined;
  ASSERT_EQ(run("train --system duffing --model phnn-jr --integrator dg --seeds 0 --steps 20 "
                "--eval-every 10 --quiet", &split), 0) << split;
  EXPECT_THAT(split, HasSubstr("note: --model phnn-jr --integrator dg is the older spelling of "
                               "--model phnn-jr-dg"));
  auto table = [](const std::string& log) { return log.substr(log.find("  seed")); };
  auto without_wall_time = [](std::string t) { return t.substr(0, t.find("wall time")); };
  EXPECT_EQ(without_wall_time(table(joined)), without_wall_time(table(split)));
}

// --out into a missing directory is refused before training (it used to
// train for the whole run, then fail to write).
TEST(TrainCommandTest, UnwritableOutIsRefusedBeforeTraining) {
  std::string log;
  EXPECT_EQ(run("train --system harmonic --model phnn-jr --steps 50000 --seeds 0-9 "
                "--out /nonexistent-dir/x.h5", &log), 2);
  EXPECT_THAT(log, HasSubstr("directory /nonexistent-dir does not exist or is not writable"));
  EXPECT_THAT(log, Not(HasSubstr("median [IQR]")));
}

// Progress written to a file (not a terminal) has no carriage returns: one
// plain line per tenth of the run.
TEST(TrainCommandTest, ProgressInALogFileHasNoCarriageReturns) {
  std::string log;
  ASSERT_EQ(run("train --system harmonic --model phnn-jr --steps 100 --eval-every 10 --seeds 0",
                &log), 0) << log;
  EXPECT_EQ(log.find('\r'), std::string::npos);
  EXPECT_THAT(log, HasSubstr("step 100/100"));
  EXPECT_THAT(log, HasSubstr("step 50/100"));
  // Header and estimate first even when stdout is a file (flushed), no
  // "ETA 0 s" before the first step, and each logged line has its time.
  EXPECT_LT(log.find("phnn train: harmonic"), log.find("step 0/100"));
  EXPECT_LT(log.find("phnn train: estimated "), log.find("step 0/100"));
  EXPECT_THAT(log, HasSubstr("step 0/100  best val"));
  EXPECT_THAT(log, ::testing::ContainsRegex("step 0/100 .* ETA --  \\(20[0-9-]+T[0-9:]+Z\\)"));
}

}  // namespace
}  // namespace phnn
