// tests/apps/cli_test.cpp — cli::Parser (CLI11 underneath): what valid
// command lines give, and the one-line usage errors with "did you mean";
// then the `phnn` binary's command dispatch and --help.
#include "apps/cli.h"

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "test_util.h"

namespace phnn {
namespace cli {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// Parses `args` as if typed after `phnn COMMAND`.
bool parse(Parser* parser, std::vector<std::string> args) {
  std::vector<char*> argv = {const_cast<char*>("phnn"), const_cast<char*>("command")};
  for (std::string& a : args) argv.push_back(a.data());
  return parser->parse(static_cast<int>(argv.size()), argv.data(), /*first=*/2);
}

// The message of the UsageError that parsing `args` throws ("" if none).
std::string usage_error(Parser* parser, const std::vector<std::string>& args) {
  try {
    parse(parser, args);
  } catch (const UsageError& e) {
    return e.message;
  }
  return "";
}

// `phnn reduce`'s declarations.
std::unique_ptr<Parser> reduce_parser() {
  auto parser = std::make_unique<Parser>("reduce", "Prints the tables of a results file.");
  parser->positional("FILE", "results file written by `phnn sweep`");
  parser->option("format", "markdown | latex | csv", "markdown");
  parser->flag("per-run", "one row per run");
  return parser;
}

// A few of `phnn train`'s declarations.
std::unique_ptr<Parser> train_parser() {
  auto parser = std::make_unique<Parser>("train", "Trains one cell.");
  parser->option("system", "harmonic | duffing | self-sustained", "", /*required=*/true);
  parser->option("seeds", "model seeds, e.g. 0-9 or 0,3,5", "0-9");
  parser->option("steps", "Adam steps", "50000");
  parser->option("lr", "learning rate", "1e-3");
  parser->option("out", "also write the runs to this results file");
  parser->flag("quiet", "no progress line");
  return parser;
}

TEST(CliTest, ReadsPositionalsOptionsAndFlagsInAnyOrder) {
  for (const auto& args :
       std::vector<std::vector<std::string>>{{"r.h5", "--format", "csv", "--per-run"},
                                             {"--per-run", "--format=csv", "r.h5"},
                                             {"--format", "csv", "r.h5", "--per-run"}}) {
    auto parser = reduce_parser();
    ASSERT_TRUE(parse(parser.get(), args));
    EXPECT_EQ(parser->get("FILE"), "r.h5");
    EXPECT_EQ(parser->get("format"), "csv");
    EXPECT_TRUE(parser->flag_set("per-run"));
  }
}

TEST(CliTest, DefaultsApplyAndHasTellsAGivenValueFromADefault) {
  auto parser = train_parser();
  ASSERT_TRUE(parse(parser.get(), {"--system", "duffing", "--steps", "50000"}));
  EXPECT_EQ(parser->get("seeds"), "0-9");
  EXPECT_FALSE(parser->has("seeds"));
  EXPECT_TRUE(parser->has("steps"));
  EXPECT_FALSE(parser->has("out"));
  EXPECT_EQ(parser->get("out"), "");
  EXPECT_FALSE(parser->flag_set("quiet"));
}

// jobs/local.sh passes --out and --threads before the user's own options.
TEST(CliTest, TheLastOfARepeatedOptionWins) {
  auto parser = train_parser();
  ASSERT_TRUE(parse(parser.get(), {"--system", "harmonic", "--out", "a.h5", "--out", "b.h5",
                                   "--quiet", "--quiet"}));
  EXPECT_EQ(parser->get("out"), "b.h5");
  EXPECT_TRUE(parser->flag_set("quiet"));
}

TEST(CliTest, ValuesMayLookLikeNegativeNumbersOrFollowTheEndOfOptions) {
  auto parser = train_parser();
  ASSERT_TRUE(parse(parser.get(), {"--system", "harmonic", "--steps", "-4", "--lr", "-1e-3"}));
  EXPECT_EQ(parser->get_int("steps"), -4);
  EXPECT_EQ(parser->get_double("lr"), -1e-3);
  auto reduce = reduce_parser();
  ASSERT_TRUE(parse(reduce.get(), {"--", "-odd-name.h5"}));
  EXPECT_EQ(reduce->get("FILE"), "-odd-name.h5");
}

TEST(CliTest, NumbersAreBaseTenAndFinite) {
  auto parser = train_parser();
  ASSERT_TRUE(parse(parser.get(), {"--system", "harmonic", "--steps", "010", "--lr", "inf"}));
  EXPECT_EQ(parser->get_int("steps"), 10);  // not octal
  EXPECT_THAT([&] { parser->get_double("lr"); },
              ::testing::Throws<UsageError>(::testing::Field(
                  &UsageError::message, "phnn train: --lr = \"inf\" is not a finite number")));
  auto hex = train_parser();
  ASSERT_TRUE(parse(hex.get(), {"--system", "harmonic", "--steps", "0x10"}));
  EXPECT_THAT([&] { hex->get_int("steps"); },
              ::testing::Throws<UsageError>(::testing::Field(
                  &UsageError::message, "phnn train: --steps = \"0x10\" is not an integer")));
}

TEST(CliTest, AMisspelledOptionGetsTheClosestName) {
  auto parser = train_parser();
  EXPECT_EQ(usage_error(parser.get(), {"--system", "harmonic", "--sedes", "0-2"}),
            "phnn train: unknown option --sedes (did you mean --seeds?); see `phnn train --help`");
  auto with_value = reduce_parser();
  EXPECT_EQ(
      usage_error(with_value.get(), {"r.h5", "--fromat=csv"}),
      "phnn reduce: unknown option --fromat (did you mean --format?); see `phnn reduce --help`");
  auto single_dash = reduce_parser();
  EXPECT_THAT(usage_error(single_dash.get(), {"r.h5", "-format", "csv"}),
              HasSubstr("unknown option -format (did you mean --format?)"));
}

TEST(CliTest, AnUnknownOptionFarFromEveryNameGetsNoGuess) {
  auto parser = reduce_parser();
  EXPECT_EQ(usage_error(parser.get(), {"r.h5", "--colour", "red"}),
            "phnn reduce: unknown option --colour; see `phnn reduce --help`");
}

// A misspelled required option is reported as misspelled, not as missing.
TEST(CliTest, AnUnknownOptionComesBeforeAMissingRequiredOne) {
  auto parser = train_parser();
  EXPECT_THAT(usage_error(parser.get(), {"--sytem", "harmonic"}),
              HasSubstr("unknown option --sytem (did you mean --system?)"));
}

TEST(CliTest, MissingArgumentsAreNamedWithTheirHelp) {
  auto train = train_parser();
  EXPECT_EQ(usage_error(train.get(), {"--steps", "1"}),
            "phnn train: --system is required (harmonic | duffing | self-sustained)");
  auto reduce = reduce_parser();
  EXPECT_EQ(usage_error(reduce.get(), {"--format", "csv"}),
            "phnn reduce: missing argument FILE; see `phnn reduce --help`");
  auto last = train_parser();
  EXPECT_EQ(usage_error(last.get(), {"--system", "harmonic", "--out"}),
            "phnn train: --out needs a value");
}

TEST(CliTest, FlagsTakeNoValueAndExtraPositionalsAreRefused) {
  auto flag = train_parser();
  EXPECT_EQ(usage_error(flag.get(), {"--system", "harmonic", "--quiet=no"}),
            "phnn train: --quiet takes no value");
  auto extra = reduce_parser();
  EXPECT_EQ(usage_error(extra.get(), {"a.h5", "b.h5"}),
            "phnn reduce: unexpected argument \"b.h5\"; see `phnn reduce --help`");
}

// "--out --quiet" forgot the file name: CLI11 would take --quiet as it.
TEST(CliTest, AnOptionIsNotTakenAsTheValueOfTheOneBefore) {
  auto parser = train_parser();
  EXPECT_EQ(usage_error(parser.get(), {"--system", "harmonic", "--out", "--quiet"}),
            "phnn train: --out needs a value (got the option --quiet; a file of that name is "
            "./--quiet)");
  auto steps = train_parser();
  EXPECT_EQ(usage_error(steps.get(), {"--system", "--steps=10"}),
            "phnn train: --system needs a value (got the option --steps; a file of that name is "
            "./--steps=10)");
  auto fine = train_parser();  // a value that merely starts with dashes is kept
  parse(fine.get(), {"--system", "harmonic", "--out", "./--quiet"});
  EXPECT_EQ(fine->get("out"), "./--quiet");
}

TEST(CliTest, PositionalRestTakesEveryFurtherArgument) {
  auto merge_parser = [] {
    auto parser = std::make_unique<Parser>("merge", "Merges shards.");
    parser->positional("OUT", "new results file");
    parser->positional_rest("SHARD", "shard results files");
    return parser;
  };
  auto parser = merge_parser();
  ASSERT_TRUE(parse(parser.get(), {"out.h5", "a.h5", "b.h5"}));
  EXPECT_EQ(parser->get("OUT"), "out.h5");
  EXPECT_THAT(parser->rest(), ElementsAre("a.h5", "b.h5"));
  auto none = merge_parser();
  EXPECT_EQ(usage_error(none.get(), {"out.h5"}),
            "phnn merge: missing argument SHARD; see `phnn merge --help`");
}

TEST(CliTest, HelpListsEveryOptionWithItsDefaultAndParsesNothingElse) {
  auto parser = train_parser();
  ::testing::internal::CaptureStdout();
  EXPECT_FALSE(parse(parser.get(), {"--steps", "1", "--help"}));  // no --system: help all the same
  const std::string help = ::testing::internal::GetCapturedStdout();
  EXPECT_THAT(help, StartsWith("Trains one cell.\n"));
  EXPECT_THAT(help, HasSubstr("Usage: phnn train [OPTIONS]"));
  EXPECT_THAT(help, HasSubstr("--system VALUE REQUIRED"));
  EXPECT_THAT(help, HasSubstr("--seeds VALUE=0-9"));
  EXPECT_THAT(help, HasSubstr("model seeds, e.g. 0-9 or 0,3,5"));
  EXPECT_THAT(help, HasSubstr("--quiet"));
}

TEST(CliTest, IntListsExpandRangesAndCapTheirLengthBeforeExpanding) {
  EXPECT_THAT(parse_int_list("seeds", "0-2,7"), ElementsAre(0, 1, 2, 7));
  EXPECT_THAT(parse_int_list("seeds", "5"), ElementsAre(5));
  EXPECT_THAT(parse_int_list("ranks", "2,16,128"), ElementsAre(2, 16, 128));
  for (const char* bad : {"", "3-1", "-1", "1-", "a", "0-2147483648", "1,,2"}) {
    EXPECT_THAT([&] { parse_int_list("seeds", bad); },
                ::testing::Throws<UsageError>(::testing::Field(
                    &UsageError::message,
                    "--seeds = \"" + std::string(bad) +
                        "\": expected integers in [0, 2147483647] like 0-9 or 0,3,5")))
        << bad;
  }
  EXPECT_THAT([] { parse_int_list("seeds", "0-99999,5"); },
              ::testing::Throws<UsageError>(
                  ::testing::Field(&UsageError::message, HasSubstr("more than 100000 values"))));
}

// The binary: commands, --help, --version and their exit statuses.
int phnn(const std::string& args, std::string* output) {
  return testing_util::run_shell(std::string(PHNN_BINARY) + " " + args, output);
}

TEST(PhnnCommandLineTest, AnUnknownCommandExitsTwoWithTheClosestName) {
  std::string log;
  EXPECT_EQ(phnn("trian --steps 1", &log), kUsageError);
  EXPECT_EQ(log,
            "phnn: unknown command \"trian\" (did you mean train?); expected one of: data, import, "
            "train, sweep, reduce, merge, eval, verify\n");
  EXPECT_EQ(phnn("--verison", &log), kUsageError);
  EXPECT_THAT(log, HasSubstr("(did you mean --version?)"));
  EXPECT_EQ(phnn("plot", &log), kUsageError);
  EXPECT_THAT(log, Not(HasSubstr("did you mean")));
}

TEST(PhnnCommandLineTest, AMisspelledOptionExitsTwoBeforeAnyWork) {
  std::string log;
  EXPECT_EQ(phnn("reduce /nonexistent-dir/r.h5 --per-rnu", &log), kUsageError);
  EXPECT_EQ(log,
            "phnn reduce: unknown option --per-rnu (did you mean --per-run?); see `phnn "
            "reduce --help`\n");
  EXPECT_EQ(phnn("data --system harmonic --out /nonexistent-dir/d.h5 --n-trian 5", &log),
            kUsageError);
  EXPECT_THAT(log, HasSubstr("unknown option --n-trian (did you mean --n-train?)"));
}

TEST(PhnnCommandLineTest, EveryCommandHasItsHelp) {
  for (const char* command : {"data", "import", "train", "sweep", "reduce", "merge", "eval"}) {
    std::string log;
    EXPECT_EQ(phnn(std::string(command) + " --help", &log), 0) << command;
    EXPECT_THAT(log, HasSubstr(std::string("Usage: phnn ") + command)) << log;
  }
  std::string log;
  EXPECT_EQ(phnn("", &log), kUsageError);
  EXPECT_THAT(log, StartsWith("usage: phnn <command> [options]"));
  EXPECT_EQ(phnn("-h", &log), 0);
  EXPECT_THAT(log, HasSubstr("merge the shard results files"));
}

}  // namespace
}  // namespace cli
}  // namespace phnn

namespace phnn {
namespace {

// "phnn sweep: phnn sweep: ..." no more: a message already prefixed keeps one.
TEST(WithPrefixTest, PrefixesOnce) {
  EXPECT_EQ(cli::with_prefix("phnn sweep: ", "x.toml:3: bad"), "phnn sweep: x.toml:3: bad");
  EXPECT_EQ(cli::with_prefix("phnn sweep: ", "phnn sweep: x.toml:3: bad"), "phnn sweep: x.toml:3: bad");
  EXPECT_EQ(cli::with_prefix("phnn sweep: ", "phnn sweepx"), "phnn sweep: phnn sweepx");
}

// A failing merge printed "phnn merge: " on stdout before its error (the
// summary's first words, flushed at exit): one prefix, in a job log too.
TEST(WithPrefixTest, AFailedMergeSaysItsNameOnce) {
  std::string log;
  const std::string out = ::testing::TempDir() + "phnn_merge_prefix_" + std::to_string(::getpid());
  EXPECT_EQ(testing_util::run_shell(std::string(PHNN_BINARY) + " merge " + out +
                                        ".h5 /nonexistent/shard.h5",
                                    &log),
            1);
  EXPECT_THAT(log, ::testing::HasSubstr("/nonexistent/shard.h5: no such results file"));
  EXPECT_EQ(log.find("phnn merge:"), log.rfind("phnn merge:")) << log;
}

}  // namespace
}  // namespace phnn
