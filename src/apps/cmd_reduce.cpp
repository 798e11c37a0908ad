// src/apps/cmd_reduce.cpp — `phnn reduce results.h5`: the paper's Appendix-F
// tables (median, or with --stat iqm the interquartile mean, [IQR] and
// bootstrap interval of the inference MSE over seeds), the seeds-per-mode view, or one CSV row per run, from a results
// file, complete or partial; --round K and --rule SWEEP show an adaptive
// sweep after round K or under another rule (apps/reduce_rule.h);
// --comparisons the pairs of cells a table invites (report/table_comparisons.h),
// with --seed-lists on resamples of the seeds (apps/reduce_seed_lists.h);
// the per-run records: apps/reduce_records.h.
// Size: one command whose five views (tables, per-run, seeds summary,
// comparisons, rungs) share one read of the file.
#include <algorithm>
#include <iostream>
#include <limits>
#include <optional>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/reduce_records.h"
#include "apps/reduce_rule.h"
#include "apps/reduce_seed_lists.h"
#include "phnn/report/per_run.h"
#include "phnn/report/table_comparisons.h"
#include "phnn/report/tables.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/adaptive.h"
#include "phnn/sweep/search.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace apps {
namespace {

// Why the file cannot be reduced as it stands, naming the damage: its
// structure (a status out of range, an empty or repeated id), then (rule 2)
// the objects its digests find damaged. "" if neither.
std::string named_damage(const ResultsFile& file) {
  const std::vector<std::string> problems = file.structure_problems();
  if (!problems.empty()) return problems.front();
  std::string objects;
  for (const ResultsFile::Damage& d : file.file_damage()) {
    if (d.object.rfind("/data/", 0) == 0) continue;  // the tables do not read /data
    objects += (objects.empty() ? "" : "; ") + d.object + ": " + d.what;
  }
  return objects;
}

[[noreturn]] void refuse_damaged(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": damaged: " + what + "; `phnn verify " + path + "` names "
                           "each damage and its repair, and `phnn sweep` with the file's sweep "
                           "file repairs it");
}

// The grid of the file's sweep text, checked row by row against /runs/id.
// A mismatch is damage (the stored text, its hash or the id column; rule 2's
// digests say which), not another phnn version: ids are hashes of the runs'
// configurations, the same in every version that reads the format.
Grid checked_grid(const ResultsFile& file, const SweepSpec& spec) {
  const std::string& path = file.path();
  Grid grid = expand_grid(spec);
  const auto ids = file.read_run_ids();
  std::string mismatch;
  if (ids.size() != grid.runs.size()) {
    mismatch = "/runs/id holds " + std::to_string(ids.size()) + " runs, the stored sweep text " +
               "expands to " + std::to_string(grid.runs.size());
  }
  for (std::size_t i = 0; mismatch.empty() && i < ids.size(); ++i) {
    if (ids[i] != grid.runs[i].id()) {
      mismatch = "/runs/id[" + std::to_string(i) + "] = " + ids[i] +
                 ", the stored sweep text gives " + grid.runs[i].id();
    }
  }
  if (mismatch.empty()) return grid;
  if (spec.text_hash != file.sweep_hash()) {
    mismatch += "; the stored sweep text hashes to " + spec.text_hash + ", @sweep_hash says " +
                file.sweep_hash();
  }
  const std::string named = named_damage(file);
  refuse_damaged(path, named.empty() ? mismatch : named + " (" + mismatch + ")");
}

// Rows whose checksum fails, named on stderr; the tables count them as
// pending (their numbers cannot be trusted).
std::vector<int> damaged_rows_named(const ResultsFile& file) {
  const std::vector<int> damaged = file.damaged_rows();
  if (damaged.empty()) return damaged;
  const std::vector<std::string> ids = file.read_run_ids();
  std::cerr << "phnn reduce: warning: " << file.path() << ": " << damaged.size()
            << " damaged rows left out, counted as pending:";
  for (int row : damaged) {
    std::cerr << " " << ids[static_cast<std::size_t>(row)] << " (row " << row << ")";
  }
  std::cerr << "; `phnn verify` tells which the journals can repair, `phnn sweep` repairs them\n";
  return damaged;
}

// `statuses`: of the runs the tables cover (an adaptive sweep's: those its
// rounds asked for).
void print_markdown_preamble(const ResultsFile& file, const SweepSpec& spec,
                             const std::vector<RunStatus>& statuses, bool seeds_summary,
                             CellStatistic statistic) {
  int counts[4] = {0, 0, 0, 0};
  for (RunStatus s : statuses) ++counts[static_cast<int>(s)];
  std::cout << "# " << spec.name << " — " << file.path() << "\n\n"
            << counts[1] << " done, " << counts[2] << " diverged, " << counts[3] << " failed, "
            << counts[0] << " pending of " << statuses.size() << " runs"
            << (spec.adaptive.enabled ? " asked for" : "") << ". ";
  if (seeds_summary) {
    std::cout << "Cells: seeds whose inference MSE (Eq. 31) lies below / above the column's "
                 "geometric midpoint m; (d=k) diverged runs (counted above), (n=k/N) finished "
                 "of expected.\n\n";
    return;
  }
  const std::string m = statistic == CellStatistic::kIqm ? "IQM" : "median";
  std::cout << "Cells: " << (statistic == CellStatistic::kIqm ? "IQM (interquartile mean: the "
                             "mean of the middle half of the sorted seeds)" : "median")
            << " [IQR] (bootstrap 95 % interval of the " << m << ") of the inference MSE (Eq. 31) "
            << "over seeds; **bold** = best " << m << " of its column, its interval overlapping "
            << "no other; (tie) = best " << m << " whose interval overlaps others', and those "
            << "others; (d=k) diverged runs (MSE +inf, included), (n=k/N) finished of "
            << "expected.\n\n";
}

// --round K: the last round (rung) replayed; -1 without it: all.
int last_round(const cli::Parser& parser) {
  return parser.has("round") ? parser.get_int_in("round", 0, 1 << 20) : -1;
}

// An adaptive sweep's rounds (up to --round K): the runs they asked for,
// each cell expecting its own number of seeds. Nothing for other sweeps.
std::optional<AdaptiveState> adaptive_rounds(const SweepSpec& spec, const Grid& grid,
                                             const std::vector<RunStatus>& statuses,
                                             const std::vector<double>& mse,
                                             const cli::Parser& parser, const std::string& path) {
  if (spec.search.enabled) return std::nullopt;  // search_rungs
  if (!spec.adaptive.enabled) {
    if (parser.has("round")) {
      throw cli::UsageError{"phnn reduce: --round: " + path + " is not an adaptive sweep (its "
                            "sweep file has no [adaptive] table); drop --round"};
    }
    return std::nullopt;
  }
  const int last = last_round(parser);
  AdaptiveState state = replay_adaptive_rounds(spec, grid, statuses, mse, {}, last);
  if (last > state.round || (last == state.round && state.pending > 0)) {
    std::cerr << "phnn reduce: warning: --round " << last << ": " << path
              << (state.complete ? " ended after round " + std::to_string(state.round)
                                 : " is in round " + std::to_string(state.round) + ", " +
                                       std::to_string(state.pending) + " of its runs pending")
              << "; the tables show that\n";
  }
  return state;
}

// Where an adaptive sweep stands, under the preamble.
// `replayed`: the --rule sweep file whose [adaptive] table was replayed, or "".
void print_adaptive_preamble(const SweepSpec& spec, const AdaptiveState& state,
                             const std::string& replayed) {
  if (!replayed.empty()) {
    std::cout << "Replayed: the [adaptive] table of " << replayed << " on this file's runs "
              << "(the runs that sweep would have trained, where the file holds them).\n\n";
  }
  std::cout << "Adaptive seeds (rule " << to_string(spec.adaptive.rule) << ", "
            << spec.adaptive.initial_seeds.size() << " seeds per cell, then " << spec.adaptive.batch
            << " more per round where the rule asks, at most " << spec.adaptive.max_seeds << "): "
            << (state.complete ? "complete after round " : "up to round ") << state.round
            << "; " << state.active_runs() << " runs asked for; the other pending runs are seeds "
            << "no round asked for, left out of the tables.";
  if (state.trained_ahead > 0) {
    std::cout << " " << state.trained_ahead << " finished runs no round " << (state.complete ? "" : "so far ")
              << "asked for (" << (state.complete ? "" : "asked for by a later round, ")
              << "trained ahead while a round drained, or asked for by another rule): left out of "
                 "the tables too.";
  }
  if (!state.cells_grown.empty()) {
    std::cout << " Cells given more seeds after round 0, 1, ...:";
    for (std::size_t k = 0; k < state.cells_grown.size(); ++k) {
      std::cout << (k == 0 ? " " : ", ") << state.cells_grown[k];
    }
    std::cout << ".";
  }
  std::cout << "\n\n";
}

// The runs the tables cover: the file's sweep, or with --rule another sweep
// file's grid, each run read from the file's row that holds it (view.row).
struct Inputs {
  Grid own_grid;  // of the file's sweep text
  RuleView view;
  std::vector<int> damaged;
  std::vector<RunStatus> statuses;
  std::vector<double> mse;
};

Inputs read_inputs(const ResultsFile& file, const cli::Parser& parser) {
  const std::string& path = file.path();
  Inputs in;
  in.damaged = damaged_rows_named(file);
  auto statuses = file.read_statuses();
  for (int row : in.damaged) statuses[static_cast<std::size_t>(row)] = RunStatus::kPending;
  auto mse = file.read_double_column("mse");
  SweepSpec own;
  try {
    own = parse_sweep_text(file.sweep_text(), path + "@sweep_text", file.stored_system_files());
  } catch (const std::exception& e) {
    const std::string named = named_damage(file);
    refuse_damaged(path, named.empty() ? e.what() : named + " (" + e.what() + ")");
  }
  in.own_grid = checked_grid(file, own);
  if (!parser.has("rule")) {
    in.view.spec = own;
    in.view.grid = in.own_grid;
    in.view.row.resize(statuses.size());
    for (std::size_t i = 0; i < statuses.size(); ++i) in.view.row[i] = static_cast<int>(i);
    in.statuses = std::move(statuses);
    in.mse = std::move(mse);
    return in;
  }
  in.view = rule_view(file, parser.get("rule"));
  in.statuses = through_view(in.view, statuses, RunStatus::kPending);
  in.mse = through_view(in.view, mse, std::numeric_limits<double>::quiet_NaN());
  return in;
}

// A [search] sweep's rungs as far as decided (up to --round K), from its
// best validation losses (read only then); nothing for other sweeps. A
// --rule view is never a search (a rule has [adaptive], which excludes
// [search]), so the rows are the file's.
std::optional<SearchReplay> search_rungs(const ResultsFile& file, const SweepSpec& spec,
                                         const Grid& grid, const Inputs& in,
                                         const cli::Parser& parser) {
  if (!spec.search.enabled) return std::nullopt;
  return replay_search(spec, grid, in.statuses, file.read_double_column("best_validation_loss"),
                       in.mse, last_round(parser));
}

// --rule: a replay that stops at a round the file cannot finish says so.
void warn_unfinished_replay(const Inputs& in, const AdaptiveState& state,
                            const cli::Parser& parser, const std::string& path) {
  if (!parser.has("rule") || state.complete || state.pending == 0) return;
  std::vector<std::string> lacking;
  for (std::size_t i = 0; i < state.active.size(); ++i) {
    if (state.active[i] && in.view.row[i] < 0) lacking.push_back(in.view.grid.runs[i].id());
  }
  std::cerr << "phnn reduce: warning: --rule " << parser.get("rule") << ": its round "
            << state.round << " needs " << state.pending << " runs that " << path
            << " has not finished (" << lacking.size() << " of them not in it at all";
  for (std::size_t k = 0; k < std::min<std::size_t>(lacking.size(), 3); ++k) {
    std::cerr << (k == 0 ? ": " : ", ") << lacking[k];
  }
  std::cerr << (lacking.size() > 3 ? ", ..." : "") << "); the tables show the replay up to "
            << "there. To go on, train them on a copy: `cp " << path << " F.h5 && phnn sweep "
            << parser.get("rule") << " --out F.h5` (refused if the rule's grid lacks runs "
            << path << " finished)\n";
}

// A record's results made unknown: pending, every double NaN, `message`.
void forget_results(RunRecord* r, const std::string& message) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r->result = RunResult{};
  for (const ResultColumn& c : result_columns()) {
    if (c.type == ResultColumn::Type::kDouble) c.set_double(r->result, nan);
  }
  r->result.message = message;
  r->trace_points = 0;
  r->initial_validation_loss = r->final_train_loss = r->final_validation_loss = nan;
  r->final_kappa = r->final_sigma_max = r->final_rho = nan;
  r->checkpoint_steps.clear();
  r->checkpoint_mse.clear();
  r->checkpoint_train_seconds.clear();
}

// One record per run of the view (a run the file lacks: pending, its
// configuration from the grid). A damaged row reads as pending with
// unknown results (its stored numbers are not to be trusted).
std::vector<RunRecord> view_records(const ResultsFile& file, const Inputs& in) {
  std::vector<RunRecord> rows = read_run_records(file, in.own_grid);
  for (int row : in.damaged) {
    forget_results(&rows[static_cast<std::size_t>(row)],
                   "damaged row: `phnn verify " + file.path() + "` names the damage");
  }
  std::vector<RunRecord> records(in.view.row.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (in.view.row[i] >= 0) {
      records[i] = rows[static_cast<std::size_t>(in.view.row[i])];
      continue;
    }
    const RunConfig& run = in.view.grid.runs[i];
    RunRecord& r = records[i];
    r.id = run.id();
    r.canonical = run.canonical();
    r.model_label = model_label(run.model, run.integrator);
    for (const std::string& s : in.view.grid.run_studies[i]) {
      r.studies += (r.studies.empty() ? "" : ",") + s;
    }
    forget_results(&r, "not in " + file.path());
  }
  return records;
}

// The options of `phnn reduce` beyond FILE (the views and the replay).
void declare_options(cli::Parser* p) {
  cli::Parser& parser = *p;
  parser.option("format", "markdown | latex | csv", "markdown");
  parser.option("stat",
                "median | iqm: what the tables' cells show and rank by, the median or the "
                "interquartile mean (25 % trimmed mean; a cell with more than a quarter of its "
                "seeds diverged has IQM inf), each with its bootstrap 95 % interval",
                "median");
  parser.flag("seeds-summary",
              "instead of the statistics, count per cell the seeds below / above the column's "
              "geometric midpoint of the MSE (shows bimodal cells)");
  parser.flag("per-run",
              "one row per run as CSV (every configuration key, status, MSE, best step, wall "
              "time, ...) instead of the tables");
  parser.option("round",
                 "adaptive sweeps: the tables as they stood after round K (0: every cell at its "
                 "first seeds)");
  parser.flag("named",
              "adaptive sweeps of the comparisons rule: instead of the tables, the cells each "
              "comparison names after round K (--round; else the last) as CSV: comparison, line, "
              "cell (of a round in progress: what its finished runs name)");
  parser.option("rule",
                "adaptive sweeps: replay the [adaptive] table of sweep file SWEEP (same grid, "
                "another rule, batch or max_seeds) on FILE's runs instead of FILE's own; the "
                "runs it asks for that FILE lacks count as pending");
  parser.flag("comparisons",
              "instead of the tables, compare the cells of each table as CSV: in each column "
              "every pair of models, in each row every column against the first (effect = "
              "median log10 MSE ratio, paired by seed where the runs share weights, batches and "
              "data, with its interval, P(A < B), and the reading A better / B better / "
              "equivalent / undecided; docs/METHOD.md \"Comparisons\")");
  parser.option("delta", "--comparisons: the equivalence margin, a factor on the MSE (> 1)",
                "1.5");
  parser.option("seed-lists",
                "--comparisons: a text file with one comma-separated list of seeds per line "
                "(repeats allowed: a bootstrap resample of the seeds); prints the comparisons "
                "of every list, slot j of a list holding its j-th seed in every cell (pairs "
                "stay paired), with a first column `list` (1, 2, ...)");
}

// Which view reduce prints, checked: one of the tables (in `format`),
// --per-run, --seeds-summary or --comparisons.
struct View {
  bool per_run = false, seeds_summary = false, comparisons = false;
  TableFormat format = TableFormat::kMarkdown;
  CellStatistic statistic = CellStatistic::kMedian;
  ComparisonOptions comparison;
};

View read_view(const cli::Parser& parser) {
  View v;
  v.per_run = parser.flag_set("per-run");
  v.seeds_summary = parser.flag_set("seeds-summary");
  v.comparisons = parser.flag_set("comparisons");
  if (parser.has("seed-lists") && !v.comparisons) {
    throw cli::UsageError{"phnn reduce: --seed-lists needs --comparisons (it resamples the "
                          "seeds of the comparisons only)"};
  }
  if (v.comparisons + v.per_run + v.seeds_summary > 1) {
    throw cli::UsageError{"phnn reduce: --comparisons, --per-run and --seeds-summary exclude "
                          "each other; pass one of them"};
  }
  try {
    v.statistic = parse_cell_statistic(parser.get("stat"));
  } catch (const std::invalid_argument& e) {
    throw cli::UsageError{std::string("phnn reduce: --stat: ") + e.what()};
  }
  if (parser.has("stat") && (v.per_run || v.seeds_summary || v.comparisons)) {
    throw cli::UsageError{"phnn reduce: --stat chooses the tables' statistic; --per-run, "
                          "--seeds-summary and --comparisons do not use it: drop --stat"};
  }
  v.comparison.delta = parser.get_double("delta");
  if (!(v.comparison.delta > 1.0)) {
    throw cli::UsageError{"phnn reduce: --delta " + parser.get("delta") +
                          " must be greater than 1 (a factor on the MSE: 1.5 reads cells within "
                          "x1.5 of each other as equivalent)"};
  }
  // --per-run writes CSV: it needs no --format csv, only refuses another one.
  v.format = v.per_run && !parser.has("format") ? TableFormat::kCsv
                                                : parse_table_format(parser.get("format"));
  if (v.per_run && v.format != TableFormat::kCsv) {
    throw cli::UsageError{"phnn reduce: --per-run writes CSV only; drop --format " +
                          parser.get("format") + " (or give --format csv)"};
  }
  return v;
}

// --per-run: a row per run (of an adaptive or search sweep: those its rounds
// asked for, `asked`).
void print_per_run(const ResultsFile& file, const Inputs& in, const AdaptiveState* asked) {
  std::vector<RunRecord> records = view_records(file, in);
  if (asked) {
    std::vector<RunRecord> kept;
    for (std::size_t i = 0; i < records.size(); ++i) {
      if (asked->active[i]) kept.push_back(std::move(records[i]));
    }
    records = std::move(kept);
  }
  std::cout << render_per_run_csv(records);
}

}  // namespace

int run_reduce(int argc, char** argv, int first) {
  cli::Parser parser(
      "reduce",
      "Prints, for each study and system of the sweep that wrote FILE, a table with\n"
      "rows = models, columns = the study's varied axis and cells = median [IQR]\n"
      "(low, high) of the inference MSE over seeds: quartiles by numpy's default linear\n"
      "interpolation, (low, high) a percentile-bootstrap 95 % interval of the median\n"
      "(100 000 resamples, fixed seed). The best median of a column is bold only if its\n"
      "interval overlaps no other cell's; otherwise the overlapping cells are marked\n"
      "(tie). --stat iqm: the interquartile mean in place of the median. Works on\n"
      "partial files: missing and diverged runs are counted.");
  parser.positional("FILE", "results file written by `phnn sweep`");
  declare_options(&parser);
  if (!parser.parse(argc, argv, first)) return 0;
  const View view = read_view(parser);
  const bool per_run = view.per_run, seeds_summary = view.seeds_summary;
  const TableFormat format = view.format;
  const std::string path = parser.get("FILE");
  const ResultsFile file = ResultsFile::open_read_only(path);
  if (const auto problems = file.structure_problems(); !problems.empty()) {
    refuse_damaged(path, problems.front());
  }
  const Inputs in = read_inputs(file, parser);
  const SweepSpec& spec = in.view.spec;
  const Grid& grid = in.view.grid;
  const std::vector<RunStatus>& statuses = in.statuses;
  const std::optional<SearchReplay> search = search_rungs(file, spec, grid, in, parser);
  const std::optional<AdaptiveState> adaptive =
      search ? std::optional<AdaptiveState>(search->state)
             : adaptive_rounds(spec, grid, statuses, in.mse, parser, path);
  if (adaptive) warn_unfinished_replay(in, *adaptive, parser, path);
  if (parser.flag_set("named")) {
    std::cout << named_cells_csv(spec, grid, search || !adaptive ? nullptr : &*adaptive, statuses,
                                 in.mse, path);
    return 0;
  }
  if (per_run) {
    print_per_run(file, in, adaptive ? &*adaptive : nullptr);
    return 0;
  }
  const auto entries =
      make_table_entries(grid, statuses, in.mse, adaptive ? &adaptive->active : nullptr);
  if (view.comparisons && parser.has("seed-lists")) {
    std::vector<int> seeds;
    for (const TableEntry& e : entries) seeds.push_back(e.seed);
    std::sort(seeds.begin(), seeds.end());
    seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
    std::cout << render_seed_list_comparisons(
        grid, entries, read_seed_lists(parser.get("seed-lists"), seeds), view.comparison);
    return 0;
  }
  if (view.comparisons) {
    std::cout << render_comparisons_csv(compare_table_cells(grid, entries, view.comparison),
                                        view.comparison.delta);
    return 0;
  }
  std::size_t expected_seeds = 0;
  for (const StudySpec& s : spec.studies) expected_seeds = std::max(expected_seeds, s.seeds.size());
  if (adaptive) expected_seeds = 0;
  if (format == TableFormat::kMarkdown) {
    std::vector<RunStatus> covered;
    for (std::size_t i = 0; i < statuses.size(); ++i) {
      if (!adaptive || adaptive->active[i]) covered.push_back(statuses[i]);
    }
    print_markdown_preamble(file, spec, covered, seeds_summary, view.statistic);
    if (search) {  // the rungs, not a table of every configuration x rung
      std::cout << search_report(spec, *search)
                << "(every cell of every rung: phnn reduce --format csv or --per-run)\n";
      return 0;
    }
    if (adaptive) {
      print_adaptive_preamble(spec, *adaptive, parser.has("rule") ? parser.get("rule") : "");
    }
  }
  const int expected = static_cast<int>(expected_seeds);
  std::cout << (seeds_summary ? render_seeds_summary(grid.studies, entries, format, expected)
                              : render_tables(grid.studies, entries, format, expected,
                                              BootstrapOptions{}, view.statistic));
  return 0;
}

}  // namespace apps
}  // namespace phnn
