// tests/sweep/sweep_file_test.cpp — the sweep-file format: accepted files,
// defaults, and the catalogue of hostile inputs rejected with FILE:LINE.
// Size: one test file per module; the catalogue is the format's contract.
#include "phnn/sweep/sweep_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "phnn/config/run_config.h"
#include "phnn/sweep/grid.h"

namespace phnn {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

const std::string kSweeps = std::string(PHNN_SOURCE_DIR) + "/sweeps/";

// The SweepFileError a text raises; fails the test if it parses.
SweepFileError error_of(const std::string& text) {
  try {
    parse_sweep_text(text, "x.toml");
  } catch (const SweepFileError& error) {
    return error;
  }
  ADD_FAILURE() << "expected a SweepFileError for:\n" << text;
  return SweepFileError("x.toml", 0, "no error");
}

using Pair = std::pair<ModelKind, IntegratorKind>;

TEST(SweepFileTest, PaperSweepHasThreeStudiesOnSpecDefaults) {
  const SweepSpec spec = parse_sweep_file(kSweeps + "paper.toml");
  EXPECT_EQ(spec.name, "paper");
  EXPECT_EQ(spec.output, "results/paper.h5");
  ASSERT_EQ(spec.studies.size(), 3u);
  EXPECT_EQ(spec.studies[0].name, "I");
  EXPECT_EQ(spec.studies[1].name, "II");
  EXPECT_EQ(spec.studies[2].name, "III");
  EXPECT_EQ(spec.studies[0].title, "Impact of the number of training points");
  EXPECT_THAT(spec.studies[0].n_train, ElementsAre(25, 100, 400));
  EXPECT_THAT(spec.studies[0].sizes, ElementsAre(ModelSize::kSmall));
  EXPECT_THAT(spec.studies[1].sizes,
              ElementsAre(ModelSize::kSmall, ModelSize::kMedium, ModelSize::kLarge));
  EXPECT_THAT(spec.studies[1].n_train, ElementsAre(25));
  EXPECT_THAT(spec.studies[2].regularizers, ElementsAre(Regularizer::kNone, Regularizer::kCn,
                                                        Regularizer::kSn, Regularizer::kSr));
  EXPECT_THAT(spec.studies[2].seeds, ElementsAre(0, 1, 2, 3, 4, 5, 6, 7, 8, 9));
  EXPECT_THAT(spec.studies[2].models, ElementsAre(Pair(ModelKind::kNode, IntegratorKind::kRk2),
                                                  Pair(ModelKind::kPhnnJr, IntegratorKind::kDg),
                                                  Pair(ModelKind::kPhnnJr, IntegratorKind::kRk2),
                                                  Pair(ModelKind::kPhnnS, IntegratorKind::kDg),
                                                  Pair(ModelKind::kPhnnS, IntegratorKind::kRk2)));
  EXPECT_THAT(spec.studies[0].systems,
              ElementsAre("harmonic", "duffing", "self-sustained"));
  // docs/METHOD.md values, bit for bit (the file restates some, which must not
  // change them).
  const TrainerOptions training;
  EXPECT_EQ(spec.training.steps, 50000);
  EXPECT_EQ(spec.training.learning_rate, training.learning_rate);
  EXPECT_EQ(spec.training.eval_every, 500);
  EXPECT_EQ(spec.data.num_validation, 2500);
  EXPECT_EQ(spec.data.generation_step, DatasetOptions().generation_step);
  for (SystemKind kind : all_systems()) {
    const OscillatorOptions defaults = OscillatorOptions::defaults(kind);
    EXPECT_EQ(spec.physics.at(kind).kind, kind);
    EXPECT_EQ(spec.physics.at(kind).damping, defaults.damping);
    EXPECT_EQ(spec.physics.at(kind).mass, defaults.mass);
  }
}

TEST(SweepFileTest, TableDampingPresetSetsDampingOfHarmonicAndDuffingOnly) {
  const SweepSpec spec = parse_sweep_file(kSweeps + "paper-table-damping.toml");
  EXPECT_EQ(spec.output, "results/paper-table-damping.h5");
  EXPECT_EQ(spec.physics.at(SystemKind::kHarmonic).damping, 0.9);
  EXPECT_EQ(spec.physics.at(SystemKind::kDuffing).damping, 0.9);
  EXPECT_EQ(spec.physics.at(SystemKind::kSelfSustained).z_coefficients,
            OscillatorOptions::defaults(SystemKind::kSelfSustained).z_coefficients);
  EXPECT_EQ(spec.studies.size(), 3u);
}

TEST(SweepFileTest, DemoAndTinySweepsParse) {
  const SweepSpec demo = parse_sweep_file(kSweeps + "demo.toml");
  EXPECT_EQ(demo.training.steps, 4000);
  EXPECT_EQ(demo.training.eval_every, 250);
  EXPECT_EQ(demo.output, "results/demo.h5");
  const SweepSpec tiny = parse_sweep_file(kSweeps + "tiny.toml");
  EXPECT_EQ(tiny.training.steps, 20);
  EXPECT_EQ(tiny.data.num_validation, 50);
  EXPECT_EQ(tiny.data.num_inference, 5);
  ASSERT_EQ(tiny.studies.size(), 1u);
  EXPECT_EQ(tiny.studies[0].name, "grid");
  EXPECT_THAT(tiny.studies[0].models, ElementsAre(Pair(ModelKind::kPhnnJr, IntegratorKind::kRk2),
                                                  Pair(ModelKind::kNode, IntegratorKind::kRk2)));
}

TEST(SweepFileTest, ReadsEveryValueKindCommentsAndMultiLineArrays) {
  const SweepSpec spec = parse_sweep_text(R"(# leading comment
name = "kinds"   # trailing comment
[data]
seed = 7
alpha = 0.25
energy_min = 1e-1
num_trajectories = 12_500
newton_tolerance = 1E-13

[training]
learning_rate = 5e-4
adam_eps = 1
batch_size = 32

[physics.self-sustained]
z_coefficients = [3, -4.0, 1.3]

[physics.duffing]
cubic_stiffness = 500.0

[grid]
n_train = [
  25,   # first
  50,
]
seeds = "3-5"
models = ["phnn-s-dg"]
)",
                                          "kinds.toml");
  EXPECT_EQ(spec.name, "kinds");
  EXPECT_EQ(spec.output, "results/kinds.h5");
  EXPECT_EQ(spec.source_path, "kinds.toml");
  EXPECT_EQ(spec.data.data_seed, 7u);
  EXPECT_EQ(spec.data.alpha, 0.25);
  EXPECT_EQ(spec.data.energy_min, 0.1);
  EXPECT_EQ(spec.data.num_trajectories, 12500);
  EXPECT_EQ(spec.data.newton.newton_tolerance, 1e-13);
  EXPECT_EQ(spec.training.learning_rate, 5e-4);
  EXPECT_EQ(spec.training.adam_eps, 1.0);  // an integer is a valid float
  EXPECT_EQ(spec.training.batch_size, 32);
  EXPECT_EQ(spec.physics.at(SystemKind::kSelfSustained).z_coefficients[1], -4.0);
  EXPECT_EQ(spec.physics.at(SystemKind::kDuffing).cubic_stiffness, 500.0);
  ASSERT_EQ(spec.studies.size(), 1u);
  EXPECT_THAT(spec.studies[0].n_train, ElementsAre(25, 50));
  EXPECT_THAT(spec.studies[0].seeds, ElementsAre(3, 4, 5));
  EXPECT_EQ(spec.studies[0].systems.size(), 3u);  // default: all systems
  EXPECT_THAT(spec.studies[0].regularizers, ElementsAre(Regularizer::kNone));
}

TEST(SweepFileTest, TextHashIsFnv1aOfTheText) {
  const std::string text = "name = \"h\"\n";
  const SweepSpec spec = parse_sweep_text(text, "h.toml");
  EXPECT_EQ(spec.text, text);
  EXPECT_EQ(spec.text_hash, hex64(fnv1a64(text)));
  EXPECT_EQ(spec.text_hash.size(), 16u);
}

TEST(SweepFileTest, StudiesKeepFileOrderAndInheritTheGrid) {
  const SweepSpec spec = parse_sweep_text(R"(name = "order"
[study.b]
n_train = [100]
[grid]
systems = ["duffing"]
[study.a]
systems = ["harmonic", "self-sustained"]
)",
                                          "order.toml");
  ASSERT_EQ(spec.studies.size(), 2u);
  EXPECT_EQ(spec.studies[0].name, "b");
  EXPECT_THAT(spec.studies[0].systems, ElementsAre("duffing"));
  EXPECT_THAT(spec.studies[0].n_train, ElementsAre(100));
  EXPECT_EQ(spec.studies[1].name, "a");
  EXPECT_THAT(spec.studies[1].systems,
              ElementsAre("harmonic", "self-sustained"));
  EXPECT_THAT(spec.studies[1].n_train, ElementsAre(25));
}

// Everything a sweep file sets, and the grid it expands to.
void expect_same_spec(const SweepSpec& a, const SweepSpec& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.output, b.output);
  ASSERT_EQ(a.studies.size(), b.studies.size());
  for (std::size_t i = 0; i < a.studies.size(); ++i) {
    SCOPED_TRACE(a.studies[i].name);
    EXPECT_EQ(a.studies[i].name, b.studies[i].name);
    EXPECT_EQ(a.studies[i].title, b.studies[i].title);
    EXPECT_EQ(a.studies[i].systems, b.studies[i].systems);
    EXPECT_EQ(a.studies[i].models, b.studies[i].models);
    EXPECT_EQ(a.studies[i].sizes, b.studies[i].sizes);
    EXPECT_EQ(a.studies[i].n_train, b.studies[i].n_train);
    EXPECT_EQ(a.studies[i].regularizers, b.studies[i].regularizers);
    EXPECT_EQ(a.studies[i].seeds, b.studies[i].seeds);
  }
  // canonical(): every physics, data and training field of every run.
  const Grid ga = expand_grid(a), gb = expand_grid(b);
  ASSERT_EQ(ga.runs.size(), gb.runs.size());
  for (std::size_t i = 0; i < ga.runs.size(); ++i) {
    EXPECT_EQ(ga.runs[i].canonical(), gb.runs[i].canonical());
  }
}

// toml++ reads all of TOML 1.0: dotted keys, inline tables, literal and
// multi-line strings, a [study] table holding the studies give the same sweep
// as the plain one-table-per-header layout.
TEST(SweepFileTest, FullTomlSyntaxGivesTheSameSpecAsThePlainLayout) {
  const SweepSpec plain = parse_sweep_text(R"(name = "same"
[data]
num_train_max = 100
[training]
steps = 200
learning_rate = 1e-3
[physics.duffing]
damping = 0.5
[study.a]
title = "A"
systems = ["duffing"]
n_train = [25, 50]
[study.b]
models = ["phnn-s-dg"]
seeds = "0-2"
)",
                                           "plain.toml");
  const SweepSpec rich = parse_sweep_text(R"(name = 'same'
data.num_train_max = 100
training = { steps = 2_00, learning_rate = 0.001 }
physics.duffing = { damping = 5e-1 }
[study]
a = { title = "A", systems = ["duffing"], n_train = [25, 50] }
b.models = [
  'phnn-s-dg',  # the only model
]
b.seeds = """0-2"""
)",
                                          "rich.toml");
  EXPECT_EQ(rich.data.num_train_max, 100);
  EXPECT_EQ(rich.training.steps, 200);
  expect_same_spec(plain, rich);
  EXPECT_THAT(error_of("name = \"t\"\ntraining = { steps = 0 }\n").what(),
              StartsWith("x.toml:2: steps = 0 is out of range"));
}

// Quoted keys would allow any study name; results files list a run's studies
// separated by commas, so names stay bare words.
TEST(SweepFileErrorTest, StudyNamesAreBareWords) {
  EXPECT_THAT(error_of("name = \"t\"\n[study.\"I,II\"]\nseeds = [0]\n").what(),
              AllOf(StartsWith("x.toml:2: study name \"I,II\" must be letters, digits"),
                    HasSubstr("separated by commas")));
  EXPECT_THAT(error_of("name = \"t\"\n[study]\n").what(),
              StartsWith("x.toml:2: [study] names no study"));
}

// toml++ nests a table per dot and recurses over them: a 60 kB [a.a.a...]
// header would need megabytes of stack, so deep keys are refused first.
TEST(SweepFileErrorTest, DeeplyDottedKeysAreRefusedBeforeParsing) {
  std::string deep;
  for (int i = 0; i < 20000; ++i) deep += ".a";
  EXPECT_THAT(error_of("name = \"t\"\n[grid" + deep + "]\n").what(),
              AllOf(StartsWith("x.toml:2: a dotted key or table header nests more than 64 tables"),
                    HasSubstr("physics.duffing.damping")));
  EXPECT_THAT(error_of("name = \"t\"\nx" + deep + " = 1\n").what(),
              StartsWith("x.toml:2: a dotted"));
  EXPECT_THAT(error_of("name = \"t\"\ngrid.a.a = 1\n").what(),
              StartsWith("x.toml:2: unknown table [grid.a] in [grid]"));
}

// --- errors: FILE:LINE, the offending key or value, the allowed values ---

TEST(SweepFileErrorTest, MisspelledKeyListsTheKeysOfItsTable) {
  const SweepFileError e = error_of(R"(name = "t"
[training]
learning_rate = 1e-3
stpes = 5000
)");
  EXPECT_EQ(e.line(), 4);
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:4: unknown key \"stpes\" in [training]"),
                              HasSubstr("did you mean \"steps\"?"),
                              HasSubstr("expected one of: steps, learning_rate, adam_beta1"),
                              HasSubstr("divergence_norm")));
}

TEST(SweepFileErrorTest, UnknownTableListsTheTables) {
  const SweepFileError e = error_of("name = \"t\"\n\n[trainng]\nsteps = 5\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:3: unknown table [trainng]"),
                              HasSubstr("did you mean \"training\"?"),
                              HasSubstr("expected one of: [data], [training], [grid]")));
}

TEST(SweepFileErrorTest, UnknownPhysicsSystemListsTheSystems) {
  const SweepFileError e = error_of("name = \"t\"\n[physics.duffin]\ndamping = 0.9\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:2: unknown system \"duffin\""),
                              HasSubstr("[physics.harmonic], [physics.duffing], "
                                        "[physics.self-sustained]")));
}

TEST(SweepFileErrorTest, PhysicsKeyTheSystemDoesNotUseIsUnknown) {
  const SweepFileError e = error_of("name = \"t\"\n[physics.harmonic]\ncubic_stiffness = 1.0\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:3: unknown key \"cubic_stiffness\" in "
                                         "[physics.harmonic]"),
                              HasSubstr("expected one of: mass, stiffness, damping")));
}

TEST(SweepFileErrorTest, UnknownKeyAtTopLevelIsReported) {
  const SweepFileError e = error_of("name = \"t\"\nouput = \"a.h5\"\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:2: unknown key \"ouput\""),
                              HasSubstr("expected one of: name, output")));
}

TEST(SweepFileErrorTest, UnknownIntegratorInModelsListsTheModels) {
  const SweepFileError e = error_of(R"(name = "t"
[grid]
models = [
  "node-rk2",
  "phnn-s-rk3",
]
)");
  EXPECT_STREQ(e.what(),
               "x.toml:5: unknown integrator \"rk3\" in models value \"phnn-s-rk3\"; expected "
               "one of: node-rk2, phnn-jr-dg, phnn-jr-rk2, phnn-s-dg, phnn-s-rk2, node-rk4, "
               "phnn-jr-rk4, phnn-s-rk4, phnn-jr-dg4, phnn-s-dg4");
}

// [training] checkpoints: sorted step budgets, checked like every other
// training option, and part of a run's identity only when set.
TEST(SweepFileTest, CheckpointsAreTrainingOptions) {
  const SweepSpec spec = parse_sweep_text(R"(name = "t"
[training]
steps = 1000
checkpoints = [1000, 500]
)", "x.toml");
  const Grid grid = expand_grid(spec);
  ASSERT_FALSE(grid.runs.empty());
  EXPECT_EQ(grid.runs[0].training.checkpoints, (std::vector<int>{500, 1000}));
  EXPECT_THAT(grid.runs[0].canonical(), HasSubstr(";checkpoints=500,1000"));
  const Grid plain = expand_grid(parse_sweep_text("name = \"t\"\n", "x.toml"));
  EXPECT_THAT(plain.runs[0].canonical(), Not(HasSubstr("checkpoints")));
  const SweepFileError e = error_of("name = \"t\"\n[training]\nsteps = 1000\ncheckpoints = [300]\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:4:"), HasSubstr("checkpoints = 300")));
}

// The fourth-order explicit variants are sweep-file models like the others
// (not in the default list, which is the paper's five).
// [grid] / [study.NAME] lambdas: numbers >= 0, each once, inherited from
// [grid] like the other axes; one that would multiply no run is refused.
TEST(SweepFileTest, LambdasAreAnAxisOfNonNegativeNumbers) {
  const SweepSpec spec = parse_sweep_text(R"(name = "t"
[grid]
regularizers = ["none", "cn"]
lambdas = [1e-6, 0, 1]
[study.a]
[study.b]
lambdas = [2e-6]
)", "x.toml");
  EXPECT_THAT(spec.studies[0].lambdas, ElementsAre(1e-6, 0.0, 1.0));
  EXPECT_THAT(spec.studies[1].lambdas, ElementsAre(2e-6));
  EXPECT_TRUE(parse_sweep_file(kSweeps + "paper.toml").studies[2].lambdas.empty());
}

TEST(SweepFileErrorTest, BadLambdasPointAtTheirLine) {
  const std::string head = "name = \"t\"\n[grid]\nregularizers = [\"sr\"]\n";
  EXPECT_THAT(error_of(head + "lambdas = [1e-4, -1e-4]\n").what(),
              StartsWith("x.toml:4: lambdas value -1e-4 is out of range; expected an array of "
                         "numbers >= 0"));
  EXPECT_THAT(error_of(head + "lambdas = [\n  1e-4,\n  1e-4,\n]\n").what(),
              StartsWith("x.toml:6: lambdas lists 1e-4 twice"));
  EXPECT_THAT(error_of(head + "lambdas = 1e-4\n").what(),
              StartsWith("x.toml:4: lambdas expects an array of numbers, got the float 1e-4"));
  EXPECT_THAT(error_of(head + "lambdas = [\"1e-4\"]\n").what(),
              StartsWith("x.toml:4: lambdas expects a number"));
  EXPECT_THAT(error_of(head + "lambdas = [nan]\n").what(),
              StartsWith("x.toml:4: lambdas expects a finite number"));
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nlambdas = [1e-4]\n").what(),
              StartsWith("x.toml:3: lambdas of [grid] multiplies no run: every run it would "
                         "apply to has regularizer \"none\""));
  EXPECT_THAT(error_of(head + "[study.I]\nregularizers = [\"none\"]\nlambdas = [1]\n").what(),
              StartsWith("x.toml:6: lambdas of study \"I\" multiplies no run"));
  // [grid] lambdas used by one study of two is fine.
  EXPECT_NO_THROW(parse_sweep_text(head + "lambdas = [1]\n[study.I]\n[study.II]\n"
                                          "regularizers = [\"none\"]\n", "x.toml"));
}

// [training] loss_norm: one of three spellings; part of a run's identity
// only away from the default.
TEST(SweepFileTest, LossNormIsATrainingOption) {
  const std::string head = "name = \"t\"\n[grid]\nseeds = [0]\n[training]\n";
  const SweepSpec spec = parse_sweep_text(head + "loss_norm = \"mse\"\n", "x.toml");
  EXPECT_EQ(spec.training.loss_norm, LossNorm::kMse);
  EXPECT_THAT(expand_grid(spec).runs[0].cell_key(), HasSubstr(";loss_norm=mse;"));
  const Grid plain = expand_grid(parse_sweep_text(head + "loss_norm = \"mean-l1\"\n", "x.toml"));
  EXPECT_EQ(plain.runs[0].id(), expand_grid(parse_sweep_text(head, "x.toml")).runs[0].id());
  EXPECT_THAT(plain.runs[0].cell_key(), Not(HasSubstr("loss_norm")));
  EXPECT_STREQ(error_of(head + "steps = 5\nloss_norm = \"sum-L1\"\n").what(),
               "x.toml:6: unknown loss_norm \"sum-L1\" (did you mean \"sum-l1\"?); expected "
               "one of: mean-l1, sum-l1, mse");
  EXPECT_THAT(error_of(head + "loss_norm = 2\n").what(),
              StartsWith("x.toml:5: loss_norm expects a \"string\", got the integer 2"));
}

// Every run of `knob` is the run of `plain` at the same place with exactly
// `key_part` added to its cell key (so a different id).
void expect_key_part_added(const Grid& knob, const Grid& plain, const std::string& key_part) {
  ASSERT_EQ(knob.runs.size(), plain.runs.size());
  for (std::size_t i = 0; i < knob.runs.size(); ++i) {
    std::string key = knob.runs[i].cell_key();
    const std::size_t at = key.find(key_part + ";");
    ASSERT_NE(at, std::string::npos) << key;
    key.erase(at, key_part.size());
    EXPECT_EQ(key, plain.runs[i].cell_key());
    EXPECT_NE(knob.runs[i].id(), plain.runs[i].id());
  }
}

// [training] inference_weights: best-validation (default) or final; part of
// a run's identity only away from the default, as ";inference_weights=final".
TEST(SweepFileTest, InferenceWeightsIsATrainingOption) {
  const std::string head = "name = \"t\"\n[grid]\nsystems = [\"duffing\"]\nseeds = [0]\n"
                           "models = [\"phnn-jr-dg\", \"node-rk2\"]\n[training]\n";
  const Grid plain = expand_grid(parse_sweep_text(head, "x.toml"));
  const SweepSpec spec = parse_sweep_text(head + "inference_weights = \"final\"\n", "x.toml");
  EXPECT_EQ(spec.training.inference_weights, InferenceWeights::kFinal);
  const Grid final = expand_grid(spec);
  ASSERT_EQ(final.runs.size(), 2u);
  expect_key_part_added(final, plain, ";inference_weights=final");
  const Grid best = expand_grid(
      parse_sweep_text(head + "inference_weights = \"best-validation\"\n", "x.toml"));
  EXPECT_EQ(best.runs[0].id(), plain.runs[0].id());
  EXPECT_THAT(best.runs[0].cell_key(), Not(HasSubstr("inference_weights")));
  EXPECT_STREQ(error_of(head + "inference_weights = \"last\"\n").what(),
               "x.toml:7: unknown inference_weights \"last\"; expected one of: "
               "best-validation, final");
}

// [training] precision: float64 (default) or float32; it changes every run
// (every model trains in it), and is part of a run's identity only away from
// the default, as exactly ";precision=float32".
TEST(SweepFileTest, PrecisionIsATrainingOption) {
  const std::string head = "name = \"t\"\n[grid]\nsystems = [\"duffing\"]\nseeds = [0]\n"
                           "models = [\"phnn-jr-dg\", \"phnn-s-rk2\", \"node-rk4\"]\n"
                           "[training]\n";
  const Grid plain = expand_grid(parse_sweep_text(head, "x.toml"));
  const SweepSpec spec = parse_sweep_text(head + "precision = \"float32\"\n", "x.toml");
  EXPECT_EQ(spec.training.precision, Precision::kFloat32);
  const Grid f32 = expand_grid(spec);
  ASSERT_EQ(f32.runs.size(), 3u);
  expect_key_part_added(f32, plain, ";precision=float32");
  const Grid f64 = expand_grid(parse_sweep_text(head + "precision = \"float64\"\n", "x.toml"));
  EXPECT_EQ(f64.runs[0].id(), plain.runs[0].id());
  EXPECT_THAT(f64.runs[0].cell_key(), Not(HasSubstr("precision")));
  EXPECT_STREQ(error_of(head + "steps = 5\nprecision = \"Float32\"\n").what(),
               "x.toml:8: unknown precision \"Float32\" (did you mean \"float32\"?); expected "
               "one of: float64, float32");
  EXPECT_STREQ(error_of(head + "precision = \"double\"\n").what(),
               "x.toml:7: unknown precision \"double\"; expected one of: float64, float32");
  EXPECT_THAT(error_of(head + "precision = 32\n").what(),
              StartsWith("x.toml:7: precision expects a \"string\", got the integer 32"));
}

// [training] dg_structure_point: part of the identity of PHNN-JR-DG runs
// only (the only DG step with a state-dependent structure), away from the
// default.
TEST(SweepFileTest, DgStructurePointChangesOnlyPhnnJrDgRuns) {
  const std::string head = "name = \"t\"\n[grid]\nsystems = [\"duffing\"]\nseeds = [0]\n"
                           "models = [\"phnn-jr-dg\", \"phnn-jr-rk2\", \"phnn-s-dg\", "
                           "\"phnn-jr-dg4\"]\n[training]\n";
  const Grid plain = expand_grid(parse_sweep_text(head, "x.toml"));
  const SweepSpec spec = parse_sweep_text(head + "dg_structure_point = \"start\"\n", "x.toml");
  EXPECT_EQ(spec.training.dg_structure_point, DgStructurePoint::kStart);
  const Grid start = expand_grid(spec);
  ASSERT_EQ(start.runs.size(), 4u);
  EXPECT_THAT(start.runs[0].cell_key(), HasSubstr(";dg_structure_point=start;"));
  EXPECT_NE(start.runs[0].id(), plain.runs[0].id());
  for (std::size_t i = 1; i < 4; ++i) EXPECT_EQ(start.runs[i].id(), plain.runs[i].id()) << i;
  EXPECT_EQ(expand_grid(parse_sweep_text(head + "dg_structure_point = \"midpoint\"\n", "x.toml"))
                .runs[0].id(),
            plain.runs[0].id());
  EXPECT_STREQ(error_of(head + "dg_structure_point = \"end\"\n").what(),
               "x.toml:7: unknown dg_structure_point \"end\"; expected one of: midpoint, start");
}

// [data] energy_sampling: part of the identity of harmonic and self-sustained
// runs only (Algorithm 1), away from the default; refused where no run uses
// it, like a dg_structure_point without phnn-jr-dg.
TEST(SweepFileTest, EnergySamplingChangesOnlyAlgorithmOneRuns) {
  const std::string head = "name = \"t\"\n[grid]\nmodels = [\"node-rk2\"]\nseeds = [0]\n[data]\n";
  const Grid plain = expand_grid(parse_sweep_text(head, "x.toml"));
  const SweepSpec spec = parse_sweep_text(head + "energy_sampling = \"direct\"\n", "x.toml");
  EXPECT_EQ(spec.data.energy_sampling, EnergySampling::kDirect);
  const Grid direct = expand_grid(spec);
  ASSERT_EQ(direct.runs.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const bool algorithm1 = direct.runs[i].system != SystemKind::kDuffing;
    EXPECT_EQ(direct.runs[i].id() != plain.runs[i].id(), algorithm1) << i;
    EXPECT_EQ(direct.runs[i].cell_key().find(";energy_sampling=direct;") != std::string::npos,
              algorithm1);
  }
  EXPECT_THAT(error_of(head + "energy_sampling = \"sqrt\"\n").what(),
              StartsWith("x.toml:6: unknown energy_sampling \"sqrt\"; expected one of: "
                         "algorithm1, direct"));
  const std::string duffing = "name = \"t\"\n[grid]\nsystems = [\"duffing\"]\n";
  EXPECT_THAT(error_of(duffing + "[data]\nenergy_sampling = \"direct\"\n").what(),
              StartsWith("x.toml:5: energy_sampling = \"direct\" changes no run"));
  EXPECT_THAT(error_of(duffing + "models = [\"phnn-s-dg\", \"phnn-jr-rk2\"]\n[training]\n"
                                 "dg_structure_point = \"start\"\n").what(),
              StartsWith("x.toml:6: dg_structure_point = \"start\" changes no run"));
}

TEST(SweepFileTest, AcceptsRk4Models) {
  const SweepSpec spec = parse_sweep_text(R"(name = "t"
[grid]
models = ["node-rk4", "phnn-jr-rk4", "phnn-s-rk4"]
)", "x.toml");
  EXPECT_THAT(spec.studies[0].models,
              ElementsAre(Pair(ModelKind::kNode, IntegratorKind::kRk4),
                          Pair(ModelKind::kPhnnJr, IntegratorKind::kRk4),
                          Pair(ModelKind::kPhnnS, IntegratorKind::kRk4)));
}

TEST(SweepFileErrorTest, NodeWithDiscreteGradientIsRejected) {
  for (std::string model : {"node-dg", "node-dg4"}) {
    const SweepFileError e = error_of("name = \"t\"\n[grid]\nmodels = [\"" + model + "\"]\n");
    EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:3: models value \"" + model + "\""),
                                HasSubstr("no Hamiltonian; rk2 or rk4 only"),
                                HasSubstr("expected one of: node-rk2")));
  }
}

TEST(SweepFileErrorTest, UnknownAxisValuesListTheAllowedValues) {
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nsystems = [\"harmonic\", \"duffng\"]\n").what(),
              AllOf(StartsWith("x.toml:3: unknown systems value \"duffng\""),
                    HasSubstr("expected one of: harmonic, duffing, self-sustained")));
  EXPECT_THAT(error_of("name = \"t\"\n[study.a]\nsizes = [\"huge\"]\n").what(),
              AllOf(StartsWith("x.toml:3: unknown sizes value \"huge\""),
                    HasSubstr("expected one of: small, medium, large")));
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nregularizers = [\"CN\"]\n").what(),
              AllOf(StartsWith("x.toml:3: unknown regularizers value \"CN\""),
                    HasSubstr("expected one of: none, cn, sn, sr")));
}

TEST(SweepFileErrorTest, StringWhereIntegerExpectedIsATypeError) {
  const SweepFileError e = error_of("name = \"t\"\n[training]\nsteps = \"5000\"\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:3: steps expects an integer >= 1"),
                              HasSubstr("got the string \"5000\"")));
}

TEST(SweepFileErrorTest, FloatWhereIntegerExpectedIsATypeError) {
  const SweepFileError e = error_of("name = \"t\"\n[training]\nbatch_size = 64.0\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:3: batch_size expects an integer >= 1"),
                              HasSubstr("got the float 64.0")));
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nn_train = [25, 1e2]\n").what(),
              AllOf(StartsWith("x.toml:3: n_train expects an array of integers >= 1"),
                    HasSubstr("got the float 1e2")));
}

TEST(SweepFileErrorTest, StringWhereNumberExpectedIsATypeError) {
  EXPECT_THAT(
      error_of("name = \"t\"\n[data]\nalpha = \"0.31\"\n").what(),
      AllOf(StartsWith("x.toml:3: alpha expects a number"), HasSubstr("got the string \"0.31\"")));
}

TEST(SweepFileErrorTest, EmptyAxisIsRejected) {
  const SweepFileError e = error_of("name = \"t\"\n[study.I]\nn_train = []\n");
  EXPECT_THAT(e.what(),
              AllOf(StartsWith("x.toml:3: n_train is empty"), HasSubstr("at least one value")));
}

TEST(SweepFileErrorTest, NegativeOrZeroStepCountIsRejected) {
  EXPECT_THAT(error_of("name = \"t\"\n[training]\nsteps = -5\n").what(),
              StartsWith("x.toml:3: steps = -5 is out of range; expected an integer >= 1"));
  EXPECT_THAT(error_of("name = \"t\"\n[training]\n\nsteps = 0\n").what(),
              StartsWith("x.toml:4: steps = 0 is out of range; expected an integer >= 1"));
}

TEST(SweepFileErrorTest, DuplicateKeyNamesBothLines) {
  const SweepFileError e = error_of(R"(name = "t"
[training]
steps = 100
eval_every = 10
steps = 200
)");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:5: duplicate key \"steps\" in [training]"),
                              HasSubstr("first set on line 3")));
}

TEST(SweepFileErrorTest, DuplicateTableNamesBothLines) {
  const SweepFileError e = error_of("name = \"t\"\n[study.I]\n[grid]\n[study.I]\n");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:4: duplicate table [study.I]"),
                              HasSubstr("first defined on line 2")));
}

TEST(SweepFileErrorTest, NTrainAboveNumTrainMaxPointsAtTheValue) {
  const SweepFileError e = error_of(R"(name = "t"
[data]
num_train_max = 100
[study.I]
n_train = [
  25,
  400,
]
)");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:7: n_train value 400 of study \"I\" is outside "
                                         "[1, num_train_max = 100]"),
                              HasSubstr("raise num_train_max in [data]")));
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nn_train = [0]\n").what(),
              StartsWith("x.toml:3: n_train value 0 is out of range; expected an array of "
                         "integers >= 1"));
}

TEST(SweepFileErrorTest, UnterminatedStringPointsAtItsLine) {
  const SweepFileError e = error_of("name = \"t\"\n[grid]\nsystems = [\"harmonic]\n");
  EXPECT_THAT(e.what(),
              AllOf(StartsWith("x.toml:3: unterminated string"), HasSubstr("\"systems\"")));
  EXPECT_THAT(error_of("name = \"t").what(), StartsWith("x.toml:1: unterminated string"));
}

TEST(SweepFileErrorTest, UnterminatedArrayPointsAtTheLineThatOpensIt) {
  const SweepFileError e = error_of(R"(name = "t"
[grid]
seeds = [0, 1, 2
n_train = [25]
)");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:3: unterminated array in the value of "
                                         "\"seeds\""),
                              HasSubstr("on line 4")));
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nseeds = [0, 1,\n").what(),
              AllOf(StartsWith("x.toml:3: unterminated array"), HasSubstr("end of the file")));
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nseeds = [0, 1,\n[study.a]\n").what(),
              StartsWith("x.toml:3: unterminated array"));
}

TEST(SweepFileErrorTest, SyntaxErrorsNameTheLine) {
  EXPECT_THAT(error_of("name = \"t\"\n[training]\nsteps 5000\n").what(),
              StartsWith("x.toml:3: expected \"=\" after key \"steps\""));
  EXPECT_THAT(error_of("name = \"t\"\n[training]\nsteps =\n").what(),
              StartsWith("x.toml:3: missing value for key \"steps\""));
  EXPECT_THAT(error_of("name = \"t\"\n[training]\nsteps = 5 6\n").what(),
              StartsWith("x.toml:3: unexpected \"6\" after the value of \"steps\""));
  EXPECT_THAT(error_of("name = paper\n").what(),
              AllOf(StartsWith("x.toml:1: invalid value \"paper\" for key \"name\""),
                    HasSubstr("double quotes")));
  EXPECT_THAT(error_of("name = \"t\"\n[grid\n").what(),
              StartsWith("x.toml:2: expected \"]\" to close the table header [grid"));
  EXPECT_THAT(error_of("name = \"t\"\n[training]\nsteps = 007\n").what(),
              StartsWith("x.toml:3: invalid value \"007\""));
}

TEST(SweepFileErrorTest, BadSeedRangeIsRejected) {
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nseeds = \"9-0\"\n").what(),
              AllOf(StartsWith("x.toml:3: seeds range \"9-0\""), HasSubstr("\"0-9\"")));
  EXPECT_THAT(error_of("name = \"t\"\n[grid]\nseeds = [-1]\n").what(),
              StartsWith("x.toml:3: seeds value -1 is out of range"));
}

TEST(SweepFileErrorTest, ValidateFailuresPointAtTheKeyTheyName) {
  const SweepFileError e = error_of(R"(name = "t"
[data]
energy_min = 0.5
energy_max = 0.2
)");
  EXPECT_THAT(e.what(), AllOf(StartsWith("x.toml:4: in [data]: Invalid DatasetOptions: "
                                         "energy_max = 0.2"),
                              HasSubstr("energy_min = 0.5")));
  EXPECT_THAT(error_of("name = \"t\"\n[physics.duffing]\n\nmass = -1\n").what(),
              StartsWith("x.toml:4: in [physics.duffing]: Invalid OscillatorOptions: mass = -1"));
  EXPECT_THAT(error_of("name = \"t\"\n[training]\nlearning_rate = 0\n").what(),
              StartsWith("x.toml:3: in [training]: Invalid TrainerOptions: learning_rate = 0"));
}

TEST(SweepFileErrorTest, MissingNameIsReportedAtLineOne) {
  EXPECT_THAT(error_of("# no name\n[grid]\n").what(),
              StartsWith("x.toml:1: missing required key \"name\""));
}

TEST(SweepFileErrorTest, MissingFileNamesThePath) {
  try {
    parse_sweep_file("/nonexistent/dir/sweep.toml");
    FAIL() << "expected a SweepFileError";
  } catch (const SweepFileError& e) {
    EXPECT_THAT(e.what(), StartsWith("/nonexistent/dir/sweep.toml: cannot open the sweep file"));
    EXPECT_EQ(e.line(), 0);
  }
}

// The SweepFileError of reading `path`; fails the test if it parses.
SweepFileError file_error_of(const std::string& path) {
  try {
    parse_sweep_file(path);
  } catch (const SweepFileError& error) {
    return error;
  }
  ADD_FAILURE() << "expected a SweepFileError for " << path;
  return SweepFileError(path, 0, "no error");
}

// Each would hang (FIFO), never end (/dev/zero) or read a directory: all are
// refused before a byte is read.
TEST(SweepFileErrorTest, RefusesWhatIsNotARegularFileWithoutWaiting) {
  const std::string fifo = ::testing::TempDir() + "phnn_sweep_fifo_" + std::to_string(::getpid());
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  for (const std::string& path : {fifo, std::string("/dev/zero"), ::testing::TempDir()}) {
    SCOPED_TRACE(path);
    EXPECT_THAT(file_error_of(path).what(), StartsWith(path + ": not a regular file"));
  }
  std::remove(fifo.c_str());
}

TEST(SweepFileErrorTest, RefusesAFileOverTheSizeCapBeforeParsing) {
  const std::string path = ::testing::TempDir() + "phnn_sweep_big_" + std::to_string(::getpid());
  std::ofstream(path) << "name = \"big\"\n" << std::string(kMaxSweepFileBytes, '#') << "\n";
  EXPECT_THAT(file_error_of(path).what(),
              AllOf(StartsWith(path + ": "), HasSubstr("more than the 60000 a sweep file may have")));
  std::remove(path.c_str());
  EXPECT_THAT(error_of("name = \"big\"\n" + std::string(kMaxSweepFileBytes, '#')).what(),
              HasSubstr("more than the 60000"));
}

// tests/fixtures/hostile/: 60+ malformed sweep files (syntax, types, ranges,
// unknown names, NUL bytes, deep nesting, ...): each is refused with an
// error that names it (`phnn sweep` launches of a sample: sweep_guard_test).
TEST(SweepFileErrorTest, EveryHostileFixtureIsRefusedNamingTheFile) {
  const std::string dir = std::string(PHNN_SOURCE_DIR) + "/tests/fixtures/hostile/";
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d)) {
      if (std::string(e->d_name).size() > 5) names.push_back(e->d_name);
    }
    ::closedir(d);
  }
  ASSERT_GE(names.size(), 60u);
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    EXPECT_THAT(file_error_of(dir + name).what(), StartsWith(dir + name + ":"));
  }
}

TEST(SweepFileTest, AFileAtTheSizeCapParses) {
  std::string text = "name = \"full\"\n#";
  text += std::string(kMaxSweepFileBytes - text.size() - 1, '#') + "\n";
  ASSERT_EQ(text.size(), kMaxSweepFileBytes);
  EXPECT_EQ(parse_sweep_text(text, "x.toml").name, "full");
}

TEST(SweepFileTest, DefaultOutputStaysInsideResultsWhateverTheName) {
  EXPECT_EQ(parse_sweep_text("name = \"../../x\"\n", "x.toml").output, "results/_._.._x.h5");
  EXPECT_EQ(parse_sweep_text("name = \"a/b\"\n", "x.toml").output, "results/a_b.h5");
  EXPECT_EQ(parse_sweep_text("name = \"ok\"\noutput = \"../elsewhere.h5\"\n", "x.toml").output,
            "../elsewhere.h5")
      << "an explicit output is the user's choice";
}

TEST(SweepFileErrorTest, IsAnInvalidArgument) {
  EXPECT_THROW(parse_sweep_text("name = 1\n", "x.toml"), std::invalid_argument);
}

}  // namespace
}  // namespace phnn
