// src/apps/cmd_verify.cpp — `phnn verify RESULTS`: what can be checked of a
// results file without changing it: its structure (ids, statuses), every
// finished row against its checksum, and whether the journals can repair
// the damaged rows (docs/RESULTS_FORMAT.md, "Checksums").
#include <cstdio>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/commands.h"
#include "phnn/store/journal.h"
#include "phnn/store/results_file.h"
#include "phnn/sweep/grid.h"
#include "phnn/sweep/sweep_file.h"

namespace phnn {
namespace apps {
namespace {

// The file's attributes against each other: the stored sweep text (and
// system files) hash to sweep_hash, and expand to the stored run ids.
std::string configuration_problem(const ResultsFile& file) {
  try {
    const SweepSpec spec = parse_sweep_text(file.sweep_text(), file.path() + "@sweep_text",
                                            file.stored_system_files());
    if (spec.text_hash != file.sweep_hash()) {
      return "the stored sweep text hashes to " + spec.text_hash + ", the attribute says " +
             file.sweep_hash();
    }
    const Grid grid = expand_grid(spec);
    const std::vector<std::string> ids = file.read_run_ids();
    if (ids.size() != grid.runs.size()) {
      return "the sweep text gives " + std::to_string(grid.runs.size()) + " runs, the file holds " +
             std::to_string(ids.size());
    }
    for (std::size_t row = 0; row < ids.size(); ++row) {
      if (ids[row] != grid.runs[row].id()) {
        return "row " + std::to_string(row) + " holds run " + ids[row] + ", the sweep text gives " +
               grid.runs[row].id();
      }
    }
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

int run_verify(int argc, char** argv, int first) {
  cli::Parser parser(
      "verify",
      "Checks a results file without changing it: its structure (run ids, statuses),\n"
      "every finished row against the checksum written with it, and, for a damaged\n"
      "row, whether the journals hold its result (then `phnn sweep` on the same file\n"
      "repairs it; otherwise it trains the run again). Exit 0 if nothing is damaged, 1\n"
      "otherwise.");
  parser.positional("RESULTS", "results file of `phnn sweep` or `phnn train --out`");
  if (!parser.parse(argc, argv, first)) return 0;
  const std::string path = parser.get("RESULTS");
  const ResultsFile file = ResultsFile::open_read_only(path);
  std::printf("phnn verify: %s: sweep '%s' (hash %s), %d runs\n", path.c_str(),
              file.sweep_name().c_str(), file.sweep_hash().c_str(), file.num_runs());
  const std::vector<std::string> problems = file.structure_problems();
  for (const std::string& p : problems) std::printf("phnn verify: structure: %s\n", p.c_str());
  if (!problems.empty()) {
    std::printf("phnn verify: damaged structure: move the file aside; `phnn sweep` rebuilds it "
                "from the journals in %s\n", journal_directory(path).c_str());
    return 1;
  }
  std::printf("phnn verify: structure: ok (run ids unique, statuses valid)\n");
  if (const std::string problem = configuration_problem(file); !problem.empty()) {
    std::printf("phnn verify: configuration: %s\n", problem.c_str());
    std::printf("phnn verify: damaged attributes or configuration columns: move the file "
                "aside; `phnn sweep` rebuilds it from the journals in %s\n",
                journal_directory(path).c_str());
    return 1;
  }
  std::printf("phnn verify: configuration: ok (the sweep text matches its hash, the run ids "
              "its grid)\n");
  if (!file.has_checksums()) {
    std::printf("phnn verify: checksums: none (the file predates them); nothing more to check\n");
    return 0;
  }
  int finished = 0;
  for (RunStatus s : file.read_statuses()) finished += s != RunStatus::kPending ? 1 : 0;
  const std::vector<int> damaged = file.damaged_rows();
  std::printf("phnn verify: checksums: %d finished rows checked, %zu damaged\n", finished,
              damaged.size());
  if (damaged.empty()) return 0;
  const auto journal = replay_journals(path);
  const std::vector<std::string> ids = file.read_run_ids();
  for (int row : damaged) {
    const std::string& id = ids[static_cast<std::size_t>(row)];
    std::printf("phnn verify: damaged: run %s (row %d): %s\n", id.c_str(), row,
                journal.count(id) ? "the journal holds it; `phnn sweep` on this file repairs it"
                                  : "not in the journals; `phnn sweep` on this file trains it again");
  }
  return 1;
}

}  // namespace apps
}  // namespace phnn
