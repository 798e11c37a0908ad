// include/phnn/sweep/sweep_file.h — sweep files: what a sweep trains.
#pragma once

#include <cstddef>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "phnn/common/enum_names.h"
#include "phnn/config/model_config.h"
#include "phnn/config/system_file_text.h"
#include "phnn/config/trainer_options.h"
#include "phnn/data/dataset.h"
#include "phnn/systems/oscillators.h"

namespace phnn {

/// A sweep file that cannot be used. what() is "FILE:LINE: message" (line 1
/// for problems of the whole file, such as a missing `name`), or
/// "FILE: message" when the file cannot be read at all. The message names the
/// offending key or value and, where there is a finite set, the allowed ones:
///
///   sweeps/x.toml:14: unknown integrator "rk4" in models value "phnn-s-rk4";
///   expected one of: node-rk2, phnn-jr-dg, phnn-jr-rk2, phnn-s-dg, phnn-s-rk2
class SweepFileError : public std::invalid_argument {
 public:
  /// line <= 0: the error concerns the file as a whole and has no line.
  SweepFileError(const std::string& file, int line, const std::string& message);

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  /// The message without the "FILE:LINE: " prefix.
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  int line_;
  std::string message_;
};

/// One study: the axes a grid is built from (the [grid] table, overridden by
/// the study's own [study.NAME] table). Every axis is non-empty and free of
/// duplicates; values keep the order of the file.
struct StudySpec {
  /// NAME of [study.NAME], or "grid" when the file has no [study.*] table.
  std::string name;
  /// Optional human-readable title (paper's study caption).
  std::string title;
  /// System names: a built-in system ("duffing") or the `name` of a system
  /// file of SweepSpec::system_files ("coupled-duffing").
  std::vector<std::string> systems;
  /// Formulation-integrator pairs, e.g. {kPhnnJr, kDg} for "phnn-jr-dg".
  std::vector<std::pair<ModelKind, IntegratorKind>> models;
  std::vector<ModelSize> sizes;
  /// N_train values, each in [1, DatasetOptions::num_train_max].
  std::vector<int> n_train;
  std::vector<Regularizer> regularizers;
  /// Regularizer weights λ (`lambdas`, each >= 0, docs/METHOD.md §4): a run
  /// with regularizer cn, sn or sr is made once per value, which replaces its
  /// lambda_cn, lambda_sn or lambda_sr; runs without a regularizer are not
  /// multiplied. Empty (the default): the single weight of [training].
  std::vector<double> lambdas;
  /// Model-initialization seeds, each >= 0.
  std::vector<int> seeds;
};

/// A system file named in a sweep file's `systems` (a value ending in ".toml"
/// or containing '/', relative to the sweep file): its text is part of the
/// sweep (stored in the results file, hashed into SweepSpec::text_hash and
/// into every run id), so a changed file is a different sweep.
struct SweepSystemFile {
  /// The value as written in `systems` ("systems/coupled-duffing.toml").
  std::string entry;
  /// The file's `name`: the system's name in runs, tables and /data.
  std::string name;
  /// The whole file, and hex64(fnv1a64(text)).
  std::string text, text_hash;
  /// States, dissipation ports and inputs of the system.
  int n_x = 0, n_w = 0, n_u = 0;
  /// A data-set file of `data` (entry ends in ".h5"): its system file is the
  /// text stored in it, `name` the file's stem, text_hash also covers the
  /// checksum of its contents (a changed data file makes different runs),
  /// and its runs train and infer on the file's splits. `path` is where it
  /// was read (relative entries resolved against the sweep file).
  std::string data_checksum, path;
  int data_train_pairs = 0;
  /// Its inference trajectories and the samples of the longest.
  int data_inference = 0, data_inference_points = 0;
  bool is_data() const { return !data_checksum.empty(); }
};

/// One side of an [adaptive] comparison: the cell of `system` with these
/// n_train, size and regularizer, and of `models` the one whose median is
/// smallest (one model: that cell). Written "system/models/n_train/size/
/// regularizer", models joined by '+': "duffing/phnn-s-dg+phnn-s-rk2/25/small/none".
struct CellSelector {
  std::string text;  // as written
  std::string system;
  std::vector<std::pair<ModelKind, IntegratorKind>> models;
  int n_train = 0;
  ModelSize size = ModelSize::kSmall;
  Regularizer regularizer = Regularizer::kNone;
};

/// Two cells whose medians a question compares (e.g. one of the paper's
/// statements): unresolved while their bootstrap intervals overlap.
struct SeedComparison {
  CellSelector a, b;
  int line = 0;  // of the comparison in the sweep file
};

/// Which cells an adaptive sweep gives more seeds after a round
/// (docs/METHOD.md, "Adaptive seeds").
enum class AdaptiveRule {
  /// In every column of every study table, the cells the reducer marks
  /// (tie): the best median and those whose interval overlaps its interval.
  kColumnBest,
  /// Both cells of every comparison of `comparisons` whose intervals overlap.
  kComparisons,
};
inline constexpr EnumNames<AdaptiveRule, 2> kAdaptiveRuleNames{
    "rule", {{{AdaptiveRule::kColumnBest, "column-best"}, {AdaptiveRule::kComparisons, "comparisons"}}}};
inline std::string to_string(AdaptiveRule rule) { return kAdaptiveRuleNames.name(rule); }
inline std::vector<AdaptiveRule> all_adaptive_rules() { return kAdaptiveRuleNames.all(); }

/// The [adaptive] table: round 0 trains the studies' `seeds`; after each
/// finished round `rule` names cells, each of which gets the next `batch`
/// seed numbers (above its largest), up to `max_seeds` per cell; the sweep
/// ends when the rule names no cell that can grow.
struct AdaptiveSpec {
  bool enabled = false;
  int max_seeds = 0, batch = 0;
  AdaptiveRule rule = AdaptiveRule::kColumnBest;
  std::vector<SeedComparison> comparisons;
  /// rule comparisons only: skip an unresolved comparison that max_seeds is
  /// not expected to resolve — intervals reading: one cell's median lies
  /// inside the other's interval narrowed about its median by
  /// sqrt(finished / max_seeds); four-way reading: the effect's interval so
  /// narrowed would still be neither inside the margin nor clear of 0
  /// (docs/METHOD.md, "Adaptive seeds").
  bool futility = false;
  /// rule comparisons only: false (grow = "both"): both cells of an
  /// unresolved comparison get seeds; true (grow = "one"): only the one
  /// whose next batch is expected to close more of the gap between the two
  /// intervals per estimated core-second (docs/METHOD.md, "Adaptive seeds").
  bool grow_one = false;
  /// `stop_confidence`: a comparison (column-best: a cell against its
  /// column's best) stops getting seeds before max_seeds only when its
  /// intervals at this confidence are disjoint; the tables, the verdicts and
  /// the futility projection keep the reducer's confidence (0.95). Above it,
  /// an early resolution must be clear, not marginal (an interim boundary
  /// stricter than the final one, docs/METHOD.md "Adaptive seeds"). 0: the
  /// reducer's confidence.
  double stop_confidence = 0;
  /// `reading`, rule comparisons only: false ("intervals"): a comparison
  /// stops when the bootstrap intervals of its two medians are disjoint;
  /// true ("four-way"): when compare_cells (phnn/report/comparison.h) reads
  /// it as A better, B better or equivalent within x delta; an undecided
  /// comparison names both cells (a paired one needs both for its pairs;
  /// grow = "one" still picks one side of an unpaired one); with futility,
  /// also when max_seeds is not expected to read it.
  bool four_way = false;
  /// `delta`: the equivalence margin of the four-way reading, a factor on
  /// the MSE (> 1; ComparisonOptions::delta).
  double delta = 1.5;
  /// The studies' `seeds` as written (every study has the same): round 0.
  /// With [adaptive], StudySpec::seeds holds these and then the
  /// max_seeds - initial_seeds.size() next seed numbers (the runs a cell may get).
  std::vector<int> initial_seeds;
};

/// [search]: successive halving over settings (sweeps/FORMAT.md, docs/METHOD.md
/// "Search"). A configuration is a cell without its step budget: a model,
/// size, N_train, regularizer, weight and one `variants` entry. Every
/// configuration trains its seeds to rungs[0] steps; of each study's
/// configurations on a system, the best ceil(n / eta) by the median over
/// seeds of the best validation loss go on to the next rung, from their
/// saved training state, and so on to the last rung.
struct SearchSpec {
  bool enabled = false;
  /// Step budgets, strictly increasing, each a multiple of eval_every (so
  /// training on from a rung equals training straight through).
  std::vector<int> rungs;
  /// Each rung keeps ceil(n / eta); eta = 1 keeps every configuration (the
  /// full grid a search is checked against: the same runs).
  int eta = 3;
  /// The search axes: [training] keys given a list of values in [search],
  /// in file order (e.g. "learning_rate").
  std::vector<std::string> axes;
  /// [training] with one value of every axis set, for every combination
  /// (the first axis slowest); one entry (the [training] table) without axes.
  std::vector<TrainerOptions> variants;
  /// "learning_rate=0.001/batch_size=32" per variant ("" without axes).
  std::vector<std::string> variant_labels;
};

/// A parsed and validated sweep file: docs/METHOD.md defaults overridden by the file.
///
///   const SweepSpec spec = parse_sweep_file("sweeps/paper.toml");
///   const Grid grid = expand_grid(spec);  // phnn/sweep/grid.h
struct SweepSpec {
  /// `name` (required).
  std::string name;
  /// `output`: default results-file path (the CLI may override it);
  /// "results/<name>.h5" when the file does not set it.
  std::string output;
  /// Path the file was read from (the display name for parse_sweep_text).
  std::string source_path;
  /// The file's full text, stored verbatim in the results file.
  std::string text;
  /// hex64(fnv1a64(text)): identifies the exact file a results file came from.
  std::string text_hash;
  /// Physical parameters of every system (all three are present, whether or
  /// not a study uses them): OscillatorOptions::defaults(kind) overridden by
  /// [physics.<system>].
  std::map<SystemKind, OscillatorOptions> physics;
  /// DatasetOptions{} overridden by [data].
  DatasetOptions data;
  /// TrainerOptions{} overridden by [training].
  TrainerOptions training;
  /// The studies in file order (at least one).
  std::vector<StudySpec> studies;
  /// System files of the `systems` axes, in order of first appearance (each
  /// once; their names differ from each other and from the built-ins').
  std::vector<SweepSystemFile> system_files;
  /// [adaptive]; enabled = false without it.
  AdaptiveSpec adaptive;
  /// [search]; enabled = false without it.
  SearchSpec search;

  /// The system file named `name`, or nullptr for a built-in system.
  const SweepSystemFile* system_file(const std::string& name) const;
};

/// Largest sweep file, in bytes: its text is stored verbatim in one HDF5
/// attribute of the results file (an object header message < 64 KiB).
constexpr std::size_t kMaxSweepFileBytes = 60000;

/// Reads and parses a sweep file (format: sweeps/FORMAT.md); system files
/// named in `systems` are read relative to the sweep file's directory. Throws
/// SweepFileError naming the path, without waiting or reading past the cap,
/// if it cannot be opened, is not a regular file (a FIFO, /dev/zero, a
/// directory) or has more than kMaxSweepFileBytes bytes; otherwise the line
/// of the first problem.
SweepSpec parse_sweep_file(const std::string& path);

/// Parses sweep-file text; `display_name` is used in error messages and as
/// SweepSpec::source_path; `read_system_file` supplies the system files it
/// names (without one, a system file in `systems` is an error). Throws
/// SweepFileError (also for a text over kMaxSweepFileBytes), for a bad
/// system file with the system file's own FILE:LINE.
SweepSpec parse_sweep_text(const std::string& text, const std::string& display_name,
                           const SystemFileReader& read_system_file = {});

/// hex64 of the sweep text alone when it names no system file, else of the
/// text followed by each system file's entry and text (and a data-set file's
/// checksum) (SweepSpec::text_hash).
std::string sweep_hash(const std::string& text, const std::vector<SweepSystemFile>& files);

/// "node-rk2", "phnn-jr-dg", ...: the sweep-file spelling of a model.
std::string model_key(ModelKind kind, IntegratorKind integrator);
/// The five valid pairs in the order node-rk2, phnn-jr-dg, phnn-jr-rk2,
/// phnn-s-dg, phnn-s-rk2 (NODE has RK2 only, docs/METHOD.md §3).
std::vector<std::pair<ModelKind, IntegratorKind>> all_model_pairs();
/// Every pair a sweep file may name: the paper's five, then every other
/// model each integrator of the table allows (all_integrators(); NODE: no
/// discrete gradient), today node-rk4, phnn-jr-rk4, phnn-s-rk4, phnn-jr-dg4,
/// phnn-s-dg4.
std::vector<std::pair<ModelKind, IntegratorKind>> known_model_pairs();
/// model_key of each of known_model_pairs(), in its order.
std::vector<std::string> known_model_keys();

}  // namespace phnn
