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

namespace phnn {
namespace apps {

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
