// src/apps/cmd_eval.cpp — `phnn eval RESULTS --run ID`: one finished run of
// a results file reloaded from its stored best-validation weights and
// evaluated again (phnn/training/evaluate.h), checked against the stored
// MSE, with the true and learned energy along the figure trajectories.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/eval_on_data.h"
#include "apps/provenance.h"
#include "phnn/store/output_path.h"
#include "phnn/store/results_file.h"
#include "phnn/store/scratch_file.h"
#include "phnn/systems/system_file.h"
#include "phnn/training/evaluate.h"

namespace phnn {
namespace apps {
namespace {

// The row of the run (of `ids`, the file's) whose id is `id` or starts with
// it (unique).
// The row whose id starts with `id`, and has seed `seed` if seed >= 0. The
// seeds of one cell share their ids' first digits (FNV-1a of canonical keys
// that differ in the seed only), so --seed picks one among them.
int find_row(const ResultsFile& results, const std::vector<std::string>& ids,
             const std::string& id, std::int64_t seed) {
  const std::vector<std::int64_t> seeds = results.read_seeds();
  std::vector<std::size_t> matches;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i].compare(0, id.size(), id) == 0 && (seed < 0 || seeds[i] == seed)) {
      matches.push_back(i);
    }
  }
  if (matches.empty() || id.empty()) {
    throw cli::UsageError{"phnn eval: no run with id " + id +
                          (seed >= 0 ? " and seed " + std::to_string(seed) : std::string()) +
                          " in " + results.path() + "; `phnn reduce " + results.path() +
                          " --per-run` lists the ids and seeds"};
  }
  if (matches.size() > 1) {
    std::string listed;
    for (std::size_t k = 0; k < matches.size() && k < 4; ++k) {
      listed += (k ? ", " : "") + ids[matches[k]] + " (seed " + std::to_string(seeds[matches[k]]) + ")";
    }
    throw cli::UsageError{"phnn eval: --run " + id + " matches " + std::to_string(matches.size()) +
                          " runs (" + listed + (matches.size() > 4 ? ", ..." : "") +
                          "); add --seed N, or give more digits"};
  }
  return static_cast<int>(matches.front());
}

// The run's configuration, rebuilt from the sweep text stored in the file.
RunConfig stored_config(const ResultsFile& results, const std::string& id) {
  const std::map<std::string, RunConfig> runs = stored_run_configs(results);
  if (const auto it = runs.find(id); it != runs.end()) return it->second;
  throw std::runtime_error(results.path() + ": run " + id +
                           " is not in the sweep text stored in the file; it was written by "
                           "another program version (" + results.program_version() + ")");
}

// The run evaluated again on the data stored in the file.
Evaluation evaluate(const ResultsFile& results, const RunConfig& run,
                    const std::vector<double>& weights) {
  const CellSpec cell = cell_spec_for(run, {run.seed});
  const PhSystemData data = results.read_system_data(run.system_name());
  const auto system =
      compile_system(data.system_text, results.path() + "@/data/" + run.system_name());
  return evaluate_stored_run(cell, data, *system, weights);
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The kernel set that computed the file's runs (kernel_set_of of the
// sessions that finished runs), or "mixed (A, B)".
std::string stored_kernel_set(const ResultsFile& results) {
  const std::vector<Provenance> sessions = results.read_sessions();
  const std::vector<bool> with_runs = results.sessions_with_runs();
  std::string out;
  for (std::size_t k = 0; k < sessions.size(); ++k) {
    if (!with_runs[k]) continue;
    const std::string theirs = kernel_set_of(sessions[k]);
    if (out.empty()) out = theirs;
    if (theirs != out) return "mixed (" + out + ", " + theirs + ")";
  }
  return out;
}

// Recomputed against stored MSE: bitwise under the kernel set that stored
// it; under another set (results differ by round-off, docs/METHOD.md
// "Deterministic kernels") to a relative 1e-6, far above the rollouts'
// round-off from the same weights and far below any other difference
// (other weights, data or settings). The verdict line and whether it passes.
std::pair<std::string, bool> mse_verdict(double recomputed, double stored,
                                         const std::string& theirs, const std::string& ours) {
  if (theirs == ours || same_bits(recomputed, stored)) {
    const bool same = same_bits(recomputed, stored);
    return {same ? "bitwise equal" : "DIFFERENT", same};
  }
  const double relative = std::fabs(recomputed - stored) / std::fabs(stored);
  char text[256];
  const bool close = relative <= 1e-6;
  std::snprintf(text, sizeof text, "%s (stored by %s, recomputed by %s: relative difference %.1e)",
                close ? "equal to round-off" : "DIFFERENT beyond round-off", theirs.c_str(),
                ours.c_str(), relative);
  return {text, close};
}

// First column: the figure's initial energy h0 [J] (0.5, 0.75 for the
// paper's systems) where the system has figure energies, else the inference
// trajectory (0, 1).
void write_energy_csv(const std::string& path, const Evaluation& e) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write the CSV; is the directory writable?");
  const bool energies = !e.figure_energies.empty();
  out << (energies ? "h0," : "trajectory,") << e.energy_05.columns << "\n";
  char buf[32];
  for (std::size_t k = 0; k < 2; ++k) {
    std::string label = std::to_string(k);
    if (energies) {
      std::snprintf(buf, sizeof buf, "%.17g", e.figure_energies[std::min(k, e.figure_energies.size() - 1)]);
      label = buf;
    }
    for (const auto& row : (k == 0 ? e.energy_05 : e.energy_075).rows) {
      out << label;
      for (double v : row) {
        std::snprintf(buf, sizeof buf, "%.17g", v);
        out << "," << buf;
      }
      out << "\n";
    }
  }
  if (!out.flush()) throw std::runtime_error(path + ": write failed; is the disk full?");
}

// --data FILE: the run of --run (or every finished run) on another data set.
int eval_on_data(const cli::Parser& parser) {
  if (parser.has("out")) throw cli::UsageError{"phnn eval: --out (the energy traces) goes without --data"};
  std::vector<std::string> inputs = {parser.get("RESULTS"), parser.get("data")};
  if (!parser.get("errors").empty()) {
    const std::string problem = output_problem("eval", parser.get("errors"), OutputKind::kEvalCsv, inputs);
    if (!problem.empty()) throw cli::UsageError{"phnn eval: --errors " + problem};
  }
  const ResultsFile results = ResultsFile::open_read_only(parser.get("RESULTS"));
  EvalOnDataOptions o;
  o.data_path = parser.get("data");
  o.errors_path = parser.get("errors");
  if (!parser.get("run").empty()) {
    o.rows = {find_row(results, results.read_run_ids(), parser.get("run"),
                       parser.has("seed") ? parser.get_int_in("seed", 0, 1 << 30) : -1)};
  }
  return apps::eval_on_data(results, o);
}

}  // namespace

int run_eval(int argc, char** argv, int first) {
  cli::Parser parser(
      "eval",
      "Reloads one finished run of a results file from its stored best-validation\n"
      "weights, evaluates it again on the stored data (the inference MSE of Eq. 31 and\n"
      "the figure trajectories: from H(x0) = 0.5 J and 0.75 J for a built-in system,\n"
      "inference trajectories 0 and 1 for a system file), checks the MSE against the\n"
      "stored one (exit 1 if it differs), and writes the states and the true and\n"
      "learned energy along the figure trajectories to --out (CSV). With --data FILE\n"
      "it rolls the run (or every finished run) out on another data set or imported\n"
      "recording of the same states and inputs instead, and prints each run's MSE there.\n\n"
      "Example: phnn eval sines.h5 --data chirp.h5 --errors chirp-errors.csv");
  parser.positional("RESULTS", "results file of `phnn sweep` or `phnn train --out`");
  parser.option("run", "run id (or a unique prefix of it), as in `phnn reduce --per-run`", "");
  parser.option("seed", "with --run PREFIX: the run of this seed among those it matches (the "
                "seeds of one cell share their ids' first digits)", "");
  parser.option("out", "CSV of t, states and energies along the figure trajectories", "");
  parser.option("data", "roll the run (without --run: every finished run of its system) out on "
                "this data set or imported recording instead of the stored data", "");
  parser.option("errors", "with --data: CSV of the error of every run on every inference trajectory", "");
  if (!parser.parse(argc, argv, first)) return 0;
  if (parser.has("data")) return eval_on_data(parser);
  if (parser.has("errors")) throw cli::UsageError{"phnn eval: --errors goes with --data FILE"};
  if (parser.get("run").empty()) {
    throw cli::UsageError{"phnn eval: --run ID is required (or --data FILE: every run on another data set)"};
  }
  if (parser.has("out")) {  // given, even empty: checked
    const std::string problem =
        output_problem("eval", parser.get("out"), OutputKind::kEvalCsv, {parser.get("RESULTS")});
    if (!problem.empty()) throw cli::UsageError{"phnn eval: --out " + problem};
  }
  const ResultsFile results = ResultsFile::open_read_only(parser.get("RESULTS"));
  const std::vector<std::string> ids = results.read_run_ids();
  const int row = find_row(results, ids, parser.get("run"),
                           parser.has("seed") ? parser.get_int_in("seed", 0, 1 << 30) : -1);
  const std::string& id = ids[static_cast<std::size_t>(row)];
  const RunResult stored = results.read_run(row);
  if (stored.weights.empty()) {
    throw std::runtime_error(results.path() + ": run " + id + " has no stored weights (" +
                             (results.layout().weights ? "status " + to_string(stored.status)
                                                       : std::string("the file predates them")) +
                             "); only finished runs of files written since weights are "
                             "stored can be evaluated");
  }
  const RunConfig run = stored_config(results, id);
  const Evaluation e = evaluate(results, run, stored.weights);
  const auto [verdict, same] = mse_verdict(e.result.mse, stored.mse, stored_kernel_set(results),
                                           kernel_set_of(build_provenance()));
  std::printf("phnn eval: run %s (%s): mse %.6e, stored %.6e: %s\n", id.c_str(),
              run.canonical().substr(0, run.canonical().find(run.has_system_file() ? ";system_file=" : ";mass=")).c_str(), e.result.mse,
              stored.mse, verdict.c_str());
  if (!parser.get("out").empty()) {
    write_atomically(parser.get("out"), "writing",
                     [&](const std::string& path) { write_energy_csv(path, e); });
    std::printf("phnn eval: energies along the figure trajectories -> %s\n",
                parser.get("out").c_str());
  }
  return same ? 0 : 1;
}

}  // namespace apps
}  // namespace phnn
